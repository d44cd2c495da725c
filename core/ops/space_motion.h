// A clip inside a space, as the operators (thesis ch. 3-5) work on it: its motion curve with
// every dimension, the pose rotations the curve encodes, and the placement the pose leaves out,
// frame for frame at the space rate. The operators edit curves; ToClip unprojects a curve and
// puts a placement back, giving a clip of the source's skeleton that exports as BVH with the
// original hierarchy and channel orders.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_OPS_SPACE_MOTION_H_
#define MOTIONDB_CORE_OPS_SPACE_MOTION_H_

#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "core/motion/matrix.h"
#include "core/space/motion_space.h"

namespace motiondb {

// What places a pose in the world: the translation channels, the facing (when the space
// removes it) and the rotations of the joints above the pelvis, which the pose sets to the
// identity (core/space/heading.h).
struct Placement {
  RowMatrixXd positions;     // frames x 3 * position joints, as Clip::positions()
  Eigen::VectorXd yaw;       // frames: the pelvis's facing in radians; empty when it is kept
  RowMatrixXd above_pelvis;  // frames x 4 * joints above the pelvis (root first), w, x, y, z

  int frames() const { return static_cast<int>(positions.rows()); }
};

struct SpaceMotion {
  RowMatrixXd coordinates;  // frames x the space's dimensions
  RowMatrixXd rotations;    // frames x 4 * joints: the pose rotations the coordinates encode
  Placement placement;
};

// The clip resampled to the space rate and projected, with its placement. INVALID_ARGUMENT
// when its skeleton is not the space's; FAILED_PRECONDITION in a space over several skeletons.
// `should_stop` is asked while the clip is resampled and between the steps after: CANCELLED once it
// says stop.
absl::StatusOr<SpaceMotion> EnterSpace(const MotionSpace& space, const Clip& clip,
                                       const std::function<bool()>& should_stop = {});

// One frame of a placement, as a mix takes it.
struct PlacementFrame {
  const Placement* placement = nullptr;
  int frame = 0;
};

// Writes into frame `out_frame` of `out` (shaped like the sources) the mix of `sources` with
// `weights` (same size, summing to 1): positions as weighted sums, the facing as a weighted sum
// of angles brought within half a turn of the first source's, and the rotations above the pelvis
// as normalised weighted sums in the first source's hemisphere, close to their mean for the
// nearby rotations a blend mixes.
void MixPlacementFrame(const std::vector<PlacementFrame>& sources,
                       const std::vector<double>& weights, Placement* out, int out_frame);

// A placement of `frames` frames shaped like `like`, zero-filled.
Placement EmptyPlacement(const Placement& like, int frames);

// The local joint rotations (frames x 4 * joints) of pose rotations placed by `placement`: the
// pose's own where the facing is kept; otherwise the joints above the pelvis from the placement
// and the pelvis turned back to the placement's facing under them.
RowMatrixXd PlaceRotations(const MotionSpace& space, const Eigen::Ref<const RowMatrixXd>& pose,
                           const Placement& placement);

// A clip of `skeleton` (the space's topology; offsets and channels are its own) sampled at the
// space rate from joint rotations and a placement of the same frame count. INVALID_ARGUMENT
// when they do not fit the skeleton or the counts differ.
absl::StatusOr<Clip> ToClip(const MotionSpace& space, std::shared_ptr<const Skeleton> skeleton,
                            RowMatrixXd rotations, const Placement& placement);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_OPS_SPACE_MOTION_H_
