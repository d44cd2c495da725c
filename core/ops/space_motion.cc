#include "core/ops/space_motion.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/motion/resample.h"
#include "core/ops/internal/quat_rows.h"
#include "core/space/heading.h"
#include "core/space/pose_encoder.h"
#include "core/space/root_velocity.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using ops_internal::QuatAt;

// The joints above the pelvis, root first.
std::vector<int> AbovePelvis(const Skeleton& skeleton) {
  std::vector<int> chain;
  for (int j = skeleton.joint(FindPelvis(skeleton)).parent; j >= 0; j = skeleton.joint(j).parent) {
    chain.push_back(j);
  }
  std::reverse(chain.begin(), chain.end());
  return chain;
}

}  // namespace

absl::StatusOr<SpaceMotion> EnterSpace(const MotionSpace& space, const Clip& clip,
                                       const std::function<bool()>& should_stop) {
  if (space.canonical()) {
    return absl::FailedPreconditionError(
        "the space is over several skeletons (canonical bone directions): the operators edit "
        "joint rotations, which its points do not hold; use a space over the clip's skeleton");
  }
  if (!clip.skeleton().SameTopology(space.skeleton())) {
    return absl::InvalidArgumentError(
        "the clip's skeleton differs from the space's: joint names or parents do not match");
  }
  // Each step after resampling takes tens of milliseconds for a take of an hour.
  const auto check_stop = [&]() -> absl::Status {
    if (should_stop && should_stop()) {
      return absl::CancelledError("entering the space was stopped by its caller");
    }
    return absl::OkStatus();
  };
  MOTIONDB_ASSIGN_OR_RETURN(const Clip sampled,
                            Resample(clip, space.sample_rate(), /*threads=*/1, should_stop));
  const PoseOptions& options = space.data().pose;
  SpaceMotion motion;
  motion.placement.positions = sampled.positions();
  PoseRotations pose{sampled.rotations(), Eigen::VectorXd(), RowMatrixXd()};
  if (options.remove_heading) {
    const std::vector<int> chain = AbovePelvis(sampled.skeleton());
    motion.placement.above_pelvis.resize(sampled.frame_count(), 4 * chain.size());
    for (size_t i = 0; i < chain.size(); ++i) {
      motion.placement.above_pelvis.middleCols(4 * i, 4) =
          pose.rotations.middleCols(4 * chain[i], 4);
    }
    MOTIONDB_RETURN_IF_ERROR(check_stop());
    motion.placement.yaw = RemoveHeading(sampled.skeleton(), &pose.rotations);
    pose.yaw_rate = YawRate(motion.placement.yaw, sampled.fps(), options.yaw_rate_window);
    if (options.root_velocity) {
      pose.root_velocity = RootVelocity(sampled, motion.placement.yaw, options.yaw_rate_window);
    }
  }
  MOTIONDB_RETURN_IF_ERROR(check_stop());
  const RowMatrixXd encoded = EncodePoses(pose, space.data().references);
  MOTIONDB_RETURN_IF_ERROR(check_stop());
  MOTIONDB_ASSIGN_OR_RETURN(motion.coordinates, space.Project(encoded));
  motion.rotations = std::move(pose.rotations);
  return motion;
}

Placement EmptyPlacement(const Placement& like, int frames) {
  Placement empty;
  empty.positions = RowMatrixXd::Zero(frames, like.positions.cols());
  if (like.yaw.size() > 0) empty.yaw = Eigen::VectorXd::Zero(frames);
  empty.above_pelvis = RowMatrixXd::Zero(frames, like.above_pelvis.cols());
  return empty;
}

void MixPlacementFrame(const std::vector<PlacementFrame>& sources,
                       const std::vector<double>& weights, Placement* out, int out_frame) {
  out->positions.row(out_frame).setZero();
  out->above_pelvis.row(out_frame).setZero();
  const Placement& first = *sources.front().placement;
  const int first_frame = sources.front().frame;
  double yaw = 0.0;
  for (size_t i = 0; i < sources.size(); ++i) {
    const Placement& source = *sources[i].placement;
    const int frame = sources[i].frame;
    out->positions.row(out_frame) += weights[i] * source.positions.row(frame);
    if (source.yaw.size() > 0) {
      const double reference = first.yaw[first_frame];
      yaw += weights[i] *
             (reference + std::remainder(source.yaw[frame] - reference, 2.0 * std::numbers::pi));
    }
    for (Eigen::Index c = 0; c < source.above_pelvis.cols(); c += 4) {
      const auto q = source.above_pelvis.block<1, 4>(frame, c);
      const double sign = q.dot(first.above_pelvis.block<1, 4>(first_frame, c)) < 0.0 ? -1.0 : 1.0;
      out->above_pelvis.block<1, 4>(out_frame, c) += sign * weights[i] * q;
    }
  }
  if (out->yaw.size() > 0) out->yaw[out_frame] = yaw;
  for (Eigen::Index c = 0; c < out->above_pelvis.cols(); c += 4) {
    out->above_pelvis.block<1, 4>(out_frame, c).normalize();
  }
}

RowMatrixXd PlaceRotations(const MotionSpace& space, const Eigen::Ref<const RowMatrixXd>& pose,
                           const Placement& placement) {
  RowMatrixXd rotations = pose;
  if (!space.data().pose.remove_heading) return rotations;
  const Skeleton& skeleton = space.skeleton();
  const std::vector<int> chain = AbovePelvis(skeleton);
  const int pelvis = FindPelvis(skeleton);
  for (Eigen::Index f = 0; f < rotations.rows(); ++f) {
    Quat above = Quat::Identity();
    for (size_t i = 0; i < chain.size(); ++i) {
      const Quat q = QuatAt(placement.above_pelvis, f, 4 * i);
      above *= q;
      rotations.block<1, 4>(f, 4 * chain[i]) << q.w(), q.x(), q.y(), q.z();
    }
    const double half = 0.5 * placement.yaw[f];
    const Quat facing(std::cos(half), 0.0, std::sin(half), 0.0);
    Quat local = (above.conjugate() * facing * QuatAt(rotations, f, 4 * pelvis)).normalized();
    if (local.w() < 0.0) local.coeffs() = -local.coeffs();
    rotations.block<1, 4>(f, 4 * pelvis) << local.w(), local.x(), local.y(), local.z();
  }
  return rotations;
}

absl::StatusOr<Clip> ToClip(const MotionSpace& space, std::shared_ptr<const Skeleton> skeleton,
                            RowMatrixXd rotations, const Placement& placement) {
  if (skeleton == nullptr || !skeleton->SameTopology(space.skeleton())) {
    return absl::InvalidArgumentError("the skeleton differs from the space's");
  }
  if (rotations.rows() != placement.frames()) {
    return absl::InvalidArgumentError(absl::StrCat("rotations have ", rotations.rows(),
                                                   " frames, the placement ", placement.frames()));
  }
  return Clip::Create(std::move(skeleton), 1.0 / space.sample_rate(), std::move(rotations),
                      placement.positions);
}

}  // namespace motiondb
