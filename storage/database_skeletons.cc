// Skeletons: their listing, their joints and their humanoid slot overrides.
#include <algorithm>
#include <map>
#include <optional>
#include <utility>

#include "absl/container/flat_hash_set.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "storage/database.h"
#include "storage/internal/database_impl.h"
#include "storage/internal/record_checks.h"
#include "storage/internal/record_rows.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::storage {
namespace {

// Both subqueries walk the clips_by_skeleton index: no scan of the clips.
constexpr absl::string_view kSummaryQuery =
    "SELECT s.skeleton_id, s.joint_count, s.joint_names, "
    "(SELECT count(*) FROM clips c WHERE c.skeleton_id = s.skeleton_id), "
    "(SELECT c.name FROM clips c WHERE c.skeleton_id = s.skeleton_id "
    "ORDER BY c.clip_id LIMIT 1), s.joint_parents "
    "FROM skeletons s";

SkeletonSummary ReadSummary(const SqliteStatement& row) {
  SkeletonSummary skeleton;
  skeleton.skeleton_id = row.ColumnInt64(0);
  skeleton.joint_count = static_cast<int>(row.ColumnInt64(1));
  // joint_names holds one name a line, the root's first.
  const std::string names = row.ColumnText(2);
  skeleton.root_joint = names.substr(0, names.find('\n'));
  skeleton.clip_count = row.ColumnInt64(3);
  skeleton.first_clip_name = row.ColumnText(4);  // NULL reads as ""
  return skeleton;
}

// The joints of a skeleton without clips: the names and parents of its row.
absl::StatusOr<std::shared_ptr<const Skeleton>> TopologyOnly(const SqliteStatement& row) {
  const std::vector<std::string> names = absl::StrSplit(row.ColumnText(2), '\n');
  const std::vector<std::string> parents = absl::StrSplit(row.ColumnText(5), ',');
  if (names.size() != parents.size()) {
    return absl::DataLossError("its joint names and parents differ in number");
  }
  std::vector<Joint> joints(names.size());
  for (size_t i = 0; i < names.size(); ++i) {
    joints[i].name = names[i];
    if (!absl::SimpleAtoi(parents[i], &joints[i].parent)) {
      return absl::DataLossError(absl::StrCat("joint ", i, "'s parent is not a number"));
    }
  }
  absl::StatusOr<Skeleton> skeleton = Skeleton::Create(std::move(joints));
  if (!skeleton.ok()) return absl::DataLossError(skeleton.status().message());
  return std::make_shared<const Skeleton>(*std::move(skeleton));
}

absl::StatusOr<SkeletonRecord> ReadSkeleton(SqliteConnection& db, int64_t skeleton_id) {
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement summary,
                            db.Prepare(absl::StrCat(kSummaryQuery, " WHERE s.skeleton_id = ?")));
  MOTIONDB_ASSIGN_OR_RETURN(const bool found, summary.BindInt64(1, skeleton_id).Step());
  if (!found) return absl::NotFoundError(absl::StrCat("skeleton ", skeleton_id, " not found"));
  SkeletonRecord record;
  record.summary = ReadSummary(summary);
  const std::string what = absl::StrCat("stored skeleton ", skeleton_id);
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement first_clip,
      db.Prepare(absl::StrCat("SELECT ", kClipRecordColumns, ", ", kClipLayoutColumns,
                              " FROM clips c WHERE c.skeleton_id = ? ORDER BY c.clip_id LIMIT 1")));
  MOTIONDB_ASSIGN_OR_RETURN(const bool has_clip, first_clip.BindInt64(1, skeleton_id).Step());
  if (has_clip) {
    MOTIONDB_ASSIGN_OR_RETURN(
        record.skeleton, Prefixed(what, ReadClipLayout(first_clip, ReadClipRecord(first_clip))));
  } else {
    MOTIONDB_ASSIGN_OR_RETURN(record.skeleton, Prefixed(what, TopologyOnly(summary)));
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement overrides,
      db.Prepare("SELECT slot, joint_name FROM skeleton_slot_overrides WHERE skeleton_id = ?"));
  overrides.BindInt64(1, skeleton_id);
  while (true) {
    MOTIONDB_ASSIGN_OR_RETURN(const bool row, overrides.Step());
    if (!row) break;
    const std::optional<HumanoidSlot> slot = ParseHumanoidSlot(overrides.ColumnText(0));
    if (!slot) {
      return absl::DataLossError(
          absl::StrCat(what, ": an override of an unknown slot '", overrides.ColumnText(0), "'"));
    }
    record.slot_overrides.push_back({*slot, overrides.ColumnText(1)});
  }
  std::sort(record.slot_overrides.begin(), record.slot_overrides.end(),
            [](const SlotOverride& a, const SlotOverride& b) { return a.slot < b.slot; });
  return record;
}

