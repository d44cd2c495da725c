#include "server/catalog.h"

#include "absl/strings/str_cat.h"
#include "core/space/canonical_pose.h"
#include "core/space/search_coordinates.h"
#include "server/skeleton_map.h"
#include "storage/content_hash.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::server {
namespace {

// The database write is done when an index swap fails, so the error says that the write stands
// and the index is stale until the next write or restart.
absl::Status StaleIndexError(const std::string& space, const absl::Status& status) {
  return absl::InternalError(absl::StrCat("stored, but the index of space ", space,
                                          " could not be rebuilt: ", status.message()));
}

}  // namespace

absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> Catalog::LoadSpace(
    const storage::SpaceRecord& record) {
  MOTIONDB_ASSIGN_OR_RETURN(MotionSpace space, database_.GetSpace(record.space_id));
  MOTIONDB_ASSIGN_OR_RETURN(std::vector<storage::Projection> projections,
                            database_.LoadProjections(record.space_id));
  std::vector<IndexedClip> clips;
  clips.reserve(projections.size());
  for (storage::Projection& projection : projections) {
    MOTIONDB_ASSIGN_OR_RETURN(storage::ClipRecord clip,
                              database_.GetClipRecord(projection.clip_id));
    const ClipTiming timing = ClipTiming::Of(clip);
    clips.push_back({{projection.clip_id, std::move(clip.name), std::move(clip.tags),
                      std::move(projection.coordinates)},
                     timing});
  }
  return BuildSnapshot(record, std::make_shared<const MotionSpace>(std::move(space)),
                       std::move(clips));
}

absl::Status Catalog::LoadIndices() {
  std::lock_guard<std::mutex> lock(write_mutex_);
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<storage::SpaceRecord> records,
                            database_.ListSpaces());
  for (const storage::SpaceRecord& record : records) {
    MOTIONDB_ASSIGN_OR_RETURN(
        std::shared_ptr<const SpaceSnapshot> snapshot,
        Prefixed(absl::StrCat("loading space ", record.name), LoadSpace(record)));
    registry_.Put(std::move(snapshot));
  }
  return absl::OkStatus();
}

