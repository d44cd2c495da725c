#include "core/ops/pose_model_serialization.h"

#include <vector>

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using nlohmann::json;

std::vector<double> Values(const Eigen::Ref<const RowMatrixXd>& m) {
  return std::vector<double>(m.data(), m.data() + m.size());
}

RowMatrixXd Matrix(const json& values, Eigen::Index rows, Eigen::Index cols) {
  const std::vector<double> numbers = values.get<std::vector<double>>();
  if (static_cast<Eigen::Index>(numbers.size()) != rows * cols) {
    throw std::invalid_argument(absl::StrCat("expected ", rows * cols, " numbers"));
  }
  return Eigen::Map<const RowMatrixXd>(numbers.data(), rows, cols);
}

}  // namespace

std::string SerializePoseModel(const PoseModel& model) {
  json covariances = json::array();
  for (const Eigen::MatrixXd& covariance : model.covariances) {
    covariances.push_back(Values(RowMatrixXd(covariance)));
  }
  const json out = {{"dims", model.dims},
                    {"covariance", std::string(CovarianceTypeName(model.covariance))},
                    {"weights", Values(model.weights.transpose())},
                    {"means", Values(model.means)},
                    {"covariances", covariances},
                    {"threshold", model.threshold},
                    {"iterations", model.iterations},
                    {"log_likelihood", model.log_likelihood}};
  return out.dump();
}

absl::StatusOr<PoseModel> ParsePoseModel(absl::string_view text) {
  PoseModel model;
  try {
    const json in = json::parse(text);
    model.dims = in.at("dims").get<int>();
    MOTIONDB_ASSIGN_OR_RETURN(model.covariance,
                              ParseCovarianceType(in.at("covariance").get<std::string>()));
    const std::vector<double> weights = in.at("weights").get<std::vector<double>>();
    const Eigen::Index k = static_cast<Eigen::Index>(weights.size());
    if (model.dims < 1 || k < 1) throw std::invalid_argument("no dimensions or components");
    model.weights = Eigen::Map<const Eigen::VectorXd>(weights.data(), k);
    model.means = Matrix(in.at("means"), k, model.dims);
    for (const json& covariance : in.at("covariances")) {
      model.covariances.push_back(Matrix(covariance, model.dims, model.dims));
    }
    model.threshold = in.at("threshold").get<double>();
    model.iterations = in.at("iterations").get<int>();
    model.log_likelihood = in.at("log_likelihood").get<double>();
  } catch (const std::exception& error) {
    return absl::InvalidArgumentError(absl::StrCat("pose model: ", error.what()));
  }
  MOTIONDB_RETURN_IF_ERROR(ValidatePoseModel(model));
  return model;
}

}  // namespace motiondb
