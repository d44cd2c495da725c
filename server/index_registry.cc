#include "server/index_registry.h"

#include <malloc.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <initializer_list>
#include <utility>

#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// Every clip of `base`, except `skip_ids`, as clips to index again.
std::vector<IndexedClip> ClipsOf(const SpaceSnapshot& base,
                                 std::initializer_list<int64_t> skip_ids) {
  std::vector<IndexedClip> clips;
  if (!base.index) return clips;
  for (int c = 0; c < base.index->clip_count(); ++c) {
    const LibraryIndex::ClipEntry& entry = base.index->clip(c);
    if (std::find(skip_ids.begin(), skip_ids.end(), entry.clip_id) != skip_ids.end()) continue;
    clips.push_back({{entry.clip_id, entry.name, entry.tags, base.index->CopyClipCoordinates(c)},
                     base.clips.at(entry.clip_id)});
  }
  return clips;
}

// A copy of `base`'s record, space and timings, to which an index is given.
std::shared_ptr<SpaceSnapshot> CopyOfSnapshot(const SpaceSnapshot& base) {
  auto snapshot = std::make_shared<SpaceSnapshot>();
  snapshot->record = base.record;
  snapshot->space = base.space;
  snapshot->clips = base.clips;
  return snapshot;
}

}  // namespace

FrameConversion SpaceSnapshot::Conversion(int64_t clip_id) const {
  const ClipTiming& timing = clips.at(clip_id);
  const LibraryIndex::ClipEntry& entry = index->clip(index->FindClip(clip_id));
  return FrameConversion(timing.fps, timing.frame_count, space->sample_rate(), entry.frame_count);
}

absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> BuildSnapshot(
    storage::SpaceRecord record, std::shared_ptr<const MotionSpace> space,
    std::vector<IndexedClip> clips) {
  auto snapshot = std::make_shared<SpaceSnapshot>();
  snapshot->record = std::move(record);
  snapshot->space = std::move(space);
  if (clips.empty()) return snapshot;
  std::sort(clips.begin(), clips.end(), [](const IndexedClip& a, const IndexedClip& b) {
    return a.clip.clip_id < b.clip.clip_id;
  });
  std::vector<LibraryClip> library;
  library.reserve(clips.size());
  for (IndexedClip& clip : clips) {
    snapshot->clips.emplace(clip.clip.clip_id, clip.timing);
    library.push_back(std::move(clip.clip));
  }
  // The kd-tree's dimensions: the search's default seed dimensions, or all of a smaller space's.
  LibraryIndexOptions options;
  options.ann_dims = std::min(options.ann_dims, snapshot->space->dims());
  MOTIONDB_ASSIGN_OR_RETURN(
      std::unique_ptr<LibraryIndex> index,
      LibraryIndex::Build(std::move(library), snapshot->space->sample_rate(), options));
  snapshot->index = std::move(index);
  return snapshot;
}

absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> SnapshotWithClip(const SpaceSnapshot& base,
                                                                      IndexedClip clip,
                                                                      int64_t replaced_clip_id) {
  const int64_t clip_id = clip.clip.clip_id;
  if (base.index && !base.clips.contains(clip_id) && !base.clips.contains(replaced_clip_id)) {
    // Only a new clip: added beside the base's index, sharing its coordinates and kd-trees.
    std::shared_ptr<SpaceSnapshot> snapshot = CopyOfSnapshot(base);
    snapshot->clips.emplace(clip_id, clip.timing);
    std::vector<LibraryClip> added;
    added.push_back(std::move(clip.clip));
    MOTIONDB_ASSIGN_OR_RETURN(snapshot->index, base.index->WithClips(std::move(added)));
    return snapshot;
  }
  std::vector<IndexedClip> clips = ClipsOf(base, {clip_id, replaced_clip_id});
  clips.push_back(std::move(clip));
  return BuildSnapshot(base.record, base.space, std::move(clips));
}

absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> SnapshotWithoutClip(const SpaceSnapshot& base,
                                                                         int64_t clip_id) {
  if (!base.clips.contains(clip_id)) {
    return std::shared_ptr<const SpaceSnapshot>(std::make_shared<SpaceSnapshot>(base));
  }
  return BuildSnapshot(base.record, base.space, ClipsOf(base, {clip_id}));
}

absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> SnapshotWithClipInfo(
    const SpaceSnapshot& base, int64_t clip_id, const std::string& name,
    const std::vector<std::string>& tags) {
  if (!base.clips.contains(clip_id)) {
    return std::shared_ptr<const SpaceSnapshot>(std::make_shared<SpaceSnapshot>(base));
  }
  std::shared_ptr<SpaceSnapshot> snapshot = CopyOfSnapshot(base);
  MOTIONDB_ASSIGN_OR_RETURN(snapshot->index, base.index->WithClipInfo(clip_id, name, tags));
  return snapshot;
}

std::shared_ptr<const SpaceSnapshot> IndexRegistry::Find(const std::string& name) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = spaces_.find(name);
  return it == spaces_.end() ? nullptr : it->second;
}

std::vector<std::shared_ptr<const SpaceSnapshot>> IndexRegistry::All() const {
  std::vector<std::shared_ptr<const SpaceSnapshot>> all;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [name, snapshot] : spaces_) all.push_back(snapshot);
  }
  std::sort(all.begin(), all.end(),
            [](const auto& a, const auto& b) { return a->record.space_id < b->record.space_id; });
  return all;
}

std::vector<std::shared_ptr<const SpaceSnapshot>> IndexRegistry::OfSkeleton(
    int64_t skeleton_id) const {
  std::vector<std::shared_ptr<const SpaceSnapshot>> spaces = All();
  std::erase_if(spaces, [&](const auto& s) {
    return s->record.skeleton_id != skeleton_id &&
           std::find(s->record.skeleton_ids.begin(), s->record.skeleton_ids.end(), skeleton_id) ==
               s->record.skeleton_ids.end();
  });
  return spaces;
}

namespace {

// After a swap, gives what the process has freed back to the system: glibc keeps what its
// arenas free (a large index freed among live blocks cannot be returned by shrinking the heap).
// The replaced snapshot itself is often still held, by the write that made the new one or by
// searches, and its memory is returned at the next swap; so is whatever the last write freed.
// With main.cc's allocator settings, a library grown by 16 ingesting clients went from 1.6-2.4x
// the resident memory of the same library loaded fresh to 1.1x
// (bench/notes/2026-12-05-memory-growth.md).
void Release(std::shared_ptr<const SpaceSnapshot> old) {
  old.reset();
#ifdef __GLIBC__
  // At most a few times a second: a trim walks every arena, and ingest swaps many times a
  // second under concurrent clients.
  constexpr auto kTrimInterval = std::chrono::milliseconds(250);
  static std::atomic<std::chrono::steady_clock::rep> last_trim{0};
  const auto now = std::chrono::steady_clock::now().time_since_epoch();
  auto last = last_trim.load(std::memory_order_relaxed);
  if (now.count() - last < std::chrono::steady_clock::duration(kTrimInterval).count()) return;
  if (!last_trim.compare_exchange_strong(last, now.count())) return;
  malloc_trim(0);
#endif
}

}  // namespace

void IndexRegistry::Put(std::shared_ptr<const SpaceSnapshot> snapshot) {
  // The old snapshot is released outside the lock: freeing a large index takes a while, and
  // readers holding it keep it alive anyway.
  std::shared_ptr<const SpaceSnapshot> old;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    std::shared_ptr<const SpaceSnapshot>& slot = spaces_[snapshot->record.name];
    old = std::move(slot);
    slot = std::move(snapshot);
  }
  Release(std::move(old));
}

void IndexRegistry::Remove(const std::string& name) {
  std::shared_ptr<const SpaceSnapshot> old;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = spaces_.find(name);
    if (it == spaces_.end()) return;
    old = std::move(it->second);
    spaces_.erase(it);
  }
  Release(std::move(old));
}

}  // namespace motiondb::server
