// motiondb space build --train FILE[:FROM-TO]... --out SPACE.mcs [--rate 30]
//     [--weights mass|uniform|FILE.json] [--yaw-rate-weight W] [--metric unit|eigen]
//     [--keep-heading] [--json]
#include <iostream>

#include <nlohmann/json.hpp>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/commands.h"
#include "core/bvh/bvh_reader.h"
#include "core/space/heading.h"
#include "core/space/motion_space.h"
#include "core/space/space_serialization.h"
#include "util/command_line.h"
#include "util/file_io.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::cli {
namespace {

constexpr char kUsage[] =
    "usage: motiondb space build --train FILE[:FROM-TO]... --out SPACE.mcs [--rate 30]\n"
    "           [--weights mass|uniform|FILE.json] [--yaw-rate-weight 0.5]\n"
    "           [--metric unit|eigen] [--keep-heading] [--json]\n"
    "  --train   BVH files to learn the space from, each optionally cut to frames FROM..TO\n"
    "            (inclusive, counted from 0 at the file's rate); repeat or list several\n"
    "  --weights a preset, or a JSON object {\"Joint\": weight} overriding the mass preset\n"
    "  --keep-heading  keep the body's facing in the pose (no yaw-rate dimension)\n";

// Joint-weights files larger than this are refused: a few hundred joints fit in kilobytes.
constexpr int64_t kMaxWeightsFileBytes = int64_t{1} << 20;

// FILE or FILE:FROM-TO. A suffix after the last ':' that is not digits and one '-' is taken as
// part of the file name.
absl::StatusOr<TrainingClip> LoadTrainingRange(const std::string& spec) {
  std::string path = spec;
  std::optional<FrameRange> frames;
  if (const size_t colon = spec.rfind(':'); colon != std::string::npos) {
    const absl::string_view suffix = absl::string_view(spec).substr(colon + 1);
    if (!suffix.empty() && suffix.find_first_not_of("0123456789-") == absl::string_view::npos) {
      const size_t dash = suffix.find('-');
      FrameRange range;
      if (dash == absl::string_view::npos ||
          !absl::SimpleAtoi(suffix.substr(0, dash), &range.first) ||
          !absl::SimpleAtoi(suffix.substr(dash + 1), &range.last)) {
        return absl::InvalidArgumentError(
            absl::StrCat(spec, ": expected FILE:FROM-TO with whole frame numbers"));
      }
      path = spec.substr(0, colon);
      frames = range;
    }
  }
  MOTIONDB_ASSIGN_OR_RETURN(BvhReadResult read, ReadBvhFile(path));
  for (const std::string& warning : read.warnings) {
    std::cerr << "motiondb space: warning: " << path << ": " << warning << "\n";
  }
  return TrainingClip{spec, std::move(read.clip), frames};
}

absl::Status ApplyWeights(const std::string& weights, SpaceOptions* options) {
  if (!absl::EndsWith(weights, ".json")) {
    MOTIONDB_ASSIGN_OR_RETURN(options->weights.preset, ParseWeightPreset(weights));
    return absl::OkStatus();
  }
  MOTIONDB_ASSIGN_OR_RETURN(const std::string text, ReadFileBytes(weights, kMaxWeightsFileBytes));
  MOTIONDB_ASSIGN_OR_RETURN(options->weights.overrides,
                            Prefixed(weights, ParseWeightOverrides(text)));
  return absl::OkStatus();
}

absl::StatusOr<SpaceOptions> ParseOptions(const CommandLine& line) {
  SpaceOptions options;
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<double> rate, line.number("rate"));
  options.sample_rate = rate.value_or(options.sample_rate);
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<double> yaw, line.number("yaw-rate-weight"));
  options.yaw_rate_weight = yaw.value_or(options.yaw_rate_weight);
  options.pose.remove_heading = !line.flag("keep-heading");
  if (const std::optional<std::string> weights = line.value("weights")) {
    MOTIONDB_RETURN_IF_ERROR(ApplyWeights(*weights, &options));
  }
  // The same names as the server's `space create`.
  const std::string metric = line.value("metric").value_or("unit");
  if (metric != "unit" && metric != "eigen") {
    return absl::InvalidArgumentError(
        absl::StrCat("--metric expects unit or eigen, got '", metric, "'"));
  }
  if (metric == "eigen") options.metric = SpaceMetric::kEigenvalueScaled;
  return options;
}

