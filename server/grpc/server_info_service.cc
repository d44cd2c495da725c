#include "server/grpc/server_info_service.h"

#include "server/database_backup.h"
#include "server/grpc/serve.h"
#include "server/grpc/server_info_conversion.h"
#include "server/grpc/space_conversion.h"
#include "util/status_macros.h"

#ifndef MOTIONDB_VERSION
#error "MOTIONDB_VERSION must be defined by the build (server/grpc/CMakeLists.txt)"
#endif

namespace motiondb::server {

grpc::Status ServerInfoServiceImpl::GetServerInfo(grpc::ServerContext* context,
                                                  const v1::GetServerInfoRequest* /*request*/,
                                                  v1::ServerInfo* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const storage::Counts counts, database_.GetCounts());
    response->set_version(MOTIONDB_VERSION);
    response->set_uptime_s(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
    ToProto(counts, response->mutable_counts());
    int64_t index_bytes = 0;
    for (const auto& snapshot : registry_.All()) {
      v1::SpaceIndexInfo* info = response->add_indices();
      info->set_space(snapshot->record.name);
      ToProto(*snapshot, info->mutable_index());
      index_bytes += snapshot->coordinate_bytes() + snapshot->tree_bytes();
    }
    response->set_index_bytes(index_bytes);
    response->set_max_message_bytes(int64_t{options_.max_message_mb} << 20);
    response->set_max_bvh_bytes(options_.uploads.max_bvh_bytes);
    response->set_max_answer_bytes(int64_t{options_.max_answer_mb} << 20);
    response->set_auth_required(!options_.auth_tokens.empty());
    response->set_scope(std::string(TokenScopeName(access_.VerdictOf(context).scope)));
    response->set_tls(!options_.tls_cert_pem.empty());
    return absl::OkStatus();
  });
}

grpc::Status ServerInfoServiceImpl::CreateBackup(grpc::ServerContext* context,
                                                 const v1::CreateBackupRequest* /*request*/,
                                                 grpc::ServerWriter<v1::BackupChunk>* writer) {
  // Large enough that per-message costs vanish, far below any message limit.
  constexpr size_t kChunkBytes = size_t{1} << 20;
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(DatabaseBackup backup,
                              DatabaseBackup::Create(database_, options_.db_path));
    // A database file is never empty, so the first chunk carries the size and counts.
    for (bool first = true;; first = false) {
      MOTIONDB_ASSIGN_OR_RETURN(std::string data, backup.ReadChunk(kChunkBytes));
      if (data.empty()) return absl::OkStatus();
      v1::BackupChunk chunk;
      if (first) {
        chunk.set_total_bytes(backup.size_bytes());
        ToProto(backup.counts(), chunk.mutable_counts());
      }
      chunk.set_data(std::move(data));
      // False once the client has gone: the copy is dropped with `backup`.
      if (!writer->Write(chunk))
        return absl::CancelledError("the client stopped reading the backup");
    }
  });
}

}  // namespace motiondb::server
