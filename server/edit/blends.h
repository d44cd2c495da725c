// EditService's pose blends (thesis 4.1-4.2): two poses interpolated by MC-LERP and by per-joint
// SLERP side by side, and M poses blended on a plane along a path of points. Each pose is a
// stored clip's frame, or the projected mean of a range; the placement (position, facing) is
// mixed with the same weights.
#ifndef MOTIONDB_SERVER_EDIT_BLENDS_H_
#define MOTIONDB_SERVER_EDIT_BLENDS_H_

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "core/ops/interpolation.h"
#include "core/ops/planar_blend.h"
#include "server/edit/context.h"

namespace motiondb::server {

enum class InterpolationMethod { kMcLerp, kSlerp };

struct InterpolateRequest {
  std::string space;
  ClipSelection from;
  ClipSelection to;
  InterpolationOptions options{};
  // The method whose poses the result holds (and a store keeps); the other comes beside it.
  InterpolationMethod method = InterpolationMethod::kMcLerp;
  EditOutput output{};
};

struct InterpolateOutcome {
  EditResult result;      // one frame per t
  std::string other_bvh;  // the other method's poses
  // The comparison (4.1): t, the joint angles between the methods and the curve distance.
  Interpolation comparison;
};

struct PlanarPose {
  ClipSelection pose;
  double x = 0.0;
  double y = 0.0;
};

struct BlendRequest {
  std::string space;
  std::vector<PlanarPose> poses{};
  std::vector<Eigen::Vector2d> path{};  // plane points, one frame each
  // Frames from each path point to the next, 1..10000 (linearly along the path); 1: the points
  // as given.
  int frames_per_segment = 1;
  PlanarBlendOptions options{};
  EditOutput output{};
};

struct BlendOutcome {
  EditResult result;
  RowMatrixXd weights;  // frames x poses, each row summing to 1
};

// NOT_FOUND for an unknown space or clip; INVALID_ARGUMENT naming the request's field (from,
// to, t[i], poses[i].pose, poses[i].x, path[i].y, frames_per_segment, epsilon, ...); nothing is
// stored on error.
absl::StatusOr<InterpolateOutcome> Interpolate(const EditContext& context,
                                               const InterpolateRequest& request,
                                               const std::function<bool()>& should_stop);
absl::StatusOr<BlendOutcome> Blend(const EditContext& context, const BlendRequest& request,
                                   const std::function<bool()>& should_stop);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_EDIT_BLENDS_H_
