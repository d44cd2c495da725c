#include "server/grpc/server_info_service.h"

#include "server/grpc/proto_conversion.h"
#include "server/grpc/status_conversion.h"

#ifndef MOTIONDB_VERSION
#error "MOTIONDB_VERSION must be defined by the build (server/grpc/CMakeLists.txt)"
#endif

namespace motiondb::server {

grpc::Status ServerInfoServiceImpl::GetServerInfo(grpc::ServerContext* context,
                                                  const v1::GetServerInfoRequest* /*request*/,
                                                  v1::ServerInfo* response) {
  return gate_.Run(context, [&]() -> grpc::Status {
    const absl::StatusOr<storage::Counts> counts = database_.GetCounts();
    if (!counts.ok()) return ToGrpcStatus(counts.status());
    response->set_version(MOTIONDB_VERSION);
    response->set_uptime_s(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
    v1::DatabaseCounts* out = response->mutable_counts();
    out->set_skeletons(counts->skeletons);
    out->set_clips(counts->clips);
    out->set_frames(counts->frames);
    out->set_spaces(counts->spaces);
    out->set_projections(counts->projections);
    out->set_labels(counts->labels);
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
    response->set_auth_required(!options_.auth_token.empty());
    response->set_tls(!options_.tls_cert_pem.empty());
    return grpc::Status::OK;
  });
}

}  // namespace motiondb::server
