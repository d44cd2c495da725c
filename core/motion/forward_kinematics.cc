#include "core/motion/forward_kinematics.h"

#include <vector>

namespace motiondb {

RowMatrixXd ForwardKinematics(const Clip& clip) {
  const Skeleton& skeleton = clip.skeleton();
  const int frames = clip.frame_count();
  const int joints = skeleton.joint_count();
  RowMatrixXd world(frames, 3 * joints);
  // World orientations of every frame, one joint's column at a time: a child needs only its
  // parent's, which comes earlier.
  std::vector<std::vector<Quat>> orientation(joints, std::vector<Quat>(frames));
  for (int j = 0; j < joints; ++j) {
    const Joint& joint = skeleton.joint(j);
    const int slot = skeleton.position_slot(j);
    for (int f = 0; f < frames; ++f) {
      const Eigen::Vector3d local =
          slot >= 0 ? Eigen::Vector3d(clip.positions().block<1, 3>(f, 3 * slot).transpose())
                    : joint.offset;
      if (joint.parent < 0) {
        orientation[j][f] = clip.rotation(f, j);
        world.block<1, 3>(f, 3 * j) = local.transpose();
      } else {
        const Quat& parent = orientation[joint.parent][f];
        orientation[j][f] = parent * clip.rotation(f, j);
        world.block<1, 3>(f, 3 * j) =
            world.block<1, 3>(f, 3 * joint.parent) + (parent * local).transpose();
      }
    }
  }
  return world;
}

}  // namespace motiondb
