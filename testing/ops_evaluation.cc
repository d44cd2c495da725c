#include "testing/ops_evaluation.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/ops/pose_detection.h"
#include "testing/labelled_index.h"
#include "util/status_macros.h"

namespace motiondb::testing {

SpaceOptions ArmsSpace() {
  SpaceOptions options;
  options.weights.overrides = {{"Shoulder_L", 2}, {"Shoulder_R", 2}, {"UpperArm_L", 4},
                               {"UpperArm_R", 4}, {"LowerArm_L", 4}, {"LowerArm_R", 4},
                               {"Hand_L", 2},     {"Hand_R", 2}};
  return options;
}

absl::StatusOr<LabelledMotions> LoadLabelledMotions(const std::filesystem::path& folder,
                                                    const SpaceOptions& options) {
  LabelledMotions library;
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<TrainingClip> training,
                            ReadLabelledFolder(folder, &library.labels));
  for (const TrainingClip& clip : training) library.clips.push_back(clip.clip);
  MOTIONDB_ASSIGN_OR_RETURN(MotionSpace space, MotionSpace::Build(training, options));
  library.space = std::make_unique<MotionSpace>(std::move(space));
  for (const Clip& clip : library.clips) {
    MOTIONDB_ASSIGN_OR_RETURN(SpaceMotion motion, EnterSpace(*library.space, clip));
    library.motions.push_back(std::move(motion));
  }
  return library;
}

int PeakFrame(const RowMatrixXd& curve) {
  const Eigen::RowVectorXd rest = 0.5 * (curve.row(0) + curve.row(curve.rows() - 1));
  Eigen::Index peak = 0;
  (curve.rowwise() - rest).rowwise().norm().maxCoeff(&peak);
  return static_cast<int>(peak);
}

Clip WithRotationNoise(const Clip& clip, double sigma, std::mt19937_64& generator) {
  std::normal_distribution<double> normal(0.0, sigma / std::sqrt(3.0));
  RowMatrixXd rotations = clip.rotations();
  for (Eigen::Index f = 0; f < rotations.rows(); ++f) {
    for (Eigen::Index j = 0; j < rotations.cols(); j += 4) {
      const auto q = rotations.block<1, 4>(f, j);
      const Eigen::Vector3d turn(normal(generator), normal(generator), normal(generator));
      const Quat noisy = (Quat(q[0], q[1], q[2], q[3]) * ExpMap(turn)).normalized();
      rotations.block<1, 4>(f, j) << noisy.w(), noisy.x(), noisy.y(), noisy.z();
    }
  }
  // The same shapes as a valid clip's, the rotations still of unit length.
  return *Clip::Create(clip.shared_skeleton(), clip.frame_time(), std::move(rotations),
                       clip.positions());
}

absl::StatusOr<DetectionEvaluation> EvaluatePoseDetection(
    const LabelledMotions& library, const DetectionEvaluationOptions& options) {
  DetectionEvaluation evaluation;
  evaluation.example.assign(library.motions.size(), false);
  std::vector<RowMatrixXd> parts;
  std::vector<int> groups;
  for (size_t i = 0, seen = 0;
       i < library.motions.size() && static_cast<int>(parts.size()) < options.examples; ++i) {
    if (library.labels[i] != options.label || seen++ % options.stride != 0) continue;
    const RowMatrixXd& curve = library.motions[i].coordinates;
    const int peak = PeakFrame(curve);
    const int first = std::max(0, peak - options.window);
    const int last = std::min(static_cast<int>(curve.rows()) - 1, peak + options.window);
    groups.insert(groups.end(), last - first + 1, static_cast<int>(parts.size()));
    parts.push_back(curve.middleRows(first, last - first + 1));
    evaluation.example[i] = true;
  }
  RowMatrixXd examples(groups.size(), library.space->dims());
  Eigen::Index row = 0;
  for (const RowMatrixXd& part : parts) {
    examples.middleRows(row, part.rows()) = part;
    row += part.rows();
  }
  evaluation.example_poses = static_cast<int>(examples.rows());
  MOTIONDB_ASSIGN_OR_RETURN(evaluation.model, FitPoseModel(examples, options.model, groups));
  for (size_t i = 0; i < library.motions.size(); ++i) {
    MOTIONDB_ASSIGN_OR_RETURN(const Detection detection,
                              DetectPose(evaluation.model, library.motions[i].coordinates,
                                         {.min_frames = options.min_frames}));
    const bool fires = !detection.intervals.empty();
    if (evaluation.example[i]) {
      evaluation.examples_fired += fires;
      continue;
    }
    const bool positive = library.labels[i] == options.label;
    evaluation.fired += fires;
    evaluation.positives += positive;
    evaluation.true_positives += fires && positive;
    auto& [fired_on, of] = evaluation.by_label[library.labels[i]];
    fired_on += fires;
    ++of;
  }
  return evaluation;
}

}  // namespace motiondb::testing
