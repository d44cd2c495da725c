#include "cluster/etcd_watch.h"

#include <chrono>

#include "cluster/etcd_client.h"
#include "cluster/internal/etcd_channels.h"
#include "etcd/etcdserver/etcdserverpb/rpc.grpc.pb.h"

namespace motiondb::cluster {
namespace {

// Between attempts to open a stream while every member fails.
constexpr std::chrono::milliseconds kRetryPause(500);

WatchEvent FromProto(const mvccpb::Event& event) {
  const mvccpb::KeyValue& kv = event.kv();
  return WatchEvent{
      .deleted = event.type() == mvccpb::Event::DELETE,
      .kv = std::make_shared<const KeyValue>(KeyValue{.key = kv.key(),
                                                      .value = kv.value(),
                                                      .create_revision = kv.create_revision(),
                                                      .mod_revision = kv.mod_revision(),
                                                      .lease = kv.lease()})};
}

}  // namespace

EtcdWatch::EtcdWatch(std::shared_ptr<const EtcdChannels> channels, std::string prefix,
                     int64_t start_revision, Callbacks callbacks)
    : channels_(std::move(channels)),
      prefix_(std::move(prefix)),
      callbacks_(std::move(callbacks)),
      next_revision_(start_revision),
      thread_([this] { Run(); }) {}

EtcdWatch::~EtcdWatch() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    if (context_ != nullptr) context_->TryCancel();
  }
  stopped_.notify_all();
  thread_.join();
}

void EtcdWatch::Run() {
  for (;;) {
    const size_t member = channels_->current();
    if (Stream(member) && callbacks_.connected) callbacks_.connected(false);
    channels_->Failed(member);
    std::unique_lock<std::mutex> lock(mutex_);
    if (stopped_.wait_for(lock, kRetryPause, [this] { return stopping_; })) return;
  }
}

bool EtcdWatch::Stream(size_t member) {
  grpc::ClientContext context;
  // Without it, a member cut off from its leader keeps the stream open and silent; with it,
  // etcd ends the stream and the watch moves on (clientv3.WithRequireLeader).
  context.AddMetadata("hasleader", "true");
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_) return false;
    context_ = &context;
  }
  etcdserverpb::Watch::Stub stub(channels_->channel(member));
  const auto stream = stub.Watch(&context);
  etcdserverpb::WatchRequest request;
  etcdserverpb::WatchCreateRequest* create = request.mutable_create_request();
  create->set_key(prefix_);
  create->set_range_end(PrefixRangeEnd(prefix_));
  create->set_start_revision(next_revision_);
  bool opened = false;
  etcdserverpb::WatchResponse response;
  if (stream->Write(request)) {
    while (stream->Read(&response)) {
      if (response.created() && !opened) {
        opened = true;
        // From now: nothing before the store's present revision is asked for.
        if (next_revision_ == 0) next_revision_ = response.header().revision() + 1;
        if (callbacks_.connected) callbacks_.connected(true);
      }
      if (response.compact_revision() > 0) {
        // The revision asked for is gone: go on from the present, after a fresh read.
        next_revision_ = 0;
        if (callbacks_.resync) callbacks_.resync();
        break;
      }
      if (response.canceled()) break;
      if (response.events_size() == 0) continue;
      std::vector<WatchEvent> events;
      for (const mvccpb::Event& event : response.events()) events.push_back(FromProto(event));
      next_revision_ = events.back().kv->mod_revision + 1;
      if (callbacks_.events) callbacks_.events(events);
    }
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    context_ = nullptr;
  }
  context.TryCancel();
  stream->Finish();
  return opened;
}

}  // namespace motiondb::cluster
