#include "server/skeleton_map.h"

#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/space/canonical_pose.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// Each joint's name appears at most three times (joints, a slot, a pair), each with its numbers.
int64_t SkeletonAnswerBytes(const Skeleton& skeleton) {
  int64_t bytes = kAnswerFixedBytes;
  for (const Joint& joint : skeleton.joints()) {
    bytes += 3 * (TextFieldBytes(static_cast<int64_t>(joint.name.size())) + 2 * kNumberFieldBytes +
                  kFieldFramingBytes);
  }
  return bytes;
}

}  // namespace

absl::Status CheckSkeletonAnswer(const storage::SkeletonRecord& record,
                                 const AnswerLimit& answers) {
  return answers.Check(SkeletonAnswerBytes(*record.skeleton),
                       absl::StrCat("skeleton ", record.summary.skeleton_id, "'s joints and map"),
                       "raise --max-answer-mb");
}

absl::StatusOr<SkeletonMapView> SkeletonView(storage::SkeletonRecord record) {
  SkeletonMapView view;
  MOTIONDB_ASSIGN_OR_RETURN(view.map, MapHumanoid(*record.skeleton, record.slot_overrides));
  for (const SlotOverride& pinned : record.slot_overrides) {
    view.overridden[static_cast<int>(pinned.slot)] = true;
  }
  view.record = std::move(record);
  return view;
}

absl::StatusOr<SkeletonMapView> ShowSkeleton(storage::Database& database, int64_t skeleton_id,
                                             const AnswerLimit& answers) {
  MOTIONDB_ASSIGN_OR_RETURN(storage::SkeletonRecord record, database.GetSkeleton(skeleton_id));
  MOTIONDB_RETURN_IF_ERROR(CheckSkeletonAnswer(record, answers));
  return SkeletonView(std::move(record));
}

absl::StatusOr<HumanoidMap> CanonicalMapOfSkeleton(storage::Database& database,
                                                   int64_t skeleton_id) {
  MOTIONDB_ASSIGN_OR_RETURN(const storage::SkeletonRecord record,
                            database.GetSkeleton(skeleton_id));
  MOTIONDB_ASSIGN_OR_RETURN(HumanoidMap map, MapHumanoid(*record.skeleton, record.slot_overrides));
  MOTIONDB_RETURN_IF_ERROR(CheckCanonicalMap(map, absl::StrCat(skeleton_id)));
  return map;
}

absl::StatusOr<HumanoidMap> CanonicalMapOfClip(storage::Database& database, const Clip& clip) {
  MOTIONDB_ASSIGN_OR_RETURN(const int64_t skeleton_id, database.FindSkeleton(clip.skeleton()));
  if (skeleton_id >= 0) return CanonicalMapOfSkeleton(database, skeleton_id);
  MOTIONDB_ASSIGN_OR_RETURN(HumanoidMap map, MapHumanoid(clip.skeleton()));
  MOTIONDB_RETURN_IF_ERROR(CheckCanonicalMap(map, "of the query"));
  return map;
}

absl::StatusOr<SkeletonMirror> MirrorOfSkeleton(storage::Database& database, int64_t skeleton_id,
                                                const Skeleton& skeleton,
                                                const RowMatrixXd& mean_pose) {
  MOTIONDB_ASSIGN_OR_RETURN(const storage::SkeletonRecord record,
                            database.GetSkeleton(skeleton_id));
  MOTIONDB_ASSIGN_OR_RETURN(const HumanoidMap map, MapHumanoid(skeleton, record.slot_overrides));
  absl::StatusOr<SkeletonMirror> mirror = MakeSkeletonMirror(skeleton, map);
  if (mirror.ok()) return mirror;
  const absl::StatusOr<SkeletonMirror> about_mean = MakeSkeletonMirror(skeleton, map, mean_pose);
  if (about_mean.ok()) return about_mean;
  const std::string why =
      about_mean.status().message() == mirror.status().message()
          ? std::string(mirror.status().message())
          : absl::StrCat(mirror.status().message(), "; and about the space's mean pose, ",
                         about_mean.status().message());
  return absl::Status(mirror.status().code(),
                      absl::StrCat("mirror: skeleton ", skeleton_id, " cannot be mirrored: ", why));
}

}  // namespace motiondb::server
