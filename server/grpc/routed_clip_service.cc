#include "server/grpc/routed_clip_service.h"

#include <algorithm>
#include <limits>
#include <utility>
#include <vector>

#include <grpcpp/create_channel.h>
#include <grpcpp/security/credentials.h>
#include <grpcpp/support/channel_arguments.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "server/clip_ingest.h"
#include "server/grpc/call_context.h"
#include "server/grpc/clip_conversion.h"
#include "server/grpc/request_logger.h"
#include "server/grpc/serve.h"
#include "server/grpc/status_conversion.h"
#include "server/grpc/stream_upload.h"
#include "server/listing.h"
#include "storage/clip_name_check.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// Room in a message beyond its payload (the call's other fields and framing).
constexpr int64_t kAnswerSlack = 1 << 20;

// A stream's messages as ReceiveUpload reads them, kept as the one request a router passes on:
// the first one's fields, and every chunk's bytes.
class KeptStream {
 public:
  // The kept bytes are counted against `ticket` too: the file is held twice while it is read
  // (its text, and its parse).
  KeptStream(grpc::ServerReader<v1::IngestClipStreamRequest>& reader, UploadBudget::Ticket& ticket)
      : reader_(reader), ticket_(ticket) {}
  bool Read(v1::IngestClipStreamRequest* message) {
    if (!status_.ok() || !reader_.Read(message)) return false;
    status_ = ticket_.Reserve(static_cast<int64_t>(message->chunk().size()));
    if (!status_.ok()) return false;
    if (first_) {
      first_ = false;
      request_.set_file_name(message->file_name());
      request_.set_name(message->name());
      *request_.mutable_tags() = message->tags();
      request_.set_on_conflict(message->on_conflict());
    }
    request_.mutable_bvh()->append(message->chunk());
    return true;
  }
  // Why reading stopped early (the budget refused what was kept), else OK.
  const absl::Status& status() const { return status_; }
  v1::IngestClipRequest Take() { return std::move(request_); }

 private:
  grpc::ServerReader<v1::IngestClipStreamRequest>& reader_;
  UploadBudget::Ticket& ticket_;
  absl::Status status_;
  bool first_ = true;
  v1::IngestClipRequest request_;
};

// Whether a failed call may have stored the clip all the same: its answer lost on the way.
bool IsOutcomeUnknown(const absl::Status& status) {
  return absl::IsUnavailable(status) || absl::IsDeadlineExceeded(status) ||
         absl::IsCancelled(status) || absl::IsUnknown(status) || absl::IsInternal(status);
}

}  // namespace

std::unique_ptr<grpc::ClientContext> RoutedClipServiceImpl::NodeContext(
    const grpc::ServerContext& from) const {
  std::unique_ptr<grpc::ClientContext> call = grpc::ClientContext::FromServerContext(from);
  // The caller was checked here; the node checks that the call is the cluster's.
  if (!cluster_token_.empty()) call->AddMetadata("authorization", "Bearer " + cluster_token_);
  return call;
}

RoutedClipServiceImpl::NodeStubs& RoutedClipServiceImpl::NodeAt(const std::string& address) {
  std::lock_guard<std::mutex> lock(mutex_);
  NodeStubs& stubs = nodes_[address];
  if (stubs.shard == nullptr) {
    // A node answers up to its answer limit (an export, a clip's poses), past gRPC's 4 MiB.
    grpc::ChannelArguments arguments;
    arguments.SetMaxReceiveMessageSize(static_cast<int>(
        std::min<int64_t>(answers_.max_bytes() + kAnswerSlack, std::numeric_limits<int>::max())));
    const std::shared_ptr<grpc::Channel> channel =
        grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), arguments);
    stubs.shard = shard::v1::ShardService::NewStub(channel);
    stubs.clips = v1::ClipService::NewStub(channel);
  }
  return stubs;
}

absl::Status RoutedClipServiceImpl::NodeFailed(const grpc::Status& status,
                                               const std::string& node_id,
                                               const std::string& address,
                                               const std::string& holding) {
  absl::Status error = FromGrpcStatus(status);
  // The caller was let in here: a node refusing this node's call refuses the cluster's token.
  if (absl::IsUnauthenticated(error) || absl::IsPermissionDenied(error)) {
    return absl::InternalError(absl::StrCat(
        "node '", node_id, "' at ", address, " refused this router's call (", error.message(),
        "): give every node of the cluster the same --cluster-token-file"));
  }
  // The node's own refusal (a bad file, a conflict, no such clip) is told as one node tells it.
  if (!absl::IsUnavailable(error)) return error;
  (void)routing_->ShardNodes(/*refresh=*/true);  // its address may have changed
  return absl::UnavailableError(
      absl::StrCat(holding, " (node '", node_id, "' at ", address, "): ", error.message()));
}

