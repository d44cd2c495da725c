// motiondb.v1.ServerService: the server's version, the database's counts and the memory of the
// resident indices; online backups.
#ifndef MOTIONDB_SERVER_GRPC_SERVER_INFO_SERVICE_H_
#define MOTIONDB_SERVER_GRPC_SERVER_INFO_SERVICE_H_

#include <chrono>

#include "motiondb/v1/server_service.grpc.pb.h"
#include "server/grpc/access_control.h"
#include "server/grpc/call_gate.h"
#include "server/grpc/server_options.h"
#include "server/index_registry.h"
#include "storage/database.h"

namespace motiondb::server {

class ServerInfoServiceImpl final : public v1::ServerService::Service {
 public:
  ServerInfoServiceImpl(storage::Database& database, const IndexRegistry& registry,
                        const ServerOptions& options, const AccessControl& access, CallGate& gate)
      : database_(database),
        registry_(registry),
        options_(options),
        access_(access),
        gate_(gate),
        start_(std::chrono::steady_clock::now()) {}

  grpc::Status GetServerInfo(grpc::ServerContext* context, const v1::GetServerInfoRequest* request,
                             v1::ServerInfo* response) override;
  grpc::Status CreateBackup(grpc::ServerContext* context, const v1::CreateBackupRequest* request,
                            grpc::ServerWriter<v1::BackupChunk>* writer) override;

 private:
  storage::Database& database_;
  const IndexRegistry& registry_;
  const ServerOptions& options_;
  const AccessControl& access_;
  CallGate& gate_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_SERVER_INFO_SERVICE_H_
