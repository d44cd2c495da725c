#include "server/query_mirror.h"

#include "core/space/canonical_pose.h"
#include "core/space/search_coordinates.h"
#include "server/skeleton_map.h"
#include "util/status_macros.h"

namespace motiondb::server {

absl::StatusOr<RowMatrixXf> MirroredCoordinates(storage::Database& database,
                                                const SpaceSnapshot& snapshot, const Clip& clip) {
  const MotionSpace& space = *snapshot.space;
  if (space.canonical()) {
    MOTIONDB_ASSIGN_OR_RETURN(const HumanoidMap map, CanonicalMapOfClip(database, clip));
    MOTIONDB_ASSIGN_OR_RETURN(RowMatrixXd poses, space.EncodeClip(clip, &map));
    MOTIONDB_RETURN_IF_ERROR(MirrorCanonicalPoses(space.data().pose, &poses));
    return SearchCoordinatesOfPoses(space, poses);
  }
  MOTIONDB_ASSIGN_OR_RETURN(const SkeletonMirror mirror,
                            MirrorOfSkeleton(database, snapshot.record.skeleton_id, clip.skeleton(),
                                             space.data().references));
  MOTIONDB_ASSIGN_OR_RETURN(const Clip mirrored, MirrorClip(clip, mirror));
  return SearchCoordinates(space, mirrored);
}

}  // namespace motiondb::server
