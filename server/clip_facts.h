// Per-clip facts that the catalogue (storage::ClipRecord) does not carry but every listing and
// every frame conversion needs: the original frame rate, frame count and joint count. Learning
// them means loading the clip's frames once; this cache keeps them so that happens once per clip
// per server run (at ingest for new clips, at startup or first listing for stored ones).
#ifndef MOTIONDB_SERVER_CLIP_FACTS_H_
#define MOTIONDB_SERVER_CLIP_FACTS_H_

#include <cstdint>
#include <mutex>

#include "absl/container/flat_hash_map.h"
#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "storage/database.h"

namespace motiondb::server {

struct ClipFacts {
  double fps = 0;
  int frame_count = 0;
  int joint_count = 0;

  static ClipFacts Of(const Clip& clip) {
    return {clip.fps(), clip.frame_count(), clip.skeleton().joint_count()};
  }
  static ClipFacts Of(const storage::ClipRecord& record) {
    return {1.0 / record.frame_time, static_cast<int>(record.frame_count), record.joint_count};
  }
};

// Thread-safe.
class ClipFactsCache {
 public:
  explicit ClipFactsCache(storage::Database& database) : database_(database) {}

  // From the cache, or from the clip's stored record (NOT_FOUND when it does not exist).
  absl::StatusOr<ClipFacts> Get(int64_t clip_id);
  void Put(int64_t clip_id, const ClipFacts& facts);
  void Erase(int64_t clip_id);

 private:
  storage::Database& database_;
  std::mutex mutex_;
  absl::flat_hash_map<int64_t, ClipFacts> facts_;
  uint64_t erasures_ = 0;  // Erase() calls so far
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_CLIP_FACTS_H_
