// A skeleton's humanoid map as the API shows it (ClipService.GetSkeleton, MapSkeleton): the
// stored overrides applied first, the automatic map (core/motion/humanoid_map.h) around them.
#ifndef MOTIONDB_SERVER_SKELETON_MAP_H_
#define MOTIONDB_SERVER_SKELETON_MAP_H_

#include <array>
#include <cstdint>
#include <functional>

#include "absl/status/statusor.h"
#include "core/motion/clip_mirror.h"
#include "core/motion/humanoid_map.h"
#include "core/motion/matrix.h"
#include "server/answer_limit.h"
#include "storage/database.h"

namespace motiondb::server {

struct SkeletonMapView {
  storage::SkeletonRecord record;
  HumanoidMap map;
  std::array<bool, kHumanoidSlotCount> overridden{};  // by slot: its joint is an override's
};

// NOT_FOUND for an unknown skeleton; RESOURCE_EXHAUSTED when its joints' names could take more
// than `answers` (three times each: joints, slots, pairs).
absl::StatusOr<SkeletonMapView> ShowSkeleton(storage::Database& database, int64_t skeleton_id,
                                             const AnswerLimit& answers);

// RESOURCE_EXHAUSTED when skeleton `record`'s joints' names could take more than `answers`.
absl::Status CheckSkeletonAnswer(const storage::SkeletonRecord& record, const AnswerLimit& answers);

// `record` as shown: its map with the stored overrides applied first.
absl::StatusOr<SkeletonMapView> SkeletonView(storage::SkeletonRecord record);

// The map of skeleton `skeleton_id`, its stored overrides applied, for its clips' canonical poses
// (core/space/canonical_pose.h) in a space over several skeletons; FAILED_PRECONDITION naming the
// slots it lacks when it cannot join one. NOT_FOUND for an unknown skeleton.
absl::StatusOr<HumanoidMap> CanonicalMapOfSkeleton(storage::Database& database,
                                                   int64_t skeleton_id);

// The map of `clip`'s skeleton for its canonical poses: a stored skeleton's with its overrides,
// any other's (an uploaded query's) as MapHumanoid makes it; FAILED_PRECONDITION naming the
// slots it lacks.
absl::StatusOr<HumanoidMap> CanonicalMapOfClip(storage::Database& database, const Clip& clip);

// The mirror (core/motion/clip_mirror.h) of a clip of skeleton `skeleton_id` whose own joints
// are `skeleton` (offsets differ between a skeleton's clips), by the skeleton's map as
// ShowSkeleton shows it: about the rest pose when that is symmetric, else about `mean_pose`
// (joints x 4: a space's mean orientations; Bandai's rest pose is no standing human). NOT_FOUND
// for an unknown skeleton; FAILED_PRECONDITION, saying why, when the map cannot mirror it.
absl::StatusOr<SkeletonMirror> MirrorOfSkeleton(storage::Database& database, int64_t skeleton_id,
                                                const Skeleton& skeleton,
                                                const RowMatrixXd& mean_pose);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_SKELETON_MAP_H_
