#include "testing/synthetic_corpus.h"

#include <algorithm>
#include <cmath>
#include <thread>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "testing/internal/synthetic_plan.h"
#include "testing/internal/synthetic_render.h"
#include "util/status_macros.h"

// The library is built in three parts: the figure and its poses (synthetic_figure.h), the plan
// of every draw and the clips' layout (synthetic_plan.h), and the rendering of the frames
// (synthetic_render.h).

namespace motiondb::testing {
namespace {

using synthetic::ClipPlan;
using synthetic::PlannedAction;
using synthetic::RestFrames;

// Longest library (or single script pass) accepted: beyond this the clips alone would need tens
// of gigabytes, which is a mistake in the options rather than a benchmark.
constexpr double kMaxDurationS = 100.0 * 3600.0;
constexpr double kMaxFps = 1000.0;
constexpr int kMaxStepCount = 1'000'000;

absl::Status CheckFinite(absl::string_view name, double value) {
  if (!std::isfinite(value)) {
    return absl::InvalidArgumentError(absl::StrCat(name, " must be finite, got ", value));
  }
  return absl::OkStatus();
}

absl::Status CheckRange(absl::string_view name, double value, double low, double high) {
  MOTIONDB_RETURN_IF_ERROR(CheckFinite(name, value));
  if (value < low || value > high) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, " must be in [", low, ", ", high, "], got ", value));
  }
  return absl::OkStatus();
}

absl::Status CheckOrdered(absl::string_view low_name, double low, absl::string_view high_name,
                          double high) {
  if (low > high) {
    return absl::InvalidArgumentError(
        absl::StrCat(low_name, " (", low, ") exceeds ", high_name, " (", high, ")"));
  }
  return absl::OkStatus();
}

absl::Status ValidateOptions(const SyntheticCorpusOptions& options) {
  MOTIONDB_RETURN_IF_ERROR(CheckFinite("fps", options.fps));
  if (options.fps <= 0.0 || options.fps > kMaxFps) {
    return absl::InvalidArgumentError(
        absl::StrCat("fps must be in (0, ", kMaxFps, "], got ", options.fps));
  }
  MOTIONDB_RETURN_IF_ERROR(CheckFinite("timing_scale_min", options.timing_scale_min));
  MOTIONDB_RETURN_IF_ERROR(CheckRange("timing_scale_max", options.timing_scale_max, 0.0, 10.0));
  if (options.timing_scale_min <= 0.0) {
    return absl::InvalidArgumentError(
        absl::StrCat("timing_scale_min must be positive, got ", options.timing_scale_min));
  }
  MOTIONDB_RETURN_IF_ERROR(CheckOrdered("timing_scale_min", options.timing_scale_min,
                                        "timing_scale_max", options.timing_scale_max));
  MOTIONDB_RETURN_IF_ERROR(CheckRange("target_jitter_m", options.target_jitter_m, 0.0, 1.0));
  MOTIONDB_RETURN_IF_ERROR(CheckRange("posture_lean_deg", options.posture_lean_deg, 0.0, 45.0));
  MOTIONDB_RETURN_IF_ERROR(CheckRange("rest_min_s", options.rest_min_s, 0.0, 3600.0));
  MOTIONDB_RETURN_IF_ERROR(CheckRange("rest_max_s", options.rest_max_s, 0.0, 3600.0));
  MOTIONDB_RETURN_IF_ERROR(
      CheckOrdered("rest_min_s", options.rest_min_s, "rest_max_s", options.rest_max_s));
  MOTIONDB_RETURN_IF_ERROR(
      CheckRange("target_duration_s", options.target_duration_s, 0.0, kMaxDurationS));
  MOTIONDB_RETURN_IF_ERROR(
      CheckRange("max_clip_duration_s", options.max_clip_duration_s, 0.0, kMaxDurationS));
  if (options.threads < 0 || options.threads > 1024) {
    return absl::InvalidArgumentError(
        absl::StrCat("threads must be in [0, 1024], got ", options.threads));
  }

  int64_t actions = 0;
  double longest_action_s = 0.0;
  double pass_upper_bound_s = options.rest_max_s;
  for (const SyntheticScriptStep& step : options.script) {
    if (step.count < 0 || step.count > kMaxStepCount) {
      return absl::InvalidArgumentError(
          absl::StrCat("script step ", SyntheticActionName(step.action), " count ", step.count,
                       " is outside [0, ", kMaxStepCount, "]"));
    }
    if (step.count == 0) continue;
    actions += step.count;
    const double action_s = SyntheticActionNominalDuration(step.action) * options.timing_scale_max;
    longest_action_s = std::max(longest_action_s, action_s);
    pass_upper_bound_s += step.count * (options.rest_max_s + action_s);
  }
  if (actions == 0) return absl::InvalidArgumentError("the script holds no action");
  if (options.target_duration_s == 0.0 && pass_upper_bound_s > kMaxDurationS) {
    return absl::InvalidArgumentError(absl::StrCat("one pass of the script may last up to ",
                                                   pass_upper_bound_s, " s, over the limit of ",
                                                   kMaxDurationS, " s"));
  }
  // Clips are cut only between actions, so the longest action with the longest rest on either
  // side must fit in one clip. Compared in frames, as the layout is.
  const int64_t max_clip_frames =
      static_cast<int64_t>(std::floor(options.max_clip_duration_s * options.fps + 1e-9));
  const int64_t unit_frames = 2 * int64_t{RestFrames(options.rest_max_s, options.fps)} +
                              std::max<int64_t>(3, std::llround(longest_action_s * options.fps));
  if (unit_frames > max_clip_frames) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_clip_duration_s (", options.max_clip_duration_s,
                     ") cannot hold the longest action with the longest rest on either side (",
                     unit_frames / options.fps, " s)"));
  }
  return absl::OkStatus();
}

}  // namespace

