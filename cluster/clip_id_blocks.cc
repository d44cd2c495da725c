#include "cluster/clip_id_blocks.h"

#include <limits>

#include "absl/strings/str_cat.h"
#include "cluster/cluster_keys.h"
#include "util/status_macros.h"

namespace motiondb::cluster {
namespace {

// Each failed attempt means another router reserved a block meanwhile, so routers starve one
// another only when far more of them than this reserve at once.
constexpr int kMaxReserveAttempts = 50;

}  // namespace

ClipIdBlocks::ClipIdBlocks(const EtcdClient& etcd, const std::string& cluster, int64_t block_size)
    : etcd_(etcd), key_(NextClipIdKey(cluster)), block_size_(block_size) {}

absl::StatusOr<int64_t> ClipIdBlocks::Next() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (next_ == end_) MOTIONDB_RETURN_IF_ERROR(ReserveBlock());
  return next_++;
}

absl::Status ClipIdBlocks::ReserveBlock() {
  if (block_size_ < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("clip ids are reserved in blocks of at least 1, not ", block_size_));
  }
  MOTIONDB_ASSIGN_OR_RETURN(std::optional<KeyValue> counter, etcd_.Get(key_));
  for (int attempt = 0; attempt < kMaxReserveAttempts; ++attempt) {
    int64_t first = 1;  // an absent counter: no id reserved yet
    if (counter) {
      MOTIONDB_ASSIGN_OR_RETURN(first, PositiveDecimalOf(key_, counter->value));
    }
    if (first > std::numeric_limits<int64_t>::max() - block_size_) {
      return absl::ResourceExhaustedError(
          absl::StrCat("etcd key '", key_, "': the clip ids are used up"));
    }
    MOTIONDB_ASSIGN_OR_RETURN(const SwapOutcome outcome,
                              etcd_.CompareAndSwap(key_, counter ? counter->mod_revision : 0,
                                                   absl::StrCat(first + block_size_)));
    if (outcome.written) {
      next_ = first;
      end_ = first + block_size_;
      return absl::OkStatus();
    }
    counter = outcome.current;  // another router's reservation: try again from there
  }
  return absl::AbortedError(absl::StrCat("could not reserve clip ids: etcd key '", key_,
                                         "' changed under each of ", kMaxReserveAttempts,
                                         " attempts (too many routers reserving at once?)"));
}

}  // namespace motiondb::cluster
