#include "core/ops/pose_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include <Eigen/Cholesky>

#include "absl/strings/str_cat.h"
#include "core/ops/internal/op_checks.h"
#include "util/status_macros.h"
#include "util/stop_poll.h"

namespace motiondb {
namespace {

using ops_internal::CheckBetween;

constexpr int kMaxComponents = 64;
constexpr int kMaxIterations = 10000;
constexpr double kNegativeInfinity = -std::numeric_limits<double>::infinity();

// A uniform double in [0, 1) of fixed definition (std's distributions may differ by library).
double Uniform(std::mt19937_64& generator) {
  return static_cast<double>(generator() >> 11) * 0x1.0p-53;
}

absl::Status CheckOptions(const PoseModelOptions& options, Eigen::Index examples,
                          Eigen::Index columns) {
  MOTIONDB_RETURN_IF_ERROR(CheckBetween("dims", options.dims, 1, static_cast<double>(columns)));
  MOTIONDB_RETURN_IF_ERROR(CheckBetween("components", options.components, 1, kMaxComponents));
  if (options.components > examples) {
    return absl::InvalidArgumentError(absl::StrCat("examples: ", examples, " poses cannot fit ",
                                                   options.components, " components"));
  }
  MOTIONDB_RETURN_IF_ERROR(
      CheckBetween("max_iterations", options.max_iterations, 1, kMaxIterations));
  MOTIONDB_RETURN_IF_ERROR(
      CheckBetween("tolerance", options.tolerance, 0.0, std::numeric_limits<double>::max()));
  MOTIONDB_RETURN_IF_ERROR(CheckBetween("regularization", options.regularization,
                                        std::numeric_limits<double>::min(), 1.0));
  return CheckBetween("threshold_quantile", options.threshold_quantile, 0.0, 1.0);
}

// Example values (examples x dims) of one component's step between two polls of a stop
// function: a component's E or M step costs a few of these a value (the dims-square
// covariance terms aside), about a millisecond.
constexpr int64_t kExampleValuesPerStopPoll = int64_t{1} << 18;

absl::Status PoseModelStopped() {
  return absl::CancelledError("fitting the pose model was stopped by its caller");
}

// k-means++: the first mean a random example, each next one drawn with probability in
// proportion to its squared distance from the nearest mean so far.
RowMatrixXd InitialMeans(const RowMatrixXd& x, int k, uint64_t seed) {
  std::mt19937_64 generator(seed);
  RowMatrixXd means(k, x.cols());
  means.row(0) = x.row(static_cast<Eigen::Index>(Uniform(generator) * x.rows()));
  Eigen::VectorXd nearest = (x.rowwise() - means.row(0)).rowwise().squaredNorm();
  for (int c = 1; c < k; ++c) {
    double target = Uniform(generator) * nearest.sum();
    Eigen::Index pick = x.rows() - 1;
    for (Eigen::Index n = 0; n < x.rows(); ++n) {
      target -= nearest[n];
      if (target < 0.0) {
        pick = n;
        break;
      }
    }
    means.row(c) = x.row(pick);
    nearest = nearest.cwiseMin((x.rowwise() - means.row(c)).rowwise().squaredNorm());
  }
  return means;
}

// Restricts a covariance to the model's type and adds the variance floor.
Eigen::MatrixXd Shape(Eigen::MatrixXd covariance, CovarianceType type, double floor) {
  const Eigen::Index d = covariance.rows();
  if (type == CovarianceType::kDiagonal) {
    covariance = Eigen::MatrixXd(covariance.diagonal().asDiagonal());
  } else if (type == CovarianceType::kSpherical) {
    covariance = Eigen::MatrixXd::Identity(d, d) * (covariance.trace() / static_cast<double>(d));
  }
  covariance.diagonal().array() += floor;
  return covariance;
}

// ln w_i + ln N(x_n; mu_i, Sigma_i) for every example n (rows) and component i (columns).
// `stop` is told each component's examples; the result is partial once it says stop.
RowMatrixXd LogJoint(const PoseModel& model, const Eigen::Ref<const RowMatrixXd>& x,
                     StopPoll& stop) {
  const Eigen::Index k = model.weights.size();
  const double d = model.dims;
  RowMatrixXd log_joint(x.rows(), k);
  for (Eigen::Index i = 0; i < k; ++i) {
    if (stop.Done(x.rows() * model.dims)) break;
    const Eigen::LLT<Eigen::MatrixXd> llt(model.covariances[i]);
    const double log_det = 2.0 * llt.matrixL().toDenseMatrix().diagonal().array().log().sum();
    const double constant =
        std::log(model.weights[i]) - 0.5 * (d * std::log(2.0 * std::numbers::pi) + log_det);
    const Eigen::MatrixXd centred =
        (x.leftCols(model.dims).rowwise() - model.means.row(i)).transpose();
    const Eigen::MatrixXd whitened = llt.matrixL().solve(centred);
    log_joint.col(i) = constant - 0.5 * whitened.colwise().squaredNorm().transpose().array();
  }
  return log_joint;
}

Eigen::VectorXd LogSumExpRows(const RowMatrixXd& values) {
  Eigen::VectorXd result(values.rows());
  for (Eigen::Index n = 0; n < values.rows(); ++n) {
    const double top = values.row(n).maxCoeff();
    result[n] = top == kNegativeInfinity
                    ? kNegativeInfinity
                    : top + std::log((values.row(n).array() - top).exp().sum());
  }
  return result;
}

// One M step from responsibilities (examples x components); `stop` as LogJoint's.
void Maximise(const RowMatrixXd& x, const RowMatrixXd& responsibility, double floor,
              PoseModel* model, StopPoll& stop) {
  for (Eigen::Index i = 0; i < model->weights.size(); ++i) {
    if (stop.Done(x.rows() * x.cols())) return;
    const double mass = responsibility.col(i).sum();
    model->weights[i] = mass / static_cast<double>(x.rows());
    if (mass < 1e-12) continue;  // an empty component keeps its place, with weight ~0
    model->means.row(i) = responsibility.col(i).transpose() * x / mass;
    const RowMatrixXd centred = x.rowwise() - model->means.row(i);
    const Eigen::MatrixXd scatter =
        centred.transpose() * responsibility.col(i).asDiagonal() * centred / mass;
    model->covariances[i] = Shape(scatter, model->covariance, floor);
  }
}

}  // namespace

absl::string_view CovarianceTypeName(CovarianceType type) {
  switch (type) {
    case CovarianceType::kFull:
      return "full";
    case CovarianceType::kDiagonal:
      return "diagonal";
    case CovarianceType::kSpherical:
      return "spherical";
  }
  return "full";
}

absl::StatusOr<CovarianceType> ParseCovarianceType(absl::string_view name) {
  for (const CovarianceType type :
       {CovarianceType::kFull, CovarianceType::kDiagonal, CovarianceType::kSpherical}) {
    if (name == CovarianceTypeName(type)) return type;
  }
  return absl::InvalidArgumentError(absl::StrCat(
      "covariance: '", name, "' is not a covariance type; expected full, diagonal or spherical"));
}

namespace {

// EM from k-means++ means; its threshold is left for the caller. `stop` is told the work of
// each component of each step: the model is partial once it says stop.
PoseModel FitMixture(const RowMatrixXd& x, const PoseModelOptions& options, StopPoll& stop) {
  const int k = options.components;
  const RowMatrixXd centred = x.rowwise() - x.colwise().mean();
  const Eigen::MatrixXd spread = centred.transpose() * centred / static_cast<double>(x.rows());
  // The floor scales with the data, with a tiny absolute part for examples that never vary.
  const double floor =
      options.regularization * spread.trace() / options.dims + std::numeric_limits<float>::min();
  PoseModel model;
  model.dims = options.dims;
  model.covariance = options.covariance;
  model.weights = Eigen::VectorXd::Constant(k, 1.0 / k);
  model.means = InitialMeans(x, k, options.seed);
  model.covariances.assign(k, Shape(spread, options.covariance, floor));
  double previous = kNegativeInfinity;
  for (model.iterations = 1; model.iterations <= options.max_iterations; ++model.iterations) {
    const RowMatrixXd log_joint = LogJoint(model, x, stop);
    if (stop.stopped()) return model;
    const Eigen::VectorXd log_likelihood = LogSumExpRows(log_joint);
    model.log_likelihood = log_likelihood.mean();
    RowMatrixXd responsibility = (log_joint.colwise() - log_likelihood).array().exp();
    Maximise(x, responsibility, floor, &model, stop);
    if (stop.stopped()) return model;
    if (model.log_likelihood - previous < options.tolerance) break;
    previous = model.log_likelihood;
  }
  model.iterations = std::min(model.iterations, options.max_iterations);
  model.log_likelihood = LogSumExpRows(LogJoint(model, x, stop)).mean();
  return model;
}

// The examples' log-likelihoods for the threshold: each group's under a model of the others.
absl::StatusOr<Eigen::VectorXd> HeldOutScores(const RowMatrixXd& x, const PoseModelOptions& options,
                                              const std::vector<int>& groups,
                                              const PoseModel& model, StopPoll& stop) {
  std::vector<int> names = groups;
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  if (names.size() < 2) return PoseLogLikelihood(model, x);
  Eigen::VectorXd scores(x.rows());
  for (const int group : names) {
    std::vector<Eigen::Index> in, out;
    for (Eigen::Index n = 0; n < x.rows(); ++n) (groups[n] == group ? in : out).push_back(n);
    if (static_cast<int>(out.size()) < options.components) {
      return absl::InvalidArgumentError(absl::StrCat("examples: without group ", group, ", ",
                                                     out.size(), " poses cannot fit ",
                                                     options.components, " components"));
    }
    const PoseModel others = FitMixture(x(out, Eigen::all), options, stop);
    if (stop.stopped()) return PoseModelStopped();
    const Eigen::VectorXd held = PoseLogLikelihood(others, x(in, Eigen::all));
    for (size_t i = 0; i < in.size(); ++i) scores[in[i]] = held[i];
  }
  return scores;
}

}  // namespace

absl::StatusOr<PoseModel> FitPoseModel(const Eigen::Ref<const RowMatrixXd>& examples,
                                       const PoseModelOptions& options,
                                       const std::vector<int>& groups,
                                       const std::function<bool()>& should_stop) {
  if (examples.rows() == 0) return absl::InvalidArgumentError("examples: no poses given");
  MOTIONDB_RETURN_IF_ERROR(
      ops_internal::CheckPoints("examples", examples, static_cast<int>(examples.cols()), 1, true));
  MOTIONDB_RETURN_IF_ERROR(CheckOptions(options, examples.rows(), examples.cols()));
  if (!groups.empty() && static_cast<Eigen::Index>(groups.size()) != examples.rows()) {
    return absl::InvalidArgumentError(
        absl::StrCat("groups: ", groups.size(), " given for ", examples.rows(), " examples"));
  }
  const RowMatrixXd x = examples.leftCols(options.dims);
  StopPoll stop(should_stop, kExampleValuesPerStopPoll);
  PoseModel model = FitMixture(x, options, stop);
  if (stop.stopped()) return PoseModelStopped();
  MOTIONDB_ASSIGN_OR_RETURN(Eigen::VectorXd scores, HeldOutScores(x, options, groups, model, stop));
  std::sort(scores.begin(), scores.end());
  model.threshold = scores[static_cast<Eigen::Index>(
      std::floor(options.threshold_quantile * static_cast<double>(scores.size() - 1)))];
  return model;
}

absl::Status ValidatePoseModel(const PoseModel& model) {
  const Eigen::Index k = model.weights.size();
  if (model.dims < 1 || k < 1 || k > kMaxComponents || model.means.rows() != k ||
      model.means.cols() != model.dims ||
      static_cast<Eigen::Index>(model.covariances.size()) != k) {
    return absl::InvalidArgumentError("pose model: its parts' shapes do not agree");
  }
  if (!model.weights.allFinite() || (model.weights.array() < 0.0).any() ||
      std::abs(model.weights.sum() - 1.0) > 1e-6 || !model.means.allFinite() ||
      !std::isfinite(model.threshold)) {
    return absl::InvalidArgumentError("pose model: weights, means or threshold are not valid");
  }
  for (const Eigen::MatrixXd& covariance : model.covariances) {
    if (covariance.rows() != model.dims || covariance.cols() != model.dims ||
        !covariance.allFinite() || !covariance.isApprox(covariance.transpose()) ||
        Eigen::LLT<Eigen::MatrixXd>(covariance).info() != Eigen::Success) {
      return absl::InvalidArgumentError(
          "pose model: a covariance is not symmetric positive definite");
    }
  }
  return absl::OkStatus();
}

Eigen::VectorXd PoseLogLikelihood(const PoseModel& model,
                                  const Eigen::Ref<const RowMatrixXd>& points) {
  StopPoll never;
  return LogSumExpRows(LogJoint(model, points, never));
}

}  // namespace motiondb
