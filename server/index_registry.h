// The resident search indices, one immutable snapshot per space. Readers take a snapshot (a
// shared_ptr copied under a short lock) and search it without further locking; writers build a
// new snapshot aside (from the old one's coordinates plus or minus a clip, never re-reading the
// database) and swap it in. A search therefore never waits for an ingest or a rebuild, and
// always sees one consistent library.
#ifndef MOTIONDB_SERVER_INDEX_REGISTRY_H_
#define MOTIONDB_SERVER_INDEX_REGISTRY_H_

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/status/statusor.h"
#include "core/index/library_index.h"
#include "core/space/motion_space.h"
#include "server/frame_conversion.h"
#include "storage/database.h"

namespace motiondb::server {

// An indexed clip's own rate and frame count, which its index entry (at the space rate) does
// not know and every frame conversion needs.
struct ClipTiming {
  double fps = 0;
  int frame_count = 0;

  static ClipTiming Of(const storage::ClipRecord& record) {
    return {1.0 / record.frame_time, static_cast<int>(record.frame_count)};
  }
};

// A clip to index: its id, name, tags and projection (frames at the space rate x the space's
// dims, pre-scaled by the metric, as storage::Projection holds it), and its timing.
struct IndexedClip {
  LibraryClip clip;
  ClipTiming timing;
};

struct SpaceSnapshot {
  storage::SpaceRecord record;
  std::shared_ptr<const MotionSpace> space;
  // Null when the space's skeleton has no clips left.
  std::shared_ptr<const LibraryIndex> index;
  // Every indexed clip's timing; names and tags are the index's.
  absl::flat_hash_map<int64_t, ClipTiming> clips;

  // The indexed clip's frame mapping; the clip must be indexed.
  FrameConversion Conversion(int64_t clip_id) const;
  int64_t coordinate_bytes() const { return index ? index->coordinate_bytes() : 0; }
  int64_t tree_bytes() const { return index ? index->tree_bytes() : 0; }
};

// Snapshot construction; pure functions.
// A snapshot of `clips` (any order; indexed in clip id order).
absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> BuildSnapshot(
    storage::SpaceRecord record, std::shared_ptr<const MotionSpace> space,
    std::vector<IndexedClip> clips);
// `base` with `clip` added (or replaced, when its id is indexed already), and without the clip
// `replaced_clip_id` when that is indexed (0: none). A new clip alone goes into the index's
// small second block; dropping one rebuilds the index.
absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> SnapshotWithClip(const SpaceSnapshot& base,
                                                                      IndexedClip clip,
                                                                      int64_t replaced_clip_id = 0);
// `base` with the clip's name and tags changed, sharing its coordinates and kd-trees; `base`
// itself when the clip is not indexed.
absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> SnapshotWithClipInfo(
    const SpaceSnapshot& base, int64_t clip_id, const std::string& name,
    const std::vector<std::string>& tags);
// `base` without the clip; `base` itself when the clip is not indexed.
absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> SnapshotWithoutClip(const SpaceSnapshot& base,
                                                                         int64_t clip_id);

// Thread-safe.
class IndexRegistry {
 public:
  // Null when no space has that name.
  std::shared_ptr<const SpaceSnapshot> Find(const std::string& name) const;
  // Every space, in space id order.
  std::vector<std::shared_ptr<const SpaceSnapshot>> All() const;
  // Over this skeleton alone, or over several among them.
  std::vector<std::shared_ptr<const SpaceSnapshot>> OfSkeleton(int64_t skeleton_id) const;
  // Adds the snapshot, or replaces the one of the same name.
  void Put(std::shared_ptr<const SpaceSnapshot> snapshot);
  void Remove(const std::string& name);

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<const SpaceSnapshot>> spaces_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_INDEX_REGISTRY_H_
