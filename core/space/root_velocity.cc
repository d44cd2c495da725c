#include "core/space/root_velocity.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/space/heading.h"

namespace motiondb {

namespace {

// The longest path of bone lengths (End Sites included) from `joint` down to a leaf. Lengths,
// not rest positions: many files (Bandai's among them) point every bone along its own X and
// give the rest posture by rotations, so only the offsets' lengths mean anything.
double LongestReach(const Skeleton& skeleton, int joint) {
  const Joint& j = skeleton.joint(joint);
  double reach = j.end_site ? j.end_site->norm() : 0.0;
  for (const int child : skeleton.Children(joint)) {
    reach = std::max(reach, skeleton.joint(child).offset.norm() + LongestReach(skeleton, child));
  }
  return reach;
}

}  // namespace

double LegLength(const Skeleton& skeleton) {
  const int pelvis = FindPelvis(skeleton);
  std::vector<double> reaches;
  for (const int child : skeleton.Children(pelvis)) {
    reaches.push_back(skeleton.joint(child).offset.norm() + LongestReach(skeleton, child));
  }
  if (reaches.empty()) return 1.0;
  std::sort(reaches.begin(), reaches.end());
  const double median = reaches[(reaches.size() - 1) / 2];
  return median > 0.0 ? median : 1.0;
}

namespace {

// The pelvis's position in the world at `frame`: the chain from the root, each joint placed by
// its position channels when it has them (some files move the pelvis, not a fixed root) or by
// its offset, turned by its parents' rotations.
Eigen::Vector3d PelvisPosition(const Clip& clip, const std::vector<int>& chain, int frame) {
  const Skeleton& skeleton = clip.skeleton();
  const auto row = clip.rotations().row(frame);
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Quat turn = Quat::Identity();
  for (const int j : chain) {
    const int slot = skeleton.position_slot(j);
    const Eigen::Vector3d local = slot < 0
                                      ? skeleton.joint(j).offset
                                      : clip.positions().block<1, 3>(frame, 3 * slot).transpose();
    position += turn * local;
    turn *= Quat(row[4 * j], row[4 * j + 1], row[4 * j + 2], row[4 * j + 3]);
  }
  return position;
}

}  // namespace

RowMatrixXd RootVelocity(const Clip& clip, const Eigen::VectorXd& yaw, int window) {
  std::vector<int> chain;  // root first, pelvis last
  for (int j = FindPelvis(clip.skeleton()); j >= 0; j = clip.skeleton().joint(j).parent) {
    chain.push_back(j);
  }
  std::reverse(chain.begin(), chain.end());
  const Eigen::Index frames = clip.frame_count();
  Eigen::VectorXd x(frames), z(frames);
  for (Eigen::Index f = 0; f < frames; ++f) {
    const Eigen::Vector3d pelvis = PelvisPosition(clip, chain, static_cast<int>(f));
    x[f] = pelvis.x();
    z[f] = pelvis.z();
  }
  const double scale = 1.0 / LegLength(clip.skeleton());
  const Eigen::VectorXd vx = YawRate(x, clip.fps(), window) * scale;
  const Eigen::VectorXd vz = YawRate(z, clip.fps(), window) * scale;
  RowMatrixXd velocity(frames, 2);
  for (Eigen::Index f = 0; f < frames; ++f) {
    // The heading turns the body by yaw about Y; its inverse turns world vectors into the body's.
    const double c = std::cos(yaw[f]), s = std::sin(yaw[f]);
    velocity(f, 0) = c * vx[f] - s * vz[f];
    velocity(f, 1) = s * vx[f] + c * vz[f];
  }
  return velocity;
}

}  // namespace motiondb