nlohmann::json Report(const std::string& out, const MotionSpace& space,
                      const std::vector<ReconstructionError>& errors) {
  const SpaceData& data = space.data();
  nlohmann::json weights = nlohmann::json::object();
  for (int j = 0; j < space.skeleton().joint_count(); ++j) {
    weights[space.skeleton().joint(j).name] = data.joint_weights[j];
  }
  const Eigen::VectorXd explained = space.ExplainedVariance();
  nlohmann::json reconstruction = nlohmann::json::array();
  for (const ReconstructionError& error : errors) {
    reconstruction.push_back(
        {{"dims", error.dims}, {"mean_rad", error.mean_rad}, {"max_rad", error.max_rad}});
  }
  return {
      {"out", out},
      {"dims", space.dims()},
      {"joints", space.skeleton().joint_count()},
      {"pelvis", space.skeleton().joint(FindPelvis(space.skeleton())).name},
      {"sample_rate", space.sample_rate()},
      {"heading_removed", data.pose.remove_heading},
      {"yaw_rate_weight",
       data.pose.remove_heading ? nlohmann::json(data.yaw_rate_weight) : nlohmann::json(nullptr)},
      {"metric", data.metric == SpaceMetric::kUnit ? "unit" : "eigen"},
      {"training_ranges", data.training.size()},
      {"joint_weights", std::move(weights)},
      {"explained_variance", std::vector<double>(explained.begin(), explained.end())},
      {"reconstruction_error", std::move(reconstruction)},
  };
}

void PrintText(const std::string& out, const MotionSpace& space,
               const std::vector<ReconstructionError>& errors) {
  const SpaceData& data = space.data();
  absl::PrintF("wrote %s\n", out);
  absl::PrintF("  skeleton: %d joints, pelvis %s\n", space.skeleton().joint_count(),
               space.skeleton().joint(FindPelvis(space.skeleton())).name);
  absl::PrintF("  training: %d ranges at %g Hz, heading %s\n", data.training.size(),
               space.sample_rate(),
               data.pose.remove_heading
                   ? absl::StrFormat("removed (yaw-rate weight %g)", data.yaw_rate_weight)
                   : std::string("kept"));
  absl::PrintF("  dims:     %d\n", space.dims());
  absl::PrintF("  explained variance (dim: share, cumulative):\n");
  const Eigen::VectorXd explained = space.ExplainedVariance();
  double cumulative = 0.0;
  for (int i = 0; i < space.dims(); ++i) {
    cumulative += explained[i];
    absl::PrintF("    %3d: %.4f  %.4f\n", i + 1, explained[i], cumulative);
  }
  absl::PrintF("  reconstruction error of the training set (radians per joint):\n");
  absl::PrintF("    dims   mean      max\n");
  for (const ReconstructionError& error : errors) {
    absl::PrintF("    %4d   %.6f  %.6f\n", error.dims, error.mean_rad, error.max_rad);
  }
}

absl::Status Build(const CommandLine& line) {
  // "--train A B --train C": the option repeats, and the files after its first value are
  // positionals.
  std::vector<std::string> specs = line.values("train");
  specs.insert(specs.end(), line.positionals().begin() + 1, line.positionals().end());
  if (specs.empty()) return absl::InvalidArgumentError("no --train files given");
  const std::optional<std::string> out = line.value("out");
  if (!out) return absl::InvalidArgumentError("no --out file given");
  MOTIONDB_ASSIGN_OR_RETURN(const SpaceOptions options, ParseOptions(line));
  std::vector<TrainingClip> training;
  for (const std::string& spec : specs) {
    MOTIONDB_ASSIGN_OR_RETURN(TrainingClip range, LoadTrainingRange(spec));
    training.push_back(std::move(range));
  }
  if (const std::optional<std::string> weights = line.value("weights");
      weights && !options.weights.overrides.empty()) {
    // Name the weights file when one of its joints is not in the training skeleton.
    MOTIONDB_RETURN_IF_ERROR(Prefixed(
        *weights, ComputeJointWeights(training.front().clip.skeleton(), options.weights).status()));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const MotionSpace space, MotionSpace::Build(training, options));
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<ReconstructionError> errors,
                            space.RepresentationalError(training));
  MOTIONDB_RETURN_IF_ERROR(WriteSpaceFile(*out, space));
  if (line.flag("json")) {
    std::cout << Report(*out, space, errors).dump() << "\n";
  } else {
    PrintText(*out, space, errors);
  }
  return absl::OkStatus();
}

}  // namespace

int RunSpace(const std::vector<std::string>& args) {
  if (args.empty() || args[0] != "build") return RunRemoteSpace(args);
  const absl::StatusOr<CommandLine> line =
      CommandLine::Parse(args, {"train", "out", "rate", "weights", "yaw-rate-weight", "metric"},
                         {"keep-heading", "json"});
  if (!line.ok()) {
    std::cerr << "motiondb space build: " << line.status().message() << "\n" << kUsage;
    return 2;
  }
  const absl::Status status = Build(*line);
  if (!status.ok()) {
    std::cerr << "motiondb space build: " << status.message() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace motiondb::cli