// The skeleton's overrides once `change` is applied to `stored`; INVALID_ARGUMENT as
// UpdateSlotOverrides says.
absl::StatusOr<std::map<HumanoidSlot, std::string>> ChangedOverrides(
    const SkeletonRecord& stored, const SlotOverrideChange& change) {
  std::map<HumanoidSlot, std::string> overrides;
  for (const SlotOverride& kept : stored.slot_overrides) overrides[kept.slot] = kept.joint;
  for (const HumanoidSlot cleared : change.clear) overrides.erase(cleared);
  std::map<HumanoidSlot, size_t> set_at;
  for (size_t i = 0; i < change.set.size(); ++i) {
    const SlotOverride& set = change.set[i];
    const std::string what = absl::StrCat("set[", i, "].");
    const absl::string_view slot = HumanoidSlotName(set.slot);
    if (stored.skeleton->FindJoint(set.joint) < 0) {
      return absl::InvalidArgumentError(
          absl::StrCat(what, "joint: skeleton ", stored.summary.skeleton_id,
                       " has no joint named '", set.joint.substr(0, 128), "'"));
    }
    if (!set_at.emplace(set.slot, i).second) {
      return absl::InvalidArgumentError(absl::StrCat(what, "slot: ", slot, " is set twice"));
    }
    if (std::find(change.clear.begin(), change.clear.end(), set.slot) != change.clear.end()) {
      return absl::InvalidArgumentError(
          absl::StrCat(what, "slot: ", slot, " is both set and cleared"));
    }
    overrides[set.slot] = set.joint;
  }
  for (const auto& [slot, i] : set_at) {
    for (const auto& [other, joint] : overrides) {
      if (other != slot && joint == change.set[i].joint) {
        return absl::InvalidArgumentError(
            absl::StrCat("set[", i, "].joint: '", joint, "' is already the override of slot ",
                         HumanoidSlotName(other), "; clear that slot or set it to another joint"));
      }
    }
  }
  return overrides;
}

