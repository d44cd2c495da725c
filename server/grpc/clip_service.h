// motiondb.v1.ClipService: ingest, list, get, delete and export clips.
#ifndef MOTIONDB_SERVER_GRPC_CLIP_SERVICE_H_
#define MOTIONDB_SERVER_GRPC_CLIP_SERVICE_H_

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "server/catalog.h"
#include "server/clip_facts.h"
#include "server/server_options.h"
#include "storage/database.h"

namespace motiondb::server {

class ClipServiceImpl final : public v1::ClipService::Service {
 public:
  ClipServiceImpl(storage::Database& database, Library& library, ClipFactsCache& facts,
                  const ServerOptions& options)
      : database_(database), library_(library), facts_(facts), options_(options) {}

  grpc::Status IngestClip(grpc::ServerContext* context, const v1::IngestClipRequest* request,
                          v1::IngestClipResponse* response) override;
  grpc::Status IngestClipStream(grpc::ServerContext* context,
                                grpc::ServerReader<v1::IngestClipStreamRequest>* reader,
                                v1::IngestClipResponse* response) override;
  grpc::Status ListClips(grpc::ServerContext* context, const v1::ListClipsRequest* request,
                         v1::ListClipsResponse* response) override;
  grpc::Status GetClip(grpc::ServerContext* context, const v1::GetClipRequest* request,
                       v1::Clip* response) override;
  grpc::Status DeleteClip(grpc::ServerContext* context, const v1::DeleteClipRequest* request,
                          v1::DeleteClipResponse* response) override;
  grpc::Status ExportClip(grpc::ServerContext* context, const v1::ExportClipRequest* request,
                          v1::ExportClipResponse* response) override;

 private:
  // Parses, stores and indexes one uploaded file.
  absl::Status Ingest(const std::string& file_name, const std::string& name,
                      const std::vector<std::string>& tags, absl::string_view bvh,
                      v1::IngestClipResponse* response);
  absl::Status ReadStream(grpc::ServerReader<v1::IngestClipStreamRequest>* reader,
                          v1::IngestClipResponse* response);
  absl::Status List(const v1::ListClipsRequest& request, v1::ListClipsResponse* response);
  absl::Status Get(int64_t clip_id, v1::Clip* response);
  absl::Status Export(const v1::ClipRange& range, v1::ExportClipResponse* response);

  storage::Database& database_;
  Library& library_;
  ClipFactsCache& facts_;
  const ServerOptions& options_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_CLIP_SERVICE_H_
