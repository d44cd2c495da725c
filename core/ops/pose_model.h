// A Mixture-of-Gaussians model of example poses in a truncated space (thesis 3.4): rather than
// one "ideal" instance, a distribution of the valid variations of a pose, fitted by
// expectation-maximisation to the first `dims` coordinates of example poses, and scored on any
// pose of the space's skeleton as a log-likelihood,
//   ln p(x) = ln sum_i w_i N(x; mu_i, Sigma_i),
//   ln N(x; mu, Sigma) = -1/2 (x - mu)^T Sigma^-1 (x - mu) - d/2 ln(2 pi) - 1/2 ln |Sigma|.
// The weighting of the space and the truncation say which features of the pose matter.
//
// Fitting is deterministic for a seed: k-means++ picks the initial means with a seeded
// generator of fixed definition. Pure functions; thread-safe.
#ifndef MOTIONDB_CORE_OPS_POSE_MODEL_H_
#define MOTIONDB_CORE_OPS_POSE_MODEL_H_

#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/motion/matrix.h"

namespace motiondb {

enum class CovarianceType {
  kFull,       // any ellipsoid
  kDiagonal,   // axis-aligned
  kSpherical,  // one variance for every dimension
};

// "full", "diagonal", "spherical".
absl::string_view CovarianceTypeName(CovarianceType type);
absl::StatusOr<CovarianceType> ParseCovarianceType(absl::string_view name);

struct PoseModelOptions {
  // Gaussians k, 1..64 and at most the number of examples.
  int components = 2;
  CovarianceType covariance = CovarianceType::kFull;
  // Truncation: the model's dimensions, 1..the examples' (3.4 used three).
  int dims = 3;
  // Seeds the initial means; equal seeds give equal models.
  uint64_t seed = 1;
  // EM iterations at most, 1..10000.
  int max_iterations = 200;
  // EM stops once the mean log-likelihood per example gains less; finite, >= 0.
  double tolerance = 1e-6;
  // Added to every variance, as a share of the examples' mean variance per dimension, so that a
  // component cannot collapse onto a single pose; finite, in (0, 1].
  double regularization = 1e-3;
  // The model's detection threshold: this quantile, in [0, 1], of the examples' log-likelihoods,
  // each scored by a model fitted without its group (see FitPoseModel), so that the threshold
  // admits new instances of the pose, not only the examples themselves; 0: the least likely.
  double threshold_quantile = 0.0;
};

struct PoseModel {
  int dims = 0;
  CovarianceType covariance = CovarianceType::kFull;
  Eigen::VectorXd weights;                     // k, summing to 1
  RowMatrixXd means;                           // k x dims
  std::vector<Eigen::MatrixXd> covariances{};  // k of dims x dims, symmetric positive definite
  double threshold = 0.0;                      // the default detection threshold
  int iterations = 0;                          // EM iterations run
  double log_likelihood = 0.0;                 // mean over the examples
};

// Fits a model to `examples` (m x at least options.dims coordinates, the first options.dims
// used). `groups` (empty, or one per example) says which examples belong together, such as the
// poses of one example clip: with two groups or more, each group's examples are scored for the
// threshold by a model fitted to the other groups (leave one group out), which estimates how
// likely an unseen instance of the pose is; with one, by the model itself. INVALID_ARGUMENT
// naming the option, or examples when there are none, too few for k (in every group's
// complement too), or NaN values, or groups of the wrong size.
// `should_stop` is asked about every millisecond of EM: CANCELLED once it says stop.
absl::StatusOr<PoseModel> FitPoseModel(const Eigen::Ref<const RowMatrixXd>& examples,
                                       const PoseModelOptions& options = {},
                                       const std::vector<int>& groups = {},
                                       const std::function<bool()>& should_stop = {});

// A model's consistency (shapes, weights, positive definite covariances), e.g. after parsing.
absl::Status ValidatePoseModel(const PoseModel& model);

// ln p(x) for every row of `points` (first model.dims coordinates used; at least that many
// columns). The model must be valid.
Eigen::VectorXd PoseLogLikelihood(const PoseModel& model,
                                  const Eigen::Ref<const RowMatrixXd>& points);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_OPS_POSE_MODEL_H_
