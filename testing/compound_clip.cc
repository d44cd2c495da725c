#include "testing/compound_clip.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/motion/forward_kinematics.h"
#include "core/motion/resample.h"
#include "core/space/heading.h"
#include "util/status_macros.h"

namespace motiondb::testing {
namespace {

absl::Status SameLayout(const Skeleton& a, const Skeleton& b) {
  if (a.joint_count() != b.joint_count()) {
    return absl::InvalidArgumentError(absl::StrCat("the clips' skeletons have ", a.joint_count(),
                                                   " and ", b.joint_count(), " joints"));
  }
  for (int j = 0; j < a.joint_count(); ++j) {
    if (a.joint(j).channels != b.joint(j).channels) {
      return absl::InvalidArgumentError(absl::StrCat("joint ", j, " (", a.joint(j).name,
                                                     ") has other channels in the second clip"));
    }
  }
  return absl::OkStatus();
}

// The pelvis's world position on `frame`.
Eigen::Vector3d PelvisPosition(const Clip& clip, int frame, int pelvis) {
  const RowMatrixXd world = ForwardKinematics(*clip.Slice({frame, frame}));
  return world.block<1, 3>(0, 3 * pelvis).transpose();
}

int Frames(double seconds, double frame_time) {
  return static_cast<int>(std::lround(seconds / frame_time));
}

}  // namespace

absl::StatusOr<CompoundClip> ConcatenateWithHold(const Clip& first, const Clip& second,
                                                 const CompoundOptions& options) {
  MOTIONDB_RETURN_IF_ERROR(SameLayout(first.skeleton(), second.skeleton()));
  const int root_slot = first.skeleton().position_slot(0);
  if (root_slot < 0) {
    return absl::InvalidArgumentError("the root has no position channels to continue");
  }
  for (const auto& [name, value] :
       {std::pair{"hold_s", options.hold_s}, {"blend_s", options.blend_s}}) {
    if (!std::isfinite(value) || value < 0) {
      return absl::InvalidArgumentError(absl::StrCat(name, " = ", value, " is not >= 0"));
    }
  }
  Clip next = second;
  if (std::abs(second.frame_time() - first.frame_time()) > 1e-9 * first.frame_time()) {
    MOTIONDB_ASSIGN_OR_RETURN(next, Resample(second, first.fps()));
  }

  const int pelvis = FindPelvis(first.skeleton());
  Eigen::Vector3d shift = PelvisPosition(first, first.frame_count() - 1, pelvis) -
                          PelvisPosition(next, 0, FindPelvis(next.skeleton()));
  shift.y() = 0;
  RowMatrixXd next_positions = next.positions();
  next_positions.middleCols<3>(3 * root_slot).rowwise() += shift.transpose();

  const int hold = Frames(options.hold_s, first.frame_time());
  const int blend = Frames(options.blend_s, first.frame_time());
  const int last = first.frame_count() - 1;
  const int64_t frames = first.frame_count() + hold + blend + next.frame_count();
  const int joints = first.skeleton().joint_count();
  RowMatrixXd rotations(frames, first.rotations().cols());
  RowMatrixXd positions(frames, first.positions().cols());
  rotations.topRows(first.frame_count()) = first.rotations();
  positions.topRows(first.frame_count()) = first.positions();
  for (int f = 0; f < hold; ++f) {
    rotations.row(first.frame_count() + f) = first.rotations().row(last);
    positions.row(first.frame_count() + f) = first.positions().row(last);
  }
  for (int f = 0; f < blend; ++f) {
    const double t = (f + 1.0) / (blend + 1.0);
    const int64_t row = first.frame_count() + hold + f;
    for (int j = 0; j < joints; ++j) {
      const Quat q = Slerp(first.rotation(last, j), next.rotation(0, j), t).normalized();
      rotations.block<1, 4>(row, 4 * j) << q.w(), q.x(), q.y(), q.z();
    }
    positions.row(row) = (1 - t) * first.positions().row(last) + t * next_positions.row(0);
  }
  const int second_first = first.frame_count() + hold + blend;
  rotations.bottomRows(next.frame_count()) = next.rotations();
  positions.bottomRows(next.frame_count()) = next_positions;

  MOTIONDB_ASSIGN_OR_RETURN(Clip clip, Clip::Create(first.shared_skeleton(), first.frame_time(),
                                                    std::move(rotations), std::move(positions)));
  return CompoundClip{
      std::move(clip), {0, last}, {second_first, second_first + next.frame_count() - 1}};
}

}  // namespace motiondb::testing