absl::Status RoutedClipServiceImpl::NodeFailed(const grpc::Status& status,
                                               const cluster::ClipRoute& route) {
  return NodeFailed(status, route.node_id, route.address, absl::StrCat("shard ", route.shard));
}

absl::StatusOr<RoutedClipServiceImpl::NodeCall> RoutedClipServiceImpl::CallClipNode(
    const grpc::ServerContext& context, int64_t clip_id) {
  // As one node answers an id no clip has.
  if (clip_id < 1) return absl::NotFoundError(absl::StrCat("clip ", clip_id, " not found"));
  NodeCall call;
  MOTIONDB_ASSIGN_OR_RETURN(call.route, routing_->Locate(clip_id, /*refresh=*/false));
  call.clips = NodeAt(call.route.address).clips.get();
  call.context = NodeContext(context);
  return call;
}

template <typename Request, typename Response>
grpc::Status RoutedClipServiceImpl::Pass(grpc::ServerContext* context, int64_t clip_id,
                                         const Request& request, Response* response,
                                         grpc::Status (v1::ClipService::Stub::*method)(
                                             grpc::ClientContext*, const Request&, Response*)) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(NodeCall call, CallClipNode(*context, clip_id));
    const grpc::Status status = (call.clips->*method)(call.context.get(), request, response);
    return status.ok() ? absl::OkStatus() : NodeFailed(status, call.route);
  });
}

grpc::Status RoutedClipServiceImpl::GetClip(grpc::ServerContext* context,
                                            const v1::GetClipRequest* request, v1::Clip* response) {
  return Pass(context, request->clip_id(), *request, response, &v1::ClipService::Stub::GetClip);
}

grpc::Status RoutedClipServiceImpl::ExportClip(grpc::ServerContext* context,
                                               const v1::ExportClipRequest* request,
                                               v1::ExportClipResponse* response) {
  return Pass(context, request->clip().clip_id(), *request, response,
              &v1::ClipService::Stub::ExportClip);
}

grpc::Status RoutedClipServiceImpl::GetClipPoses(grpc::ServerContext* context,
                                                 const v1::GetClipPosesRequest* request,
                                                 v1::ClipPoses* response) {
  return Pass(context, request->clip().clip_id(), *request, response,
              &v1::ClipService::Stub::GetClipPoses);
}

grpc::Status RoutedClipServiceImpl::ExportClipStream(
    grpc::ServerContext* context, const v1::ExportClipRequest* request,
    grpc::ServerWriter<v1::ExportClipResponse>* writer) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(NodeCall call, CallClipNode(*context, request->clip().clip_id()));
    const std::unique_ptr<grpc::ClientReader<v1::ExportClipResponse>> pieces =
        call.clips->ExportClipStream(call.context.get(), *request);
    v1::ExportClipResponse piece;
    while (pieces->Read(&piece)) {
      if (!writer->Write(piece)) {
        call.context->TryCancel();
        (void)pieces->Finish();
        return absl::CancelledError("the client stopped reading the export");
      }
    }
    const grpc::Status status = pieces->Finish();
    return status.ok() ? absl::OkStatus() : NodeFailed(status, call.route);
  });
}

grpc::Status RoutedClipServiceImpl::ListClips(grpc::ServerContext* context,
                                              const v1::ListClipsRequest* request,
                                              v1::ListClipsResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipOrder order, ClipOrderOf(request->sort()));
    if (request->skeleton_id() != 0) {
      return absl::InvalidArgumentError(
          "skeleton_id: in a cluster a skeleton's id is its shard node's own; a listing by "
          "skeleton is not routed yet");
    }
    MOTIONDB_ASSIGN_OR_RETURN(
        const storage::Page page,
        StoragePage({.page_size = request->page_size(), .page_token = request->page_token()}));
    MOTIONDB_ASSIGN_OR_RETURN(const std::vector<cluster::ShardNode> nodes,
                              routing_->ShardNodes(/*refresh=*/false));
    // Each node's first page after the token: a token is a place in the order, good on every
    // node, so the whole page is among them.
    v1::ListClipsRequest ask = *request;
    ask.set_page_size(page.page_size);
    std::vector<v1::ListClipsResponse> answers(nodes.size());
    std::vector<PartPage> parts(nodes.size());
    int64_t total = 0;
    for (size_t n = 0; n < nodes.size(); ++n) {
      const std::unique_ptr<grpc::ClientContext> call = NodeContext(*context);
      const grpc::Status status =
          NodeAt(nodes[n].address).clips->ListClips(call.get(), ask, &answers[n]);
      if (!status.ok()) {
        return NodeFailed(status, nodes[n].node_id, nodes[n].address,
                          absl::StrCat("shards ", absl::StrJoin(nodes[n].shards, ", ")));
      }
      parts[n].more = !answers[n].next_page_token().empty();
      for (const v1::Clip& clip : answers[n].clips()) {
        storage::ClipRecord& position = parts[n].positions.emplace_back();
        position.clip_id = clip.clip_id();
        position.name = clip.name();
        position.created_unix_ms = clip.created_unix_ms();
      }
      total += answers[n].total_size();
    }
    const MergedClipPage merged = MergeClipPages(order, page.page_size, parts);
    for (const auto& [part, index] : merged.taken) {
      *response->add_clips() = std::move(*answers[part].mutable_clips(static_cast<int>(index)));
    }
    response->set_next_page_token(merged.next_page_token);
    response->set_total_size(total);
    return absl::OkStatus();
  });
}

