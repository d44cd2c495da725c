#include "bench/style_metric.h"

#include <algorithm>
#include <limits>

#include <Eigen/Eigenvalues>

namespace motiondb::bench {
namespace {

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

absl::StatusOr<Eigen::MatrixXd> FitStyleMetric(const std::vector<RowMatrixXf>& coordinates,
                                               const std::vector<std::string>& labels,
                                               const std::vector<std::string>& styles,
                                               const std::vector<bool>& fit,
                                               const StyleMetricOptions& options) {
  const Eigen::Index dims = coordinates.front().cols();
  std::vector<Eigen::MatrixXd> clips(coordinates.size());
  for (size_t c = 0; c < coordinates.size(); ++c) clips[c] = coordinates[c].cast<double>();

  // The fitting frames' covariance, and the styles' aligned differences, one share a pair.
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(dims);
  Eigen::MatrixXd outer = Eigen::MatrixXd::Zero(dims, dims);
  Eigen::MatrixXd style = Eigen::MatrixXd::Zero(dims, dims);
  double frames = 0;
  int pairs = 0;
  for (size_t c = 0; c < clips.size(); ++c) {
    if (!fit[c]) continue;
    sum += clips[c].colwise().sum().transpose();
    outer.noalias() += clips[c].transpose() * clips[c];
    frames += static_cast<double>(clips[c].rows());
    int partners = 0;
    for (size_t other = c + 1; other < clips.size() && partners < options.partners; ++other) {
      if (!fit[other] || labels[other] != labels[c] || styles[other] == styles[c]) continue;
      style += AlignedDifferenceScatter(clips[c], clips[other]);
      ++pairs;
      ++partners;
    }
  }
  if (pairs == 0) {
    return absl::InvalidArgumentError("no two clips of one content in two styles to fit on");
  }
  const Eigen::VectorXd mean = sum / frames;
  const Eigen::MatrixXd total = outer / frames - mean * mean.transpose();
  style /= pairs;

  // Whitening of the style differences, shrunk towards the identity at their mean variance.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> style_eigen(style);
  const double mean_variance = style.trace() / static_cast<double>(dims);
  const Eigen::VectorXd scales = ((1 - options.shrink) * mean_variance +
                                  options.shrink * style_eigen.eigenvalues().array().max(0.0))
                                     .rsqrt()
                                     .matrix();
  const Eigen::MatrixXd whiten =
      style_eigen.eigenvectors() * scales.asDiagonal() * style_eigen.eigenvectors().transpose();

  // Rotated to the principal axes of the fitting frames in the new metric, largest first.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> spread(whiten * total * whiten);
  Eigen::MatrixXd transform = whiten * spread.eigenvectors().rowwise().reverse();
  const double variance = (transform.transpose() * total * transform).trace();
  transform *= std::sqrt(total.trace() / variance);
  return transform;
}

}  // namespace motiondb::bench
