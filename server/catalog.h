// The database and the resident indices, kept in step. Every write (ingest or replace, rename
// and re-tag, delete, space creation and deletion) goes through here: it is stored in one
// transaction first, and the affected indices are rebuilt aside and swapped in afterwards, so a
// search sees either the library before the write or after it, never half of it, and never
// waits.
//
// Writes are serialised by one mutex: an ingest must see every space of its skeleton, and a new
// space must see every clip, so they cannot interleave. Reads do not take it.
//
// Every write takes a `should_stop` (the call's deadline or cancellation, server/grpc's
// StopWhenCallEnds), asked just before the database commits: true rolls the write back and
// returns CANCELLED, with the database and the indices as they were.
#ifndef MOTIONDB_SERVER_CATALOG_H_
#define MOTIONDB_SERVER_CATALOG_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "server/answer_limit.h"
#include "server/index_registry.h"
#include "server/skeleton_map.h"
#include "server/space_builder.h"
#include "storage/database.h"

namespace motiondb::server {

// What an ingest does when a clip of its name exists.
enum class OnConflict {
  // Skip when the existing clip's content is identical (the same content hash), refuse with
  // ALREADY_EXISTS otherwise: re-running a batch ingest is idempotent, and a real conflict is
  // never silently dropped or overwritten.
  kSkipIdentical,
  kError,    // ALREADY_EXISTS
  kSkip,     // keep the existing clip, store nothing
  kReplace,  // delete the existing clip and store the new one, in one transaction
};

enum class IngestResult { kStored, kSkipped, kReplaced };

struct IngestedClip {
  // As stored, with its id, skeleton, creation time and content hash; when skipped, the
  // existing clip.
  storage::ClipRecord record;
  IngestResult result = IngestResult::kStored;
  int64_t replaced_clip_id = 0;  // kReplaced: the deleted clip's id
  // Stored or replaced: other clips of identical content (up to kMaxDuplicatesReported, in id
  // order). Stored all the same: two names for one take can be deliberate.
  std::vector<storage::ClipRecord> duplicates;
  std::vector<std::string> spaces;  // projected into; none when skipped
};

inline constexpr int kMaxDuplicatesReported = 10;

struct IngestClipOptions {
  OnConflict on_conflict = OnConflict::kSkipIdentical;  // when a clip of its name exists
  // The new clip's id; 0: the database's next. A cluster's shard stores the ids its router hands
  // out (cluster/clip_id_blocks.h); a replacement may keep the replaced clip's.
  int64_t clip_id = 0;
};

struct UpdateClipOptions {
  // A cluster's router has reserved the new name cluster-wide: a shard node renames only then.
  bool name_reserved = false;
};

class Catalog {
 public:
  // `cluster_shard`: the database is a cluster's shard node's, whose clips come through a router
  // with ids unique cluster-wide (IngestClipOptions::clip_id) and names reserved cluster-wide: an
  // ingest without an id, and a rename without a reserved name (UpdateClipOptions), are refused
  // (FAILED_PRECONDITION).
  Catalog(storage::Database& database, IndexRegistry& registry, bool cluster_shard = false)
      : database_(database), registry_(registry), cluster_shard_(cluster_shard) {}

  // Loads every stored space and its cached projections into the registry (at start; nothing
  // is recomputed).
  absl::Status LoadIndices();

  // Stores the clip with its projection into every space of its skeleton, or, when a clip of
  // its name exists, does what `options.on_conflict` says: ALREADY_EXISTS (whose message, for
  // kSkipIdentical, says how to skip or replace), skip, or replace the existing clip in the
  // database and in every resident index. The database assigns the clip's skeleton, creation
  // time and content hash, and its id unless `options` gives it (ALREADY_EXISTS when held).
  absl::StatusOr<IngestedClip> IngestClip(const storage::ClipRecord& record, const Clip& clip,
                                          const IngestClipOptions& options = {},
                                          const std::function<bool()>& should_stop = {});
  absl::Status DeleteClip(int64_t clip_id, const std::function<bool()>& should_stop = {});
  // Renames and re-tags a clip (storage::Database::UpdateClip's rules and errors), and gives
  // every space of its skeleton a snapshot that shows the new name and tags.
  absl::StatusOr<storage::ClipRecord> UpdateClip(int64_t clip_id, const storage::ClipUpdate& update,
                                                 const UpdateClipOptions& options = {},
                                                 const std::function<bool()>& should_stop = {});

  // Stores `change` to skeleton `skeleton_id`'s humanoid map (storage::Database::
  // UpdateSlotOverrides, whose errors it returns) and shows the skeleton as updated. Its clips
  // are projected again into every space over several skeletons that lists it, whose poses
  // follow the map, in the same transaction, and those spaces' indices follow: a search sees the
  // old map or the new one. FAILED_PRECONDITION, nothing changed, when the map would then lack
  // a slot such a space needs; RESOURCE_EXHAUSTED when the answer could exceed `answers`.
  // `should_stop` is also polled between clips.
  absl::StatusOr<SkeletonMapView> MapSkeleton(int64_t skeleton_id,
                                              const storage::SlotOverrideChange& change,
                                              const AnswerLimit& answers,
                                              const std::function<bool()>& should_stop);

  // `should_stop` is also polled between clips while the space is built.
  absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> CreateSpace(
      const SpaceRequest& request, const std::function<bool()>& should_stop);
  absl::Status DeleteSpace(const std::string& name, const std::function<bool()>& should_stop = {});

 private:
  absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> LoadSpace(
      const storage::SpaceRecord& record);
  // For IngestClip, under write_mutex_: the ingest of a clip whose name `existing` has, when
  // `on_conflict` says not to replace it (skipped, or the error); nullopt when it is replaced.
  absl::StatusOr<std::optional<IngestedClip>> ResolveConflict(const storage::ClipRecord& existing,
                                                              const Clip& clip,
                                                              OnConflict on_conflict);
  // Under write_mutex_: replaces the snapshot of every space of the skeleton with `change`'s
  // (INTERNAL saying the index is stale when that fails).
  absl::Status ChangeIndices(
      int64_t skeleton_id, const std::function<absl::StatusOr<std::shared_ptr<const SpaceSnapshot>>(
                               const SpaceSnapshot&)>& change);
  // For IngestClip, under write_mutex_: puts `ingested` (stored, replacing `replaced` when
  // given) into the indices of `spaces`, its skeleton's, whose projections those are, and drops
  // `replaced` from the indices of its own skeleton when that is another.
  absl::Status IndexIngested(IngestedClip& ingested,
                             const std::vector<std::shared_ptr<const SpaceSnapshot>>& spaces,
                             std::vector<std::pair<int64_t, storage::Projection>> projections,
                             const std::optional<storage::ClipRecord>& replaced);

  storage::Database& database_;
  IndexRegistry& registry_;
  const bool cluster_shard_;
  std::mutex write_mutex_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_CATALOG_H_
