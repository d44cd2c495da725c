// motiondb.v1.LabelService: add, list, find and delete labels, and a clip's label timeline.
#ifndef MOTIONDB_SERVER_GRPC_LABEL_SERVICE_H_
#define MOTIONDB_SERVER_GRPC_LABEL_SERVICE_H_

#include "motiondb/v1/label_service.grpc.pb.h"
#include "server/answer_limit.h"
#include "server/grpc/call_gate.h"
#include "storage/database.h"

namespace motiondb::server {

class LabelServiceImpl final : public v1::LabelService::Service {
 public:
  LabelServiceImpl(storage::Database& database, const AnswerLimit& answers, CallGate& gate)
      : database_(database), answers_(answers), gate_(gate) {}

  grpc::Status AddLabels(grpc::ServerContext* context, const v1::AddLabelsRequest* request,
                         v1::AddLabelsResponse* response) override;
  grpc::Status ListLabels(grpc::ServerContext* context, const v1::ListLabelsRequest* request,
                          v1::ListLabelsResponse* response) override;
  grpc::Status DeleteLabels(grpc::ServerContext* context, const v1::DeleteLabelsRequest* request,
                            v1::DeleteLabelsResponse* response) override;
  grpc::Status FindLabels(grpc::ServerContext* context, const v1::FindLabelsRequest* request,
                          v1::FindLabelsResponse* response) override;
  grpc::Status GetClipLabels(grpc::ServerContext* context, const v1::GetClipLabelsRequest* request,
                             v1::GetClipLabelsResponse* response) override;

 private:
  storage::Database& database_;
  AnswerLimit answers_;
  CallGate& gate_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_LABEL_SERVICE_H_
