#include "core/space/heading.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace motiondb {
namespace {

// Below this squared norm of (w, y) the twist about Y is undefined.
constexpr double kUndefinedTwist = 1e-20;

}  // namespace

int FindPelvis(const Skeleton& skeleton) {
  int joint = 0;
  while (true) {
    const std::vector<int> children = skeleton.Children(joint);
    if (children.size() >= 2) return joint;
    if (children.empty()) return 0;
    joint = children.front();
  }
}

Quat HeadingOf(const Quat& global) {
  const double sign = global.w() < 0.0 ? -1.0 : 1.0;
  const double w = sign * global.w();
  const double y = sign * global.y();
  const double norm2 = w * w + y * y;
  if (norm2 < kUndefinedTwist) return Quat::Identity();
  const double inverse_norm = 1.0 / std::sqrt(norm2);
  return Quat(w * inverse_norm, 0.0, y * inverse_norm, 0.0);
}

Eigen::VectorXd RemoveHeading(const Skeleton& skeleton, RowMatrixXd* rotations) {
  std::vector<int> chain;  // root first, pelvis last
  for (int j = FindPelvis(skeleton); j >= 0; j = skeleton.joint(j).parent) chain.push_back(j);
  std::reverse(chain.begin(), chain.end());
  const int pelvis = chain.back();

  const Eigen::Index frames = rotations->rows();
  Eigen::VectorXd yaw(frames);
  for (Eigen::Index f = 0; f < frames; ++f) {
    auto row = rotations->row(f);
    Quat global = Quat::Identity();
    for (const int j : chain) {
      global *= Quat(row[4 * j], row[4 * j + 1], row[4 * j + 2], row[4 * j + 3]);
      row.segment<4>(4 * j) << 1.0, 0.0, 0.0, 0.0;
    }
    const Quat heading = HeadingOf(global);
    const Quat rest = heading.conjugate() * global;
    row.segment<4>(4 * pelvis) << rest.w(), rest.x(), rest.y(), rest.z();

    const double raw = 2.0 * std::atan2(heading.y(), heading.w());
    if (f == 0) {
      yaw[f] = raw;
    } else {
      const double step = raw - yaw[f - 1];
      yaw[f] = yaw[f - 1] + std::remainder(step, 2.0 * std::numbers::pi);
    }
  }
  return yaw;
}

Eigen::VectorXd YawRate(const Eigen::VectorXd& yaw, double fps, int window) {
  const Eigen::Index n = yaw.size();
  Eigen::VectorXd rate = Eigen::VectorXd::Zero(n);
  if (n < 2) return rate;
  rate[0] = (yaw[1] - yaw[0]) * fps;
  rate[n - 1] = (yaw[n - 1] - yaw[n - 2]) * fps;
  if (n > 2) {
    rate.segment(1, n - 2) = (yaw.tail(n - 2) - yaw.head(n - 2)) * (0.5 * fps);
  }
  // Centred moving average from prefix sums: sum[k] holds rate[0] + ... + rate[k - 1].
  Eigen::VectorXd sum(n + 1);
  sum[0] = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) sum[k + 1] = sum[k] + rate[k];
  const Eigen::Index half = std::max(window, 1) / 2;
  Eigen::VectorXd smoothed(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const Eigen::Index first = std::max<Eigen::Index>(0, k - half);
    const Eigen::Index end = std::min(n, k + half + 1);
    smoothed[k] = (sum[end] - sum[first]) / static_cast<double>(end - first);
  }
  return smoothed;
}

}  // namespace motiondb