// Replaces skeleton `skeleton_id`'s clips' projections into `reprojection`'s space.
absl::Status ReplaceProjections(SqliteConnection& db, int64_t skeleton_id,
                                const SpaceReprojection& reprojection) {
  const std::string space = absl::StrCat("space ", reprojection.space_id);
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement listed,
      db.Prepare("SELECT s.dims FROM spaces s JOIN space_skeletons k ON k.space_id = s.space_id "
                 "WHERE s.space_id = ? AND k.skeleton_id = ?"));
  MOTIONDB_ASSIGN_OR_RETURN(
      const bool found,
      listed.BindInt64(1, reprojection.space_id).BindInt64(2, skeleton_id).Step());
  if (!found) {
    return absl::FailedPreconditionError(absl::StrCat(
        space, " is no space over several skeletons that lists skeleton ", skeleton_id));
  }
  const int dims = static_cast<int>(listed.ColumnInt64(0));
  absl::flat_hash_set<int64_t> clips;
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement of_skeleton,
                            db.Prepare("SELECT clip_id FROM clips WHERE skeleton_id = ?"));
  of_skeleton.BindInt64(1, skeleton_id);
  while (true) {
    MOTIONDB_ASSIGN_OR_RETURN(const bool row, of_skeleton.Step());
    if (!row) break;
    clips.insert(of_skeleton.ColumnInt64(0));
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement erase,
      db.Prepare("DELETE FROM projections WHERE space_id = ? AND clip_id = ?"));
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement insert, PrepareProjectionInsert(db));
  for (const Projection& projection : reprojection.projections) {
    if (clips.erase(projection.clip_id) == 0) {
      return absl::InvalidArgumentError(absl::StrCat(
          "projection into ", space, " of clip ", projection.clip_id,
          ", which is not one of skeleton ", skeleton_id, "'s clips (or given twice)"));
    }
    MOTIONDB_RETURN_IF_ERROR(
        CheckProjection(projection.coordinates, dims,
                        absl::StrCat("projection of clip ", projection.clip_id, " into ", space)));
    erase.Reset();
    MOTIONDB_RETURN_IF_ERROR(
        erase.BindInt64(1, reprojection.space_id).BindInt64(2, projection.clip_id).Run());
    MOTIONDB_RETURN_IF_ERROR(InsertProjection(insert, reprojection.space_id, projection.clip_id,
                                              projection.coordinates));
  }
  if (!clips.empty()) {
    return absl::FailedPreconditionError(absl::StrCat("no new projection into ", space, " of clip ",
                                                      *std::min_element(clips.begin(), clips.end()),
                                                      " of skeleton ", skeleton_id));
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<std::vector<SlotOverride>> OverridesAfterChange(const SkeletonRecord& stored,
                                                               const SlotOverrideChange& change) {
  MOTIONDB_ASSIGN_OR_RETURN(const auto overrides, ChangedOverrides(stored, change));
  std::vector<SlotOverride> after;
  for (const auto& [slot, joint] : overrides) after.push_back({slot, joint});
  return after;
}

absl::StatusOr<std::vector<SkeletonSummary>> Database::ListSkeletons() {
  std::vector<SkeletonSummary> skeletons;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query,
                              db.Prepare(absl::StrCat(kSummaryQuery, " ORDER BY s.skeleton_id")));
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, query.Step());
      if (!row) return absl::OkStatus();
      skeletons.push_back(ReadSummary(query));
    }
  }));
  return skeletons;
}

absl::StatusOr<SkeletonRecord> Database::GetSkeleton(int64_t skeleton_id) {
  std::optional<SkeletonRecord> record;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(record, ReadSkeleton(db, skeleton_id));
    return absl::OkStatus();
  }));
  return *std::move(record);
}

absl::StatusOr<SkeletonRecord> Database::UpdateSlotOverrides(
    int64_t skeleton_id, const SlotOverrideChange& change,
    const std::vector<SpaceReprojection>& reprojections, const WriteOptions& write) {
  std::optional<SkeletonRecord> record;
  MOTIONDB_RETURN_IF_ERROR(impl_->Write(write, [&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const SkeletonRecord stored, ReadSkeleton(db, skeleton_id));
    MOTIONDB_ASSIGN_OR_RETURN(const auto overrides, ChangedOverrides(stored, change));
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement erase,
        db.Prepare("DELETE FROM skeleton_slot_overrides WHERE skeleton_id = ?"));
    MOTIONDB_RETURN_IF_ERROR(erase.BindInt64(1, skeleton_id).Run());
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement insert,
        db.Prepare("INSERT INTO skeleton_slot_overrides (skeleton_id, slot, joint_name) "
                   "VALUES (?, ?, ?)"));
    for (const auto& [slot, joint] : overrides) {
      insert.Reset();
      MOTIONDB_RETURN_IF_ERROR(insert.BindInt64(1, skeleton_id)
                                   .BindText(2, std::string(HumanoidSlotName(slot)))
                                   .BindText(3, joint)
                                   .Run());
    }
    for (const SpaceReprojection& reprojection : reprojections) {
      MOTIONDB_RETURN_IF_ERROR(ReplaceProjections(db, skeleton_id, reprojection));
    }
    MOTIONDB_ASSIGN_OR_RETURN(record, ReadSkeleton(db, skeleton_id));
    return absl::OkStatus();
  }));
  return *std::move(record);
}

}  // namespace motiondb::storage
