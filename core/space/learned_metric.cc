#include "core/space/learned_metric.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

absl::Status CheckExamples(absl::Span<const LabelledCurve> examples,
                           const LearnedMetricOptions& options) {
  MOTIONDB_RETURN_IF_ERROR(ValidateLearnedMetricOptions(options));
  if (examples.empty()) return absl::InvalidArgumentError("examples: none given");
  const Eigen::Index dims = examples.front().coordinates->cols();
  for (size_t e = 0; e < examples.size(); ++e) {
    const RowMatrixXf& coordinates = *examples[e].coordinates;
    if (coordinates.cols() != dims || coordinates.rows() == 0 || dims == 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("examples[", e, "]: ", coordinates.rows(), " x ", coordinates.cols(),
                       " coordinates; every example needs frames of ", dims, " dimensions"));
    }
    if (!coordinates.allFinite()) {
      return absl::InvalidArgumentError(
          absl::StrCat("examples[", e, "]: its coordinates hold a non-finite number"));
    }
  }
  return absl::OkStatus();
}

// The mean outer product of the pose differences along the plain DTW path (steps of one frame
// in either clip or both, Euclidean cost) between `a` and `b`.
Eigen::MatrixXd AlignedDifferenceScatter(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  const Eigen::Index n = a.rows(), m = b.rows();
  const Eigen::MatrixXd cost =
      ((a.rowwise().squaredNorm() * Eigen::RowVectorXd::Ones(m) +
        Eigen::VectorXd::Ones(n) * b.rowwise().squaredNorm().transpose() - 2 * a * b.transpose())
           .cwiseMax(0.0))
          .cwiseSqrt();
  Eigen::MatrixXd total(n, m);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < m; ++j) {
      double best = i == 0 && j == 0 ? 0 : kInf;
      if (i > 0) best = std::min(best, total(i - 1, j));
      if (j > 0) best = std::min(best, total(i, j - 1));
      if (i > 0 && j > 0) best = std::min(best, total(i - 1, j - 1));
      total(i, j) = best + cost(i, j);
    }
  }
  Eigen::MatrixXd scatter = Eigen::MatrixXd::Zero(a.cols(), a.cols());
  int cells = 0;
  for (Eigen::Index i = n - 1, j = m - 1;;) {
    const Eigen::VectorXd d = (a.row(i) - b.row(j)).transpose();
    scatter.noalias() += d * d.transpose();
    ++cells;
    if (i == 0 && j == 0) break;
    if (i == 0) {
      --j;
    } else if (j == 0) {
      --i;
    } else {
      const double diagonal = total(i - 1, j - 1), up = total(i - 1, j), left = total(i, j - 1);
      if (diagonal <= up && diagonal <= left) {
        --i;
        --j;
      } else if (up <= left) {
        --i;
      } else {
        --j;
      }
    }
  }
  return scatter / cells;
}

}  // namespace

absl::Status ValidateLearnedMetricOptions(const LearnedMetricOptions& options) {
  if (!(options.shrink >= 0 && options.shrink < 1)) {
    return absl::InvalidArgumentError(
        absl::StrCat("shrink: ", options.shrink, " is outside [0, 1)"));
  }
  if (options.partners < 1) {
    return absl::InvalidArgumentError(absl::StrCat("partners: ", options.partners, " is below 1"));
  }
  if (options.max_frames < 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_frames: ", options.max_frames, " is below 2"));
  }
  return absl::OkStatus();
}

RowMatrixXf AlignedFrames(const Eigen::Ref<const RowMatrixXf>& rows, int max_frames) {
  const Eigen::Index step = (rows.rows() + max_frames - 1) / std::max(max_frames, 1);
  return rows(Eigen::seq(0, Eigen::last, std::max<Eigen::Index>(step, 1)), Eigen::all);
}

absl::StatusOr<Eigen::MatrixXd> FitLearnedMetric(absl::Span<const LabelledCurve> examples,
                                                 const LearnedMetricOptions& options,
                                                 const std::function<bool()>& should_stop) {
  MOTIONDB_RETURN_IF_ERROR(CheckExamples(examples, options));
  const Eigen::Index dims = examples.front().coordinates->cols();
  std::vector<Eigen::MatrixXd> curves(examples.size());
  std::map<std::string, std::vector<size_t>> of_label;  // in increasing order
  for (size_t e = 0; e < examples.size(); ++e) {
    curves[e] = AlignedFrames(*examples[e].coordinates, options.max_frames).cast<double>();
    of_label[examples[e].label].push_back(e);
  }

  // The examples' frames' covariance, and the groups' aligned differences, one share a pair.
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(dims);
  Eigen::MatrixXd outer = Eigen::MatrixXd::Zero(dims, dims);
  Eigen::MatrixXd groups = Eigen::MatrixXd::Zero(dims, dims);
  double frames = 0;
  int pairs = 0;
  for (size_t e = 0; e < curves.size(); ++e) {
    if (should_stop && should_stop()) {
      return absl::CancelledError("stopped by its caller while fitting the learned metric");
    }
    sum += curves[e].colwise().sum().transpose();
    outer.noalias() += curves[e].transpose() * curves[e];
    frames += static_cast<double>(curves[e].rows());
    const std::vector<size_t>& same = of_label[examples[e].label];
    int partners = 0;
    for (auto other = std::upper_bound(same.begin(), same.end(), e);
         other != same.end() && partners < options.partners; ++other) {
      if (examples[*other].group == examples[e].group) continue;
      groups += AlignedDifferenceScatter(curves[e], curves[*other]);
      ++pairs;
      ++partners;
    }
  }
  if (pairs == 0) {
    return absl::FailedPreconditionError(
        "examples: no two of one label in two groups, so nothing tells what a group changes");
  }
  const Eigen::VectorXd mean = sum / frames;
  const Eigen::MatrixXd total = outer / frames - mean * mean.transpose();
  groups /= pairs;

  // The groups' differences whitened, shrunk towards the identity at their mean variance.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> group_axes(groups);
  const double mean_variance = groups.trace() / static_cast<double>(dims);
  if (!(mean_variance > 0)) {
    return absl::FailedPreconditionError(
        "examples: the aligned examples of one label are identical across groups");
  }
  const Eigen::VectorXd scales = ((1 - options.shrink) * mean_variance +
                                  options.shrink * group_axes.eigenvalues().array().max(0.0))
                                     .rsqrt()
                                     .matrix();
  const Eigen::MatrixXd whiten =
      group_axes.eigenvectors() * scales.asDiagonal() * group_axes.eigenvectors().transpose();

  // Rotated to the principal axes of the examples' frames in the new metric, largest first.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> spread(whiten * total * whiten);
  Eigen::MatrixXd transform = whiten * spread.eigenvectors().rowwise().reverse();
  const double variance = (transform.transpose() * total * transform).trace();
  if (variance > 0) transform *= std::sqrt(total.trace() / variance);
  return transform;
}

}  // namespace motiondb
