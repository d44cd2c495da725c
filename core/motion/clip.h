// A motion clip at its original frame rate: one unit quaternion per joint per frame, and the
// per-frame translation of every joint that has position channels (the root, and in some
// exporters every joint).
//
// Immutable after Create(); thread-safe for concurrent reads. Copies share the skeleton.
#ifndef MOTIONDB_CORE_MOTION_CLIP_H_
#define MOTIONDB_CORE_MOTION_CLIP_H_

#include <cstdint>
#include <memory>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/motion/matrix.h"
#include "core/motion/rotation.h"
#include "core/motion/skeleton.h"

namespace motiondb {

// An inclusive range of frames, counted from 0 at the clip's own rate.
struct FrameRange {
  int first = 0;
  int last = 0;
  int size() const { return last - first + 1; }
};

// OK when `range` is non-empty and lies inside frames 0..frame_count - 1, else OUT_OF_RANGE.
absl::Status CheckFrameRange(FrameRange range, int64_t frame_count);

class Clip {
 public:
  // `rotations`: frames x (4 * joints), each joint's quaternion as w, x, y, z; every quaternion
  // must be finite and of unit length within 1e-6. `positions`: frames x
  // (3 * skeleton->position_joint_count()), the translation channels' values as x, y, z in
  // the joints' position-slot order. `frame_time`: seconds per frame, finite and positive.
  static absl::StatusOr<Clip> Create(std::shared_ptr<const Skeleton> skeleton, double frame_time,
                                     RowMatrixXd rotations, RowMatrixXd positions);

  const Skeleton& skeleton() const { return *skeleton_; }
  const std::shared_ptr<const Skeleton>& shared_skeleton() const { return skeleton_; }

  int frame_count() const { return static_cast<int>(rotations_.rows()); }
  double frame_time() const { return frame_time_; }
  double fps() const { return 1.0 / frame_time_; }
  // The time the clip plays for: frame_count() * frame_time().
  double duration_s() const { return frame_count() * frame_time_; }

  const RowMatrixXd& rotations() const { return rotations_; }
  const RowMatrixXd& positions() const { return positions_; }
  Quat rotation(int frame, int joint) const;
  // The root joint's translation: its position channels, or its offset when it has none.
  Eigen::Vector3d root_position(int frame) const;

  // The frames in `range`, which must lie inside the clip (CheckFrameRange).
  absl::StatusOr<Clip> Slice(FrameRange range) const;

 private:
  Clip(std::shared_ptr<const Skeleton> skeleton, double frame_time, RowMatrixXd rotations,
       RowMatrixXd positions);

  std::shared_ptr<const Skeleton> skeleton_;
  double frame_time_;
  RowMatrixXd rotations_;
  RowMatrixXd positions_;
};

}  // namespace motiondb

#endif  // MOTIONDB_CORE_MOTION_CLIP_H_
