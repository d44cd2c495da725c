#include "server/search_explanation.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace motiondb::server {
namespace {

// The name of pose-vector number `k`'s group: its joint (its bone in a space over several
// skeletons), or the extra dimensions'.
std::vector<std::string> GroupNames(const MotionSpace& space) {
  std::vector<std::string> names;
  for (int j = 0; j < space.part_count(); ++j) names.push_back(space.part_name(j));
  if (space.data().pose.remove_heading) names.push_back("yaw rate");
  if (space.data().pose.remove_heading && space.data().pose.root_velocity) {
    names.push_back("root velocity");
  }
  return names;
}

// Pose-vector number k's group: 3 numbers a joint, then the yaw rate, then the root velocity.
int GroupOf(int k, int joints) {
  return k < 3 * joints ? k / 3 : (k == 3 * joints ? joints : joints + 1);
}

void SetSpeeds(const std::vector<int64_t>& path, double rate, SearchExplanation* out) {
  const int64_t n = static_cast<int64_t>(path.size());
  if (n < 2) {
    out->mean_speed = out->max_speed = 1.0;
    return;
  }
  out->mean_speed = static_cast<double>(path.back() - path.front()) / (n - 1);
  const int64_t window = std::clamp<int64_t>(std::llround(kSpeedWindowS * rate), 1, n - 1);
  for (int64_t i = 0; i + window < n; ++i) {
    out->max_speed =
        std::max(out->max_speed, static_cast<double>(path[i + window] - path[i]) / window);
  }
}

}  // namespace

absl::StatusOr<SearchExplanation> ExplainHit(const MotionSpace& space, CoordinateView query,
                                             CoordinateView clip,
                                             const std::vector<int64_t>& path) {
  if (static_cast<int64_t>(path.size()) != query.rows) {
    return absl::InternalError(
        absl::StrCat("a path of ", path.size(), " rows for a query of ", query.rows));
  }
  const int dims = std::min<int>(space.dims(), std::min(query.stride, clip.stride));
  const Eigen::MatrixXd basis = space.data().basis.leftCols(dims);
  // A learned metric's coordinates are turned back into the space's, which split by joint.
  const RowMatrixXd& learned_inverse = space.search_transform_inverse();
  if (learned_inverse.size() > 0 && dims < space.dims()) {
    return absl::InternalError(absl::StrCat("coordinates of ", dims, " dimensions in a space of ",
                                            space.dims(), " with a learned metric"));
  }
  const int joints = space.part_count();
  const std::vector<std::string> names = GroupNames(space);
  std::vector<double> squared(names.size(), 0.0);
  double total_squared = 0, distance_sum = 0;
  Eigen::VectorXd difference(dims);
  for (int64_t i = 0; i < query.rows; ++i) {
    if (path[i] < 0 || path[i] >= clip.rows) {
      return absl::InternalError(absl::StrCat("path row ", i, " is outside the clip"));
    }
    for (int d = 0; d < dims; ++d) difference[d] = query.row(i)[d] - clip.row(path[i])[d];
    if (learned_inverse.size() > 0) difference = learned_inverse.transpose() * difference;
    const Eigen::VectorXd pose = basis * difference;
    for (int k = 0; k < pose.size(); ++k) squared[GroupOf(k, joints)] += pose[k] * pose[k];
    total_squared += difference.squaredNorm();
    distance_sum += difference.norm();
  }
  SearchExplanation out;
  out.full_score = query.rows > 0 ? distance_sum / query.rows : 0.0;
  for (size_t g = 0; g < names.size(); ++g) {
    const double share = total_squared > 0 ? squared[g] / total_squared : 0.0;
    out.joints.push_back({names[g], share, share * out.full_score});
  }
  std::stable_sort(out.joints.begin(), out.joints.end(),
                   [](const JointShare& a, const JointShare& b) { return a.share > b.share; });
  SetSpeeds(path, space.sample_rate(), &out);
  return out;
}

}  // namespace motiondb::server
