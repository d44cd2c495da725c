// The operators (core/ops) on a labelled folder of real capture (e.g.
// ../shared/mocap/bandai2-normal), for the real-data tests and the ops_measurements program:
// every clip in a space trained on the folder, and pose detection's precision and recall of the
// clips it fires on (thesis 3.4).
#ifndef MOTIONDB_TESTING_OPS_EVALUATION_H_
#define MOTIONDB_TESTING_OPS_EVALUATION_H_

#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/ops/pose_model.h"
#include "core/ops/space_motion.h"

namespace motiondb::testing {

struct LabelledMotions {
  std::vector<std::string> labels;  // per clip: the file name's content field
  std::vector<Clip> clips;
  std::unique_ptr<MotionSpace> space;  // trained on every clip
  std::vector<SpaceMotion> motions;    // per clip
};

// The space of the detection measurements: the default weights with the arms' raised (upper and
// lower arms x4, shoulders and hands x2, of Bandai's joints), as thesis 3.4 suggests for a pose
// told by the arms (bench/notes/2026-12-05-curve-operators.md compares it with the defaults).
SpaceOptions ArmsSpace();

absl::StatusOr<LabelledMotions> LoadLabelledMotions(const std::filesystem::path& folder,
                                                    const SpaceOptions& options);

// The frame of a curve farthest (over all dimensions) from the mean of its first and last
// frames: the peak of a move that starts and ends at rest.
int PeakFrame(const RowMatrixXd& curve);

// `clip` with every joint of every frame turned by a random rotation of about `sigma` radians
// (normal in each axis, sigma / sqrt(3) each), as capture jitter would.
Clip WithRotationNoise(const Clip& clip, double sigma, std::mt19937_64& generator);

struct DetectionEvaluationOptions {
  std::string label = "raise-up-both-hands";
  int examples = 5;  // clips of the label, the first of every `stride`, give their peak poses
  int stride = 1;
  int window = 2;      // frames either side of each peak taken as examples too
  int min_frames = 5;  // a clip fires on an interval at least this long
  PoseModelOptions model = {};
};

struct DetectionEvaluation {
  PoseModel model;
  int example_poses = 0;
  std::vector<bool> example;  // per clip: its peak poses are in the model
  int examples_fired = 0;     // of the example clips
  // Over the other clips only, which the model has not seen: an example clip's peak poses are
  // the model's own, so its firing says little about how the model generalises.
  int fired = 0, true_positives = 0, positives = 0;
  std::map<std::string, std::pair<int, int>> by_label;  // fired on, of
  double precision() const { return fired > 0 ? static_cast<double>(true_positives) / fired : 0; }
  double recall() const {
    return positives > 0 ? static_cast<double>(true_positives) / positives : 0;
  }
};

// Fits a model to the peak poses of example clips of `options.label` (each clip a group of the
// model's threshold) and runs it over every clip with the model's threshold; precision and
// recall count the clips that were not examples.
absl::StatusOr<DetectionEvaluation> EvaluatePoseDetection(
    const LabelledMotions& library, const DetectionEvaluationOptions& options);

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTING_OPS_EVALUATION_H_