absl::StatusOr<v1::Clip> RoutedClipServiceImpl::ClipOnNode(NodeCall& call, int64_t clip_id) {
  v1::GetClipRequest which;
  which.set_clip_id(clip_id);
  v1::Clip clip;
  const grpc::Status status = call.clips->GetClip(call.context.get(), which, &clip);
  if (!status.ok()) return NodeFailed(status, call.route);
  return clip;
}

void RoutedClipServiceImpl::FreeName(const std::string& name, int64_t clip_id,
                                     absl::string_view done) {
  // What was done stands whatever etcd says, so a failed release is logged, not told: a name left
  // reserved is taken over by its next ingest (ClipRouter::Route) or rename (ReserveName).
  if (const absl::Status freed = routing_->ReleaseName(name, clip_id); !freed.ok()) {
    LogLine(absl::StrCat("clip ", clip_id, " was ", done, "; the name '", name,
                         "' stays reserved for it in the cluster: ", freed.message()));
  }
}

grpc::Status RoutedClipServiceImpl::UpdateClip(grpc::ServerContext* context,
                                               const v1::UpdateClipRequest* request,
                                               v1::Clip* response) {
  if (!request->has_name()) {
    return Pass(context, request->clip_id(), *request, response,
                &v1::ClipService::Stub::UpdateClip);
  }
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    // Checked before the name is reserved cluster-wide; the shard checks it again.
    MOTIONDB_RETURN_IF_ERROR(storage::CheckClipName(request->name()));
    MOTIONDB_ASSIGN_OR_RETURN(NodeCall call, CallClipNode(*context, request->clip_id()));
    MOTIONDB_ASSIGN_OR_RETURN(const v1::Clip before, ClipOnNode(call, request->clip_id()));
    // A name left reserved for a clip named otherwise now is taken over.
    const auto still_named = [&](int64_t holder) -> absl::StatusOr<bool> {
      MOTIONDB_ASSIGN_OR_RETURN(NodeCall holder_call, CallClipNode(*context, holder));
      const absl::StatusOr<v1::Clip> held = ClipOnNode(holder_call, holder);
      if (absl::IsNotFound(held.status())) return false;
      MOTIONDB_RETURN_IF_ERROR(held.status());
      return held->name() == request->name();
    };
    MOTIONDB_RETURN_IF_ERROR(
        routing_->ReserveName(request->name(), request->clip_id(), still_named));
    const bool renamed = request->name() != before.name();
    const grpc::Status status =
        NodeAt(call.route.address)
            .shard->UpdateClip(NodeContext(*context).get(), *request, response);
    if (!status.ok()) {
      const absl::Status error = NodeFailed(status, call.route);
      // Refused: the new name is free again. Unanswered: the shard may have renamed the clip,
      // so the name stays the clip's.
      if (renamed && !IsOutcomeUnknown(error)) {
        FreeName(request->name(), request->clip_id(), "not renamed");
      }
      return error;
    }
    if (renamed) FreeName(before.name(), request->clip_id(), "renamed");
    return absl::OkStatus();
  });
}

grpc::Status RoutedClipServiceImpl::DeleteClip(grpc::ServerContext* context,
                                               const v1::DeleteClipRequest* request,
                                               v1::DeleteClipResponse* response) {
  return Serve(gate_, context, [&](const ShouldStop&) -> absl::Status {
    // The name, to free once the clip is gone.
    MOTIONDB_ASSIGN_OR_RETURN(NodeCall call, CallClipNode(*context, request->clip_id()));
    MOTIONDB_ASSIGN_OR_RETURN(const v1::Clip clip, ClipOnNode(call, request->clip_id()));
    const grpc::Status status =
        call.clips->DeleteClip(NodeContext(*context).get(), *request, response);
    if (!status.ok()) return NodeFailed(status, call.route);
    FreeName(clip.name(), request->clip_id(), "deleted");
    return absl::OkStatus();
  });
}

