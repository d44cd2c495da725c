// motiondb space build --train FILE[:FROM-TO]... --out SPACE.mcs [--rate 30]
//     [--weights mass|uniform|FILE.json] [--yaw-rate-weight W] [--metric unit|eigen]
//     [--keep-heading] [--json]: a space file built offline.
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/commands.h"
#include "client/space_flags.h"
#include "core/bvh/bvh_reader.h"
#include "core/space/heading.h"
#include "core/space/motion_space.h"
#include "core/space/space_serialization.h"
#include "util/file_io.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::cli {
namespace {

struct BuildFlags {
  std::vector<std::string> train;
  std::string out;
  SpaceFlags space;
};

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
  if (IsWeightPreset(weights)) {
    MOTIONDB_ASSIGN_OR_RETURN(options->weights.preset, ParseWeightPreset(weights));
    return absl::OkStatus();
  }
  MOTIONDB_ASSIGN_OR_RETURN(const std::string text, ReadFileBytes(weights, kMaxWeightsFileBytes));
  MOTIONDB_ASSIGN_OR_RETURN(options->weights.overrides,
                            Prefixed(weights, ParseWeightOverrides(text)));
  return absl::OkStatus();
}

absl::StatusOr<SpaceOptions> ParseOptions(const SpaceFlags& flags) {
  SpaceOptions options;
  options.sample_rate = flags.rate.value_or(options.sample_rate);
  options.yaw_rate_weight = flags.yaw_rate_weight.value_or(options.yaw_rate_weight);
  options.pose.remove_heading = !flags.keep_heading;
  if (flags.root_velocity_weight) {
    options.pose.root_velocity = *flags.root_velocity_weight != 0;
    if (options.pose.root_velocity) options.root_velocity_weight = *flags.root_velocity_weight;
  }
  MOTIONDB_RETURN_IF_ERROR(ApplyWeights(flags.weights, &options));
  if (flags.metric == "eigen") options.metric = SpaceMetric::kEigenvalueScaled;
  return options;
}

nlohmann::json SpaceFileReport(const std::string& out, const MotionSpace& space,
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
      {"root_velocity_weight", data.root_velocity_weight},
      {"metric", data.metric == SpaceMetric::kUnit ? "unit" : "eigen"},
      {"training_ranges", data.training.size()},
      {"joint_weights", std::move(weights)},
      {"explained_variance", std::vector<double>(explained.begin(), explained.end())},
      {"reconstruction_error", std::move(reconstruction)},
  };
}

void PrintSpaceSummary(const std::string& out, const MotionSpace& space,
                       const std::vector<ReconstructionError>& errors) {
  const SpaceData& data = space.data();
  absl::PrintF("wrote %s\n", out);
  absl::PrintF("  skeleton: %d joints, pelvis %s\n", space.skeleton().joint_count(),
               space.skeleton().joint(FindPelvis(space.skeleton())).name);
  absl::PrintF("  training: %d ranges at %g Hz, heading %s\n", data.training.size(),
               space.sample_rate(),
               data.pose.remove_heading
                   ? absl::StrFormat("removed (yaw-rate weight %g, root-velocity weight %g)",
                                     data.yaw_rate_weight, data.root_velocity_weight)
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

absl::Status Build(const BuildFlags& flags, bool json) {
  MOTIONDB_ASSIGN_OR_RETURN(const SpaceOptions options, ParseOptions(flags.space));
  std::vector<TrainingClip> training;
  for (const std::string& spec : flags.train) {
    MOTIONDB_ASSIGN_OR_RETURN(TrainingClip range, LoadTrainingRange(spec));
    training.push_back(std::move(range));
  }
  if (!options.weights.overrides.empty()) {
    // Name the weights file when one of its joints is not in the training skeleton.
    MOTIONDB_RETURN_IF_ERROR(
        Prefixed(flags.space.weights,
                 ComputeJointWeights(training.front().clip.skeleton(), options.weights).status()));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const MotionSpace space, MotionSpace::Build(training, options));
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<ReconstructionError> errors,
                            space.RepresentationalError(training));
  MOTIONDB_RETURN_IF_ERROR(WriteSpaceFile(flags.out, space));
  if (json) {
    std::cout << SpaceFileReport(flags.out, space, errors).dump() << "\n";
  } else {
    PrintSpaceSummary(flags.out, space, errors);
  }
  return absl::OkStatus();
}

}  // namespace

void AddSpaceBuild(Commands& commands, CLI::App* space) {
  auto flags = std::make_shared<BuildFlags>();
  const GlobalOptions& global = commands.global();
  CLI::App* build =
      commands.AddOffline(space, "build", "build a Motion Curve space file from BVH files",
                          /*json=*/true, [flags, &global] { return Build(*flags, global.json); });
  build->add_option("--train", flags->train, "BVH files to learn from, or frames FROM..TO of them")
      ->type_name("FILE[:FROM-TO]...")
      ->required();
  build->add_option("--out", flags->out, "the space file to write")
      ->type_name("SPACE.mcs")
      ->required();
  AddSpaceFlags(build, &flags->space);
}

}  // namespace motiondb::cli
