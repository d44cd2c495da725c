#include "server/grpc/routed_clip_service.h"

#include <utility>
#include <vector>

#include <grpcpp/create_channel.h>
#include <grpcpp/security/credentials.h>

#include "absl/strings/str_cat.h"
#include "server/clip_ingest.h"
#include "server/grpc/call_context.h"
#include "server/grpc/clip_conversion.h"
#include "server/grpc/serve.h"
#include "server/grpc/status_conversion.h"
#include "storage/clip_name_check.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// The caller's token, which the shard checks as this node did (the scopes are the same).
void PassTokenOn(const grpc::ServerContext& from, grpc::ClientContext* to) {
  const auto token = from.client_metadata().find("authorization");
  if (token != from.client_metadata().end()) {
    to->AddMetadata("authorization", std::string(token->second.data(), token->second.size()));
  }
}

// A shard's error as the client sees it: the node it came from named when the node did not
// answer; the shard's own refusal (a bad file, a conflict) as one node would give it.
absl::Status ShardError(const grpc::Status& status, const cluster::ClipRoute& route) {
  absl::Status error = FromGrpcStatus(status);
  if (!absl::IsUnavailable(error)) return error;
  return absl::UnavailableError(absl::StrCat("shard ", route.shard, " (node '", route.node_id,
                                             "' at ", route.address, "): ", error.message()));
}

// Whether a failed call may have stored the clip all the same: its answer lost on the way.
bool IsOutcomeUnknown(const absl::Status& status) {
  return absl::IsUnavailable(status) || absl::IsDeadlineExceeded(status) ||
         absl::IsCancelled(status) || absl::IsUnknown(status) || absl::IsInternal(status);
}

}  // namespace

shard::v1::ShardService::Stub& RoutedClipServiceImpl::ShardAt(const std::string& address) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::unique_ptr<shard::v1::ShardService::Stub>& stub = shards_[address];
  if (stub == nullptr) {
    stub = shard::v1::ShardService::NewStub(
        grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  }
  return *stub;
}

absl::Status RoutedClipServiceImpl::StoreTake(grpc::ServerContext& context,
                                              const v1::IngestClipRequest& request, size_t take,
                                              const std::string& take_name,
                                              v1::IngestClipResponse* response) {
  // Checked before the name is reserved cluster-wide; the shard checks it again.
  MOTIONDB_RETURN_IF_ERROR(storage::CheckClipName(take_name));
  MOTIONDB_ASSIGN_OR_RETURN(const cluster::ClipRoute route,
                            routing_->Route(take_name, DeadlineOf(context)));
  shard::v1::StoreTakeRequest store;
  *store.mutable_ingest() = request;
  store.set_take(static_cast<int>(take));
  store.set_clip_id(route.clip_id);
  // The caller's deadline and cancellation, and its token.
  const std::unique_ptr<grpc::ClientContext> call = grpc::ClientContext::FromServerContext(context);
  PassTokenOn(context, call.get());
  const grpc::Status stored = ShardAt(route.address).StoreTake(call.get(), store, response);
  if (stored.ok()) {
    MOTIONDB_RETURN_IF_ERROR(routing_->Settle(take_name, route, response->clip().clip_id()));
    return absl::OkStatus();
  }
  const absl::Status error = ShardError(stored, route);
  // A refusal frees the name it reserved; an answer lost on the way (the clip may be stored)
  // leaves it to the next try, which finds the clip on its shard.
  if (!IsOutcomeUnknown(error)) {
    if (const absl::Status settled = routing_->Settle(take_name, route, std::nullopt);
        !settled.ok()) {
      return absl::Status(error.code(), absl::StrCat(error.message(),
                                                     " (and the name's release "
                                                     "failed: ",
                                                     settled.message(), ")"));
    }
  }
  return error;
}

grpc::Status RoutedClipServiceImpl::IngestClip(grpc::ServerContext* context,
                                               const v1::IngestClipRequest* request,
                                               v1::IngestClipResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const IngestRequest ingest, FromProto(*request));
    MOTIONDB_ASSIGN_OR_RETURN(const std::string name, ClipName(ingest));
    MOTIONDB_ASSIGN_OR_RETURN(UploadBudget::Ticket ticket, budget_.Admit());
    MOTIONDB_RETURN_IF_ERROR(ticket.Reserve(static_cast<int64_t>(request->bvh().size())));
    // Read here for its takes' names, each routed before it is stored; the shard of each take
    // reads the file again (it is sent whole) and stores that take alone.
    MOTIONDB_ASSIGN_OR_RETURN(const UploadedFile file,
                              ReadUpload(request->bvh(), ingest.file_name, limits_, should_stop));
    std::vector<std::string> stored;
    for (size_t t = 0; t < file.takes.size(); ++t) {
      const std::string take_name = TakeClipName(name, file, t);
      v1::IngestClipResponse taken;
      const absl::Status status = StoreTake(*context, *request, t, take_name, &taken);
      if (!status.ok()) return TakeFailure(status, take_name, stored);
      stored.push_back(take_name);
      if (t == 0) {
        *response = std::move(taken);
      } else {
        taken.clear_file();
        *response->add_more_takes() = std::move(taken);
      }
    }
    return absl::OkStatus();
  });
}

}  // namespace motiondb::server