absl::Status RoutedClipServiceImpl::StoreTake(grpc::ServerContext& context,
                                              shard::v1::StoreTakeRequest& store, size_t take,
                                              const std::string& take_name,
                                              v1::IngestClipResponse* response) {
  // Checked before the name is reserved cluster-wide; the shard checks it again.
  MOTIONDB_RETURN_IF_ERROR(storage::CheckClipName(take_name));
  MOTIONDB_ASSIGN_OR_RETURN(const cluster::ClipRoute route,
                            routing_->Route(take_name, WaitDeadlineOf(context)));
  store.set_take(static_cast<int>(take));
  store.set_clip_id(route.clip_id);
  const std::unique_ptr<grpc::ClientContext> call = NodeContext(context);
  const grpc::Status stored = NodeAt(route.address).shard->StoreTake(call.get(), store, response);
  if (stored.ok()) {
    MOTIONDB_RETURN_IF_ERROR(routing_->Settle(take_name, route, response->clip().clip_id()));
    return absl::OkStatus();
  }
  const absl::Status error = NodeFailed(stored, route);
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

absl::Status RoutedClipServiceImpl::StoreTakes(grpc::ServerContext& context,
                                               shard::v1::StoreTakeRequest& store,
                                               const std::string& name, const UploadedFile& file,
                                               v1::IngestClipResponse* response) {
  // The file goes to a node whole, in one message: a node refuses more than --max-message-mb.
  if (static_cast<int64_t>(store.ByteSizeLong()) > max_message_bytes_ - kAnswerSlack) {
    return absl::ResourceExhaustedError(absl::StrCat(
        "'", store.ingest().file_name(), "' is ", store.ingest().bvh().size(),
        " bytes: a cluster passes a file to its shard node in one message, of at most ",
        max_message_bytes_ - kAnswerSlack, " (--max-message-mb, less room for the call)"));
  }
  std::vector<std::string> stored;
  for (size_t t = 0; t < file.takes.size(); ++t) {
    const std::string take_name = TakeClipName(name, file, t);
    v1::IngestClipResponse taken;
    const absl::Status status = StoreTake(context, store, t, take_name, &taken);
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
    // The request is gRPC's to keep: the one copy sent is counted too.
    MOTIONDB_RETURN_IF_ERROR(ticket.Reserve(static_cast<int64_t>(request->bvh().size())));
    shard::v1::StoreTakeRequest store;
    *store.mutable_ingest() = *request;
    return StoreTakes(*context, store, name, file, response);
  });
}

grpc::Status RoutedClipServiceImpl::IngestClipStream(
    grpc::ServerContext* context, grpc::ServerReader<v1::IngestClipStreamRequest>* reader,
    v1::IngestClipResponse* response) {
  // As one node reads a stream (ClipServiceImpl::IngestClipStream: the right first, the stream
  // read outside --threads, parsed as it arrives), keeping its bytes to pass them on whole.
  if (grpc::Status allowed = gate_.Allowed(context); !allowed.ok()) return allowed;
  absl::StatusOr<UploadBudget::Ticket> ticket = budget_.Admit();
  if (!ticket.ok()) return ToGrpcStatus(ticket.status());
  KeptStream kept(*reader, *ticket);
  absl::StatusOr<ReceivedUpload> received;
  {
    StreamWatchdog::Watch watch = watchdog_.Start(context);
    received = ReceiveUpload(kept, watch, limits_, *ticket);
  }
  if (!kept.status().ok()) return ToGrpcStatus(kept.status());
  if (!received.ok()) return ToGrpcStatus(ExplainStop(received.status(), context));
  return Serve(gate_, context, [&](const ShouldStop& should_stop) -> absl::Status {
    if (should_stop()) return absl::CancelledError("the upload ended before its last chunk");
    MOTIONDB_ASSIGN_OR_RETURN(const UploadedFile file, received->bvh.Finish(should_stop));
    MOTIONDB_ASSIGN_OR_RETURN(const std::string name, ClipName(received->request));
    shard::v1::StoreTakeRequest store;
    *store.mutable_ingest() = kept.Take();
    return StoreTakes(*context, store, name, file, response);
  });
}

}  // namespace motiondb::server
