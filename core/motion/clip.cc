#include "core/motion/clip.h"

#include <cmath>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb {

absl::Status CheckFrameRange(FrameRange range, int64_t frame_count) {
  if (range.first < 0 || range.last < range.first || range.last >= frame_count) {
    return absl::OutOfRangeError(absl::StrCat("frame range ", range.first, "-", range.last,
                                              " is outside the clip's frames 0-", frame_count - 1));
  }
  return absl::OkStatus();
}

absl::StatusOr<Clip> Clip::Create(std::shared_ptr<const Skeleton> skeleton, double frame_time,
                                  RowMatrixXd rotations, RowMatrixXd positions) {
  if (skeleton == nullptr) return absl::InvalidArgumentError("clip has no skeleton");
  if (!std::isfinite(frame_time) || frame_time <= 0.0) {
    return absl::InvalidArgumentError(
        absl::StrCat("frame time must be finite and positive, got ", frame_time));
  }
  const int joints = skeleton->joint_count();
  if (rotations.cols() != 4 * joints) {
    return absl::InvalidArgumentError(absl::StrCat("rotations have ", rotations.cols(),
                                                   " columns, expected 4 x ", joints, " joints"));
  }
  if (positions.rows() != rotations.rows() ||
      positions.cols() != 3 * skeleton->position_joint_count()) {
    return absl::InvalidArgumentError(
        absl::StrCat("positions are ", positions.rows(), " x ", positions.cols(), ", expected ",
                     rotations.rows(), " x ", 3 * skeleton->position_joint_count()));
  }
  if (!rotations.allFinite() || !positions.allFinite()) {
    return absl::InvalidArgumentError("clip contains NaN or infinite values");
  }
  // |norm - 1| <= 1e-6 on the squared norm, without a square root per quaternion (a clip is
  // made for every export and edit).
  constexpr double kLowest = (1 - 1e-6) * (1 - 1e-6), kHighest = (1 + 1e-6) * (1 + 1e-6);
  for (Eigen::Index f = 0; f < rotations.rows(); ++f) {
    for (int j = 0; j < joints; ++j) {
      const double squared = rotations.block<1, 4>(f, 4 * j).squaredNorm();
      if (!(squared >= kLowest && squared <= kHighest)) {
        const double norm = std::sqrt(squared);
        return absl::InvalidArgumentError(absl::StrCat("frame ", f, ", joint '",
                                                       skeleton->joint(j).name,
                                                       "': quaternion norm ", norm, " is not 1"));
      }
    }
  }
  return Clip(std::move(skeleton), frame_time, std::move(rotations), std::move(positions));
}

Clip::Clip(std::shared_ptr<const Skeleton> skeleton, double frame_time, RowMatrixXd rotations,
           RowMatrixXd positions)
    : skeleton_(std::move(skeleton)),
      frame_time_(frame_time),
      rotations_(std::move(rotations)),
      positions_(std::move(positions)) {}

Quat Clip::rotation(int frame, int joint) const {
  const auto q = rotations_.block<1, 4>(frame, 4 * joint);
  return Quat(q[0], q[1], q[2], q[3]);
}

Eigen::Vector3d Clip::root_position(int frame) const {
  const int slot = skeleton_->position_slot(0);
  if (slot < 0) return skeleton_->joint(0).offset;
  return positions_.block<1, 3>(frame, 3 * slot).transpose();
}

absl::StatusOr<Clip> Clip::Slice(FrameRange range) const {
  MOTIONDB_RETURN_IF_ERROR(CheckFrameRange(range, frame_count()));
  return Clip(skeleton_, frame_time_, rotations_.middleRows(range.first, range.size()),
              positions_.middleRows(range.first, range.size()));
}

}  // namespace motiondb
