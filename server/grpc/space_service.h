// motiondb.v1.SpaceService: create, list, get and delete spaces, and plot clips in them.
#ifndef MOTIONDB_SERVER_GRPC_SPACE_SERVICE_H_
#define MOTIONDB_SERVER_GRPC_SPACE_SERVICE_H_

#include "absl/status/statusor.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "server/answer_limit.h"
#include "server/catalog.h"
#include "server/grpc/call_gate.h"
#include "server/index_registry.h"
#include "storage/database.h"

namespace motiondb::server {

class SpaceServiceImpl final : public v1::SpaceService::Service {
 public:
  SpaceServiceImpl(storage::Database& database, Catalog& catalog, const IndexRegistry& registry,
                   const AnswerLimit& answers, CallGate& gate)
      : database_(database),
        catalog_(catalog),
        registry_(registry),
        answers_(answers),
        gate_(gate) {}

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
  storage::Database& database_;
  Catalog& catalog_;
  const IndexRegistry& registry_;
  AnswerLimit answers_;
  CallGate& gate_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_SPACE_SERVICE_H_
