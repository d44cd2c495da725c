#include "cluster/shard_map_watcher.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "cluster/cluster_keys.h"

namespace motiondb::cluster {
namespace {

// How often CurrentMap reads the map again while neither a read nor the stream confirms it.
constexpr absl::Duration kConfirmRetry = absl::Milliseconds(250);

}  // namespace

ShardMapWatcher::ShardMapWatcher(const EtcdClient& etcd, const ClusterOptions& options,
                                 std::function<void(const ShardMap&)> on_change)
    : store_(etcd, options.cluster), options_(options), on_change_(std::move(on_change)) {
  const std::string key = ShardMapKey(options.cluster);
  watch_ = etcd.Watch(
      key, 0,
      EtcdWatch::Callbacks{
          .events =
              [this, key](const std::vector<WatchEvent>& events) {
                for (const WatchEvent& event : events) {
                  if (event.deleted || event.kv->key != key) continue;
                  const absl::StatusOr<ShardMap> map = ShardMap::FromJson(event.kv->value);
                  if (map.ok()) {
                    Offer(*map);
                    SetCurrent(true);  // delivered by the open stream
                  } else if (options_.log) {
                    options_.log(absl::StrCat("cluster '", options_.cluster,
                                              "': ignored a shard map: ", map.status().message()));
                  }
                }
              },
          .resync = [this] { Refresh(); },
          .connected =
              [this](bool connected) {
                if (connected) {
                  Refresh();
                } else {
                  SetCurrent(false);
                }
              }});
}

ShardMapWatcher::~ShardMapWatcher() { watch_.reset(); }

std::shared_ptr<const ShardMap> ShardMapWatcher::map() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return map_;
}

absl::StatusOr<std::shared_ptr<const ShardMap>> ShardMapWatcher::CurrentMap(
    absl::Time deadline) const {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (current_) return map_;
  }
  // Not confirmed by the stream (none open, or its first read failed): a read of the map
  // confirms it as of that read, tried again until the deadline.
  for (;;) {
    const absl::StatusOr<StoredShardMap> read = store_.Read(deadline);
    if (absl::IsNotFound(read.status())) return read.status();  // no cluster: no waiting helps
    std::unique_lock<std::mutex> lock(mutex_);
    if (read.ok() || current_) {
      if (read.ok() && (map_ == nullptr || read->map.epoch > map_->epoch)) {
        return std::make_shared<const ShardMap>(read->map);  // the watch will offer it too
      }
      return map_;  // as new as the read, or confirmed by the stream meanwhile
    }
    const absl::Duration left = deadline - absl::Now();
    if (left <= absl::ZeroDuration()) {
      return absl::UnavailableError(
          absl::StrCat("cluster '", options_.cluster, "': the shard map cannot be confirmed (",
                       map_ == nullptr ? std::string("no map seen yet")
                                       : absl::StrCat("the last map seen is epoch ", map_->epoch),
                       "): ", read.status().message()));
    }
    // Woken early when the stream confirms the map; else read again.
    current_changed_.wait_for(lock, absl::ToChronoNanoseconds(std::min(left, kConfirmRetry)),
                              [this] { return current_; });
    if (current_) return map_;
  }
}

void ShardMapWatcher::SetCurrent(bool current) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    current_ = current && map_ != nullptr;
  }
  current_changed_.notify_all();
}

void ShardMapWatcher::Refresh() {
  const absl::StatusOr<StoredShardMap> read = store_.Read();
  SetCurrent(false);  // until the read is offered: a resync means the map held may be old
  if (read.ok()) {
    Offer(read->map);
    SetCurrent(true);
  } else if (options_.log && map() == nullptr) {
    options_.log(std::string(read.status().message()));  // it names the cluster
  }
}

void ShardMapWatcher::Offer(const ShardMap& map) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (map_ != nullptr && map.epoch <= map_->epoch) return;
    map_ = std::make_shared<const ShardMap>(map);
  }
  if (options_.log) {
    options_.log(absl::StrCat("cluster '", options_.cluster, "': shard map epoch ", map.epoch, ", ",
                              map.ShardsOf(options_.node.node_id).size(), " of ", map.shard_count(),
                              " shards here"));
  }
  if (on_change_) on_change_(map);
}

}  // namespace motiondb::cluster
