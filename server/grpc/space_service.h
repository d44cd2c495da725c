// motiondb.v1.SpaceService: create, list, get and delete spaces, and plot clips in them.
#ifndef MOTIONDB_SERVER_GRPC_SPACE_SERVICE_H_
#define MOTIONDB_SERVER_GRPC_SPACE_SERVICE_H_

#include "absl/status/statusor.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "server/catalog.h"
#include "server/index_registry.h"
#include "server/space_builder.h"
#include "storage/database.h"

namespace motiondb::server {

// The request's options and training ranges; INVALID_ARGUMENT names a bad field.
absl::StatusOr<SpaceRequest> ToSpaceRequest(const v1::CreateSpaceRequest& request);

class SpaceServiceImpl final : public v1::SpaceService::Service {
 public:
  SpaceServiceImpl(storage::Database& database, Library& library, const IndexRegistry& registry)
      : database_(database), library_(library), registry_(registry) {}

  grpc::Status CreateSpace(grpc::ServerContext* context, const v1::CreateSpaceRequest* request,
                           v1::Space* response) override;
  grpc::Status ListSpaces(grpc::ServerContext* context, const v1::ListSpacesRequest* request,
                          v1::ListSpacesResponse* response) override;
  grpc::Status GetSpace(grpc::ServerContext* context, const v1::GetSpaceRequest* request,
                        v1::Space* response) override;
  grpc::Status DeleteSpace(grpc::ServerContext* context, const v1::DeleteSpaceRequest* request,
                           v1::DeleteSpaceResponse* response) override;
  grpc::Status GetCurve(grpc::ServerContext* context, const v1::GetCurveRequest* request,
                        v1::GetCurveResponse* response) override;

 private:
  absl::Status Create(const v1::CreateSpaceRequest& request, grpc::ServerContext* context,
                      v1::Space* response);
  absl::Status List(const v1::ListSpacesRequest& request, v1::ListSpacesResponse* response);
  absl::Status Curve(const v1::GetCurveRequest& request, v1::GetCurveResponse* response);

  storage::Database& database_;
  Library& library_;
  const IndexRegistry& registry_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_SPACE_SERVICE_H_
