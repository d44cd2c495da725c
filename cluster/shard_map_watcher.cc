#include "cluster/shard_map_watcher.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "cluster/cluster_keys.h"

namespace motiondb::cluster {
namespace {

// Between CurrentMap's reads while etcd is unreachable.
constexpr absl::Duration kReadRetry = absl::Milliseconds(250);

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
                  } else if (options_.log) {
                    options_.log(absl::StrCat("cluster '", options_.cluster,
                                              "': ignored a shard map: ", map.status().message()));
                  }
                }
              },
          .resync = [this] { Refresh(); },
          .connected =
              [this](bool connected) {
                if (connected) Refresh();
              }});
}

ShardMapWatcher::~ShardMapWatcher() { watch_.reset(); }

std::shared_ptr<const ShardMap> ShardMapWatcher::map() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return map_;
}

absl::StatusOr<ShardMap> ShardMapWatcher::CurrentMap(absl::Time deadline) const {
  for (;;) {
    const absl::StatusOr<StoredShardMap> read = store_.Read(deadline);
    if (read.ok()) return read->map;
    const bool unreachable =
        absl::IsUnavailable(read.status()) || absl::IsDeadlineExceeded(read.status());
    const absl::Duration left = deadline - absl::Now();
    if (!unreachable) return read.status();  // no cluster, or a map that is not one
    if (left <= absl::ZeroDuration()) {
      const std::shared_ptr<const ShardMap> last = map();
      return absl::UnavailableError(
          absl::StrCat("cluster '", options_.cluster, "': the shard map cannot be read (",
                       last == nullptr ? std::string("no map seen yet")
                                       : absl::StrCat("the last map seen is epoch ", last->epoch),
                       "): ", read.status().message()));
    }
    absl::SleepFor(std::min(left, kReadRetry));
  }
}

void ShardMapWatcher::Refresh() {
  const absl::StatusOr<StoredShardMap> read = store_.Read();
  if (read.ok()) {
    Offer(read->map);
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