absl::string_view SyntheticActionName(SyntheticAction action) {
  switch (action) {
    case SyntheticAction::kRightArmRaise:
      return "right-arm-raise";
    case SyntheticAction::kLeftArmRaise:
      return "left-arm-raise";
    case SyntheticAction::kBothArmsRaise:
      return "both-arms-raise";
    case SyntheticAction::kShrug:
      return "shrug";
    case SyntheticAction::kSlouch:
      return "slouch";
  }
  return "?";
}

double SyntheticActionNominalDuration(SyntheticAction action) {
  return synthetic::NominalPhases(action).total();
}

std::vector<SyntheticScriptStep> ThesisSyntheticScript() {
  return {{SyntheticAction::kRightArmRaise, 15},
          {SyntheticAction::kLeftArmRaise, 20},
          {SyntheticAction::kBothArmsRaise, 20},
          {SyntheticAction::kShrug, 10},
          {SyntheticAction::kSlouch, 10}};
}

absl::StatusOr<SyntheticCorpus> GenerateSyntheticCorpus(const SyntheticCorpusOptions& options) {
  MOTIONDB_RETURN_IF_ERROR(ValidateOptions(options));
  // Every draw happens here, in one sequence, before any rendering: the clips then depend only
  // on the plan, whatever the thread count.
  synthetic::Random random(options.seed);
  const synthetic::SwayPhases sway = synthetic::DrawSwayPhases(random);
  int final_rest_frames = 0;
  const std::vector<PlannedAction> plans =
      synthetic::PlanLibrary(options, random, final_rest_frames);
  const std::vector<ClipPlan> layout = synthetic::LayoutClips(
      plans, final_rest_frames,
      static_cast<int64_t>(std::floor(options.max_clip_duration_s * options.fps + 1e-9)));

  const int threads = options.threads > 0
                          ? options.threads
                          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  SyntheticCorpus library;
  MOTIONDB_ASSIGN_OR_RETURN(library.clips,
                            synthetic::RenderClips(sway, options.fps, plans, layout, threads));
  library.segments = synthetic::Segments(plans, layout);
  return library;
}

}  // namespace motiondb::testing
