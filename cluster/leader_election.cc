#include "cluster/leader_election.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "cluster/cluster_keys.h"
#include "cluster/internal/lease_keeper.h"
#include "util/status_macros.h"

namespace motiondb::cluster {
namespace {

// Between attempts while etcd does not answer.
constexpr absl::Duration kRetryPause = absl::Seconds(1);

}  // namespace

absl::StatusOr<std::unique_ptr<LeaderElection>> LeaderElection::Start(
    const EtcdClient& etcd, const std::string& cluster, const std::string& office,
    const std::string& node_id, absl::Duration lease_ttl,
    std::function<void(bool leading)> on_change) {
  MOTIONDB_RETURN_IF_ERROR(CheckClusterName(cluster, "cluster name"));
  MOTIONDB_RETURN_IF_ERROR(CheckClusterName(office, "office"));
  MOTIONDB_RETURN_IF_ERROR(CheckClusterName(node_id, "node id"));
  if (lease_ttl < absl::Seconds(1)) {
    return absl::InvalidArgumentError(absl::StrCat("an election's lease TTL is at least 1s, not ",
                                                   absl::FormatDuration(lease_ttl)));
  }
  std::unique_ptr<LeaderElection> election(new LeaderElection(
      etcd, ElectionKey(cluster, office), node_id, lease_ttl, std::move(on_change)));
  // The first attempt too is the thread's: a server starts without waiting on etcd.
  election->thread_ = std::thread([raw = election.get()] { raw->Run(); });
  return election;
}

LeaderElection::LeaderElection(const EtcdClient& etcd, std::string key, std::string node_id,
                               absl::Duration lease_ttl, std::function<void(bool)> on_change)
    : etcd_(etcd),
      key_(std::move(key)),
      node_id_(std::move(node_id)),
      lease_ttl_(lease_ttl),
      on_change_(std::move(on_change)),
      lease_(std::make_unique<LeaseKeeper>(etcd, lease_ttl)) {}

LeaderElection::~LeaderElection() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  // Revoking the lease deletes the key too; deleted first, the office is free at once even when
  // the revocation fails (the lease then lives out its TTL). By revision, so that a key another
  // candidate holds by now stays. Not when etcd did not answer the last step: the call would
  // only wait out its timeout, and the key goes with the lease anyway.
  if (revision_ != 0 && last_step_ok_) etcd_.DeleteIfRevision(key_, revision_).IgnoreError();
}

bool LeaderElection::leading() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return Clock::now() < leading_until_;
}

absl::StatusOr<std::optional<std::string>> LeaderElection::CurrentLeader() const {
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<KeyValue> held, etcd_.Get(key_));
  if (!held) return std::nullopt;
  return std::optional<std::string>(held->value);
}

void LeaderElection::SetLeading(bool leading) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    leading_until_ = leading ? lease_->surely_until() : Clock::time_point::min();
  }
  if (leading == reported_) return;
  reported_ = leading;
  if (on_change_) on_change_(leading);
}

void LeaderElection::Lose(bool drop_lease) {
  revision_ = 0;
  // A renewal that may have come too late may still have kept the key: dropped with the lease,
  // the office is free now rather than held by no one who knows it.
  if (drop_lease) lease_->Drop();
  // Standing back a TTL before trying again lets a candidate that has been waiting (trying every
  // third of it) take the office, rather than a leader cut off from etcd racing it on its return.
  stand_back_until_ = Clock::now() + absl::ToChronoMilliseconds(lease_ttl_);
  SetLeading(false);
}

void LeaderElection::CheckLease() {
  if (revision_ != 0 && Clock::now() >= lease_->surely_until()) Lose(/*drop_lease=*/true);
}

absl::Status LeaderElection::Step() {
  CheckLease();  // before a call that may take long: the lease may run out meanwhile
  const absl::StatusOr<bool> new_lease = lease_->Renew();
  if (!new_lease.ok()) {
    CheckLease();
    return new_lease.status();
  }
  if (*new_lease && revision_ != 0) Lose(false);  // the old lease expired, and the key with it
  if (Stopping()) return absl::OkStatus();
  if (revision_ != 0) {
    // The key must be the one written: deleted or rewritten, another may have led meanwhile.
    MOTIONDB_ASSIGN_OR_RETURN(const std::optional<KeyValue> held, etcd_.Get(key_));
    if (!held || held->mod_revision != revision_) {
      Lose(false);
      return absl::OkStatus();
    }
  } else {
    if (Clock::now() < stand_back_until_) return absl::OkStatus();
    MOTIONDB_ASSIGN_OR_RETURN(const SwapOutcome outcome,
                              etcd_.CompareAndSwap(key_, 0, node_id_, lease_->id()));
    if (outcome.written) {
      revision_ = outcome.revision;
    } else if (outcome.current && outcome.current->lease == lease_->id()) {
      revision_ = outcome.current->mod_revision;  // written by an attempt whose answer was lost
    } else {
      return absl::OkStatus();  // another leads
    }
  }
  // The calls took longer than the lease surely lives: not a leader to report.
  if (Clock::now() >= lease_->surely_until()) {
    Lose(/*drop_lease=*/true);
    return absl::OkStatus();
  }
  SetLeading(true);
  return absl::OkStatus();
}

bool LeaderElection::Stopping() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stopping_;
}

void LeaderElection::Run() {
  for (;;) {
    last_step_ok_ = Step().ok();
    std::unique_lock<std::mutex> lock(mutex_);
    Clock::time_point next =
        Clock::now() + absl::ToChronoMilliseconds(last_step_ok_ ? lease_ttl_ / 3 : kRetryPause);
    // Leading, wake when the lease may run out, to say so then rather than after a retry.
    if (revision_ != 0) next = std::min(next, lease_->surely_until());
    if (wake_.wait_until(lock, next, [this] { return stopping_; })) return;
  }
}

}  // namespace motiondb::cluster