absl::Status Catalog::ChangeIndices(
    int64_t skeleton_id,
    const std::function<absl::StatusOr<std::shared_ptr<const SpaceSnapshot>>(const SpaceSnapshot&)>&
        change) {
  for (const auto& space : registry_.OfSkeleton(skeleton_id)) {
    absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> updated = change(*space);
    if (!updated.ok()) return StaleIndexError(space->record.name, updated.status());
    registry_.Put(*std::move(updated));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::optional<IngestedClip>> Catalog::ResolveConflict(
    const storage::ClipRecord& existing, const Clip& clip, OnConflict on_conflict) {
  const std::string taken = absl::StrCat("a clip named '", existing.name, "' already exists (clip ",
                                         existing.clip_id, ")");
  IngestedClip skipped;
  skipped.record = existing;
  skipped.result = IngestResult::kSkipped;
  switch (on_conflict) {
    case OnConflict::kReplace:
      return std::nullopt;
    case OnConflict::kSkip:
      return skipped;
    case OnConflict::kError:
      return absl::AlreadyExistsError(taken);
    case OnConflict::kSkipIdentical:
      break;
  }
  MOTIONDB_ASSIGN_OR_RETURN(const std::string content_hash, storage::ContentHash(clip));
  if (content_hash == existing.content_hash) return skipped;
  return absl::AlreadyExistsError(
      absl::StrCat(taken,
                   " with other content; pass on_conflict skip to keep it, or replace to "
                   "store this file in its place"));
}

absl::Status Catalog::IndexIngested(
    IngestedClip& ingested, const std::vector<std::shared_ptr<const SpaceSnapshot>>& spaces,
    std::vector<std::pair<int64_t, storage::Projection>> projections,
    const std::optional<storage::ClipRecord>& replaced) {
  const storage::ClipRecord& record = ingested.record;
  const int64_t replaced_id = replaced ? replaced->clip_id : 0;
  const ClipTiming timing = ClipTiming::Of(record);
  for (size_t i = 0; i < spaces.size(); ++i) {
    absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> updated = SnapshotWithClip(
        *spaces[i],
        {{record.clip_id, record.name, record.tags, std::move(projections[i].second.coordinates)},
         timing},
        replaced_id);
    if (!updated.ok()) return StaleIndexError(spaces[i]->record.name, updated.status());
    registry_.Put(*std::move(updated));
    ingested.spaces.push_back(spaces[i]->record.name);
  }
  // The spaces above have dropped the replaced clip if it was theirs; another skeleton's have not.
  if (replaced && replaced->skeleton_id != record.skeleton_id) {
    return ChangeIndices(replaced->skeleton_id, [&](const SpaceSnapshot& space) {
      return SnapshotWithoutClip(space, replaced_id);
    });
  }
  return absl::OkStatus();
}

absl::StatusOr<IngestedClip> Catalog::IngestClip(const storage::ClipRecord& record,
                                                 const Clip& clip, const IngestClipOptions& options,
                                                 const std::function<bool()>& should_stop) {
  if (cluster_shard_ && options.clip_id == 0) {
    return absl::FailedPreconditionError(
        "this node is a cluster's shard node: clips are stored through a router, which gives "
        "them ids and names unique in the cluster");
  }
  std::lock_guard<std::mutex> lock(write_mutex_);
  // Decided before the projections are computed, which a skip or a refusal does not need. The
  // database checks the name again in the insert's transaction.
  std::optional<storage::ClipRecord> replaced;
  absl::StatusOr<storage::ClipRecord> existing = database_.GetClipRecordByName(record.name);
  if (existing.ok()) {
    MOTIONDB_ASSIGN_OR_RETURN(std::optional<IngestedClip> kept,
                              ResolveConflict(*existing, clip, options.on_conflict));
    if (kept) return *std::move(kept);
    replaced = *std::move(existing);
  } else if (!absl::IsNotFound(existing.status())) {
    return existing.status();
  }

  MOTIONDB_ASSIGN_OR_RETURN(const int64_t skeleton_id, database_.FindSkeleton(clip.skeleton()));
  std::vector<std::shared_ptr<const SpaceSnapshot>> spaces;
  if (skeleton_id >= 0) spaces = registry_.OfSkeleton(skeleton_id);
  std::vector<std::pair<int64_t, storage::Projection>> projections;
  std::optional<HumanoidMap> map;  // for the spaces over several skeletons
  for (const auto& space : spaces) {
    if (space->space->canonical() && !map) {
      MOTIONDB_ASSIGN_OR_RETURN(map, CanonicalMapOfSkeleton(database_, skeleton_id));
    }
    MOTIONDB_ASSIGN_OR_RETURN(
        RowMatrixXf coordinates,
        SearchCoordinates(*space->space, clip, -1, space->space->canonical() ? &*map : nullptr));
    projections.push_back({space->record.space_id, storage::Projection{0, std::move(coordinates)}});
  }
  const storage::InsertClipOptions insert{.replace_clip_id = replaced ? replaced->clip_id : 0,
                                          .clip_id = options.clip_id};
  MOTIONDB_ASSIGN_OR_RETURN(
      const int64_t clip_id,
      database_.InsertClip(record, clip, projections, insert, {.should_stop = should_stop}));
  IngestedClip ingested;
  MOTIONDB_ASSIGN_OR_RETURN(ingested.record, database_.GetClipRecord(clip_id));
  if (replaced) {
    ingested.result = IngestResult::kReplaced;
    ingested.replaced_clip_id = replaced->clip_id;
  }
  MOTIONDB_RETURN_IF_ERROR(IndexIngested(ingested, spaces, std::move(projections), replaced));

  // One more than reported, since the new clip is among them.
  absl::StatusOr<std::vector<storage::ClipRecord>> same =
      database_.FindClipsByContentHash(ingested.record.content_hash, kMaxDuplicatesReported + 1);
  if (!same.ok()) {
    return Prefixed(absl::StrCat("stored as clip ", clip_id, ", but its duplicates are unknown"),
                    same.status());
  }
  std::erase_if(*same, [&](const storage::ClipRecord& other) { return other.clip_id == clip_id; });
  if (same->size() > static_cast<size_t>(kMaxDuplicatesReported)) same->pop_back();
  ingested.duplicates = *std::move(same);
  return ingested;
}

absl::Status Catalog::DeleteClip(int64_t clip_id, const std::function<bool()>& should_stop) {
  std::lock_guard<std::mutex> lock(write_mutex_);
  MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord record, database_.GetClipRecord(clip_id));
  MOTIONDB_RETURN_IF_ERROR(database_.DeleteClip(clip_id, {.should_stop = should_stop}));
  return ChangeIndices(record.skeleton_id, [&](const SpaceSnapshot& space) {
    return SnapshotWithoutClip(space, clip_id);
  });
}

absl::StatusOr<storage::ClipRecord> Catalog::UpdateClip(int64_t clip_id,
                                                        const storage::ClipUpdate& update,
                                                        const UpdateClipOptions& options,
                                                        const std::function<bool()>& should_stop) {
  if (cluster_shard_ && update.name && !options.name_reserved) {
    return absl::FailedPreconditionError(
        "this node is a cluster's shard node: a clip's name is reserved in the cluster, and "
        "renamed through a router");
  }
  std::lock_guard<std::mutex> lock(write_mutex_);
  MOTIONDB_ASSIGN_OR_RETURN(storage::ClipRecord record,
                            database_.UpdateClip(clip_id, update, {.should_stop = should_stop}));
  MOTIONDB_RETURN_IF_ERROR(ChangeIndices(record.skeleton_id, [&](const SpaceSnapshot& space) {
    return SnapshotWithClipInfo(space, clip_id, record.name, record.tags);
  }));
  return record;
}

absl::StatusOr<SkeletonMapView> Catalog::MapSkeleton(int64_t skeleton_id,
                                                     const storage::SlotOverrideChange& change,
                                                     const AnswerLimit& answers,
                                                     const std::function<bool()>& should_stop) {
  std::lock_guard<std::mutex> lock(write_mutex_);
  // Checked before the write: a change whose answer could not be sent is not made. A
  // skeleton's joints never change, so the check holds for the answer after the write.
  MOTIONDB_ASSIGN_OR_RETURN(const storage::SkeletonRecord before,
                            database_.GetSkeleton(skeleton_id));
  MOTIONDB_RETURN_IF_ERROR(CheckSkeletonAnswer(before, answers));
  std::vector<std::shared_ptr<const SpaceSnapshot>> spaces = registry_.OfSkeleton(skeleton_id);
  std::erase_if(spaces, [](const auto& space) { return !space->space->canonical(); });
  std::vector<storage::SpaceReprojection> reprojections;
  if (!spaces.empty()) {
    MOTIONDB_ASSIGN_OR_RETURN(const std::vector<SlotOverride> overrides,
                              storage::OverridesAfterChange(before, change));
    MOTIONDB_ASSIGN_OR_RETURN(const HumanoidMap map, MapHumanoid(*before.skeleton, overrides));
    MOTIONDB_RETURN_IF_ERROR(
        Prefixed(absl::StrCat("space ", spaces.front()->record.name, " lists skeleton ",
                              skeleton_id, "; the change is refused"),
                 CheckCanonicalMap(map, absl::StrCat(skeleton_id))));
    MOTIONDB_ASSIGN_OR_RETURN(const std::vector<int64_t> clip_ids,
                              database_.ClipsOfSkeleton(skeleton_id));
    for (const auto& space : spaces) reprojections.push_back({space->record.space_id, {}});
    for (const int64_t clip_id : clip_ids) {
      if (should_stop && should_stop()) {
        return absl::CancelledError("the map change was stopped by its caller; nothing changed");
      }
      MOTIONDB_ASSIGN_OR_RETURN(const storage::StoredClip stored, database_.GetClip(clip_id));
      for (size_t i = 0; i < spaces.size(); ++i) {
        MOTIONDB_ASSIGN_OR_RETURN(RowMatrixXf coordinates,
                                  SearchCoordinates(*spaces[i]->space, stored.clip, -1, &map));
        reprojections[i].projections.push_back({clip_id, std::move(coordinates)});
      }
    }
  }
  MOTIONDB_ASSIGN_OR_RETURN(storage::SkeletonRecord record,
                            database_.UpdateSlotOverrides(skeleton_id, change, reprojections,
                                                          {.should_stop = should_stop}));
  for (const auto& space : spaces) {
    absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> reloaded = LoadSpace(space->record);
    if (!reloaded.ok()) return StaleIndexError(space->record.name, reloaded.status());
    registry_.Put(*std::move(reloaded));
  }
  return SkeletonView(std::move(record));
}

absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> Catalog::CreateSpace(
    const SpaceRequest& request, const std::function<bool()>& should_stop) {
  MOTIONDB_RETURN_IF_ERROR(ValidateSpaceName(request.name));
  std::lock_guard<std::mutex> lock(write_mutex_);
  // Checked before the (long) build; the database checks again in the transaction.
  if (registry_.Find(request.name) != nullptr) {
    return absl::AlreadyExistsError(absl::StrCat("a space named ", request.name, " exists"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(BuiltSpace built, BuildSpace(database_, request, should_stop));
  std::vector<storage::Projection> projections;
  projections.reserve(built.clips.size());
  for (IndexedClip& clip : built.clips) {
    projections.push_back({clip.clip.clip_id, std::move(clip.clip.coordinates)});
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      built.record.space_id,
      database_.InsertSpace(built.record, *built.space, projections, {.should_stop = should_stop}));
  for (size_t i = 0; i < built.clips.size(); ++i) {
    built.clips[i].clip.coordinates = std::move(projections[i].coordinates);
  }
  absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> snapshot =
      BuildSnapshot(built.record, built.space, std::move(built.clips));
  if (!snapshot.ok()) {
    // Without an index the space would be stored but unsearchable; undo the insert.
    const absl::Status undone = database_.DeleteSpace(request.name);
    return absl::InternalError(absl::StrCat("the space's index could not be built (",
                                            snapshot.status().message(), "); space ",
                                            undone.ok() ? "not stored" : "stored but unusable"));
  }
  registry_.Put(*snapshot);
  return *std::move(snapshot);
}

absl::Status Catalog::DeleteSpace(const std::string& name,
                                  const std::function<bool()>& should_stop) {
  std::lock_guard<std::mutex> lock(write_mutex_);
  MOTIONDB_RETURN_IF_ERROR(database_.DeleteSpace(name, {.should_stop = should_stop}));
  registry_.Remove(name);
  return absl::OkStatus();
}

}  // namespace motiondb::server
