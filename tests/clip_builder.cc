#include "tests/clip_builder.h"

#include <gtest/gtest.h>

namespace motiondb::testing {

std::shared_ptr<const Skeleton> ChainSkeleton() {
  std::vector<Joint> joints(3);
  joints[0].name = "root";
  joints[0].channels = {Channel::kXposition, Channel::kYposition, Channel::kZposition,
                        Channel::kZrotation, Channel::kXrotation, Channel::kYrotation};
  joints[1].name = "child";
  joints[1].parent = 0;
  joints[1].offset = Eigen::Vector3d(0, 10, 0);
  joints[1].channels = {Channel::kXrotation, Channel::kYrotation, Channel::kZrotation};
  joints[2].name = "leaf";
  joints[2].parent = 1;
  joints[2].offset = Eigen::Vector3d(0, 5, 1);
  joints[2].channels = {Channel::kYrotation, Channel::kZrotation, Channel::kXrotation};
  joints[2].end_site = Eigen::Vector3d(0, 2, 0);
  absl::StatusOr<Skeleton> skeleton = Skeleton::Create(std::move(joints));
  EXPECT_TRUE(skeleton.ok()) << skeleton.status();
  return std::make_shared<const Skeleton>(*std::move(skeleton));
}

Clip MakeClip(std::shared_ptr<const Skeleton> skeleton, int frames, double frame_time,
              const std::function<Quat(int frame, int joint)>& rotation,
              const std::function<Eigen::Vector3d(int frame, int joint)>& position) {
  const int joints = skeleton->joint_count();
  RowMatrixXd rotations(frames, 4 * joints);
  RowMatrixXd positions(frames, 3 * skeleton->position_joint_count());
  for (int f = 0; f < frames; ++f) {
    for (int j = 0; j < joints; ++j) {
      const Quat q = rotation(f, j).normalized();
      rotations.block<1, 4>(f, 4 * j) << q.w(), q.x(), q.y(), q.z();
      if (const int slot = skeleton->position_slot(j); slot >= 0) {
        positions.block<1, 3>(f, 3 * slot) = position(f, j).transpose();
      }
    }
  }
  absl::StatusOr<Clip> clip =
      Clip::Create(std::move(skeleton), frame_time, std::move(rotations), std::move(positions));
  EXPECT_TRUE(clip.ok()) << clip.status();
  return *std::move(clip);
}

}  // namespace motiondb::testing
