#include "cluster/node_registration.h"

#include <chrono>

#include "absl/strings/str_cat.h"
#include "cluster/cluster_keys.h"
#include "cluster/internal/lease_keeper.h"
#include "util/status_macros.h"

namespace motiondb::cluster {
namespace {

// Between attempts while etcd does not answer or the id is taken.
constexpr absl::Duration kRetryPause = absl::Seconds(1);

}  // namespace

absl::StatusOr<std::unique_ptr<NodeRegistration>> NodeRegistration::Start(
    const EtcdClient& etcd, const ClusterOptions& options,
    std::function<void(bool registered)> on_change) {
  std::unique_ptr<NodeRegistration> registration(
      new NodeRegistration(etcd, options, std::move(on_change)));
  const absl::Status first = registration->Step();
  if (absl::IsAlreadyExists(first)) return first;
  registration->Report(first);
  registration->thread_ = std::thread([raw = registration.get()] { raw->Run(); });
  return registration;
}

NodeRegistration::NodeRegistration(const EtcdClient& etcd, const ClusterOptions& options,
                                   std::function<void(bool)> on_change)
    : etcd_(etcd),
      options_(options),
      key_(NodeKey(options.cluster, options.node.node_id)),
      on_change_(std::move(on_change)),
      lease_(std::make_unique<LeaseKeeper>(etcd, options.lease_ttl)),
      info_(options.node) {}

NodeRegistration::~NodeRegistration() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void NodeRegistration::SetShards(std::vector<int> shards) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (info_.shards == shards) return;
    info_.shards = std::move(shards);
    dirty_ = true;
  }
  wake_.notify_all();
}

absl::Status NodeRegistration::WriteKey(int64_t lease, const std::string& value) {
  MOTIONDB_ASSIGN_OR_RETURN(const SwapOutcome outcome, etcd_.CompareAndSwap(key_, 0, value, lease));
  if (outcome.written) return absl::OkStatus();
  if (outcome.current && outcome.current->lease == lease) return etcd_.Put(key_, value, lease);
  std::string holder = "another node";
  if (outcome.current) {
    const absl::StatusOr<NodeInfo> other =
        NodeInfo::FromJson(options_.node.node_id, outcome.current->value);
    if (other.ok()) holder = absl::StrCat("the ", other->role, " node at ", other->address);
  }
  return absl::AlreadyExistsError(absl::StrCat(
      "node id '", options_.node.node_id, "' of cluster '", options_.cluster, "' is held by ",
      holder,
      ", alive: choose another --node-id (or, if that node just stopped, retry after its "
      "lease of ",
      absl::FormatDuration(options_.lease_ttl), ")"));
}

absl::Status NodeRegistration::Step() {
  MOTIONDB_ASSIGN_OR_RETURN(const bool new_lease, lease_->Renew());
  if (new_lease) {
    std::lock_guard<std::mutex> lock(mutex_);
    dirty_ = true;
  }
  std::string value;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!dirty_) return absl::OkStatus();
    value = info_.ToJson();
    dirty_ = false;
  }
  const absl::Status written = WriteKey(lease_->id(), value);
  if (!written.ok()) {
    std::lock_guard<std::mutex> lock(mutex_);
    dirty_ = true;
  }
  if (absl::IsAlreadyExists(written)) {
    // Ours would keep the id from its holder once that one dies; take a new lease next time.
    lease_->Drop();
  }
  return written;
}

void NodeRegistration::Report(const absl::Status& status) {
  const bool now = status.ok();
  if (registered_.exchange(now) != now) {
    if (options_.log) {
      options_.log(now ? absl::StrCat("cluster '", options_.cluster, "': registered as node '",
                                      options_.node.node_id, "' (", options_.node.role, ")")
                       : absl::StrCat("cluster '", options_.cluster, "': not registered: ",
                                      status.message(), "; retrying, still serving"));
    }
    if (on_change_) on_change_(now);
  } else if (!now && options_.log && std::string(status.message()) != last_problem_) {
    options_.log(absl::StrCat("cluster '", options_.cluster, "': ", status.message()));
  }
  last_problem_ = now ? "" : std::string(status.message());
}

void NodeRegistration::Run() {
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      const absl::Duration pause = registered() ? options_.lease_ttl / 3 : kRetryPause;
      // A change of shards is written at once while registered; otherwise with the next try.
      wake_.wait_for(lock, absl::ToChronoMilliseconds(pause),
                     [this] { return stopping_ || (dirty_ && registered()); });
      if (stopping_) return;
    }
    Report(Step());
  }
}

}  // namespace motiondb::cluster
