// One gRPC channel to each etcd member, and the member calls go to first. Thread-safe.
#ifndef MOTIONDB_CLUSTER_INTERNAL_ETCD_CHANNELS_H_
#define MOTIONDB_CLUSTER_INTERNAL_ETCD_CHANNELS_H_

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "absl/status/status.h"
#include "cluster/etcd_options.h"

namespace motiondb::cluster {

class EtcdChannels {
 public:
  explicit EtcdChannels(EtcdOptions options);

  // Runs `attempt` on the member last known good, then on the next ones while it fails as a
  // member that is down or cut off fails (UNAVAILABLE, or its attempt's deadline), each member
  // at most once and all within the call's timeout, or by `deadline` when that is sooner
  // (passed, it is DEADLINE_EXCEEDED and no member is blamed). The context carries the deadline.
  // A write retried this way may have been applied by the member that did not answer: callers
  // keep their writes idempotent or compare-and-swap.
  absl::Status Call(const std::function<grpc::Status(const std::shared_ptr<grpc::Channel>& channel,
                                                     grpc::ClientContext& context)>& attempt,
                    absl::Time deadline = absl::InfiniteFuture()) const;

  // The member to open a stream on, and the one after it when that one failed.
  size_t current() const { return current_.load(); }
  void Failed(size_t member) const;
  const std::shared_ptr<grpc::Channel>& channel(size_t member) const { return channels_[member]; }
  const std::string& endpoint(size_t member) const { return options_.endpoints[member]; }
  const EtcdOptions& options() const { return options_; }

 private:
  EtcdOptions options_;
  std::vector<std::shared_ptr<grpc::Channel>> channels_;
  mutable std::atomic<size_t> current_{0};
};

// grpc::Status -> absl::Status (the codes are the same numbers), naming the member.
absl::Status FromGrpc(const grpc::Status& status, const std::string& endpoint);

}  // namespace motiondb::cluster

#endif  // MOTIONDB_CLUSTER_INTERNAL_ETCD_CHANNELS_H_
