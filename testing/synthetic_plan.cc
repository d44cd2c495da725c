#include "testing/internal/synthetic_plan.h"

#include <algorithm>
#include <cmath>

namespace motiondb::testing::synthetic {
namespace {

// At least 3 frames, so that rise, hold and fall each get one.
int ActionFrames(SyntheticAction action, double scale, double fps) {
  return std::max(3, static_cast<int>(std::lround(NominalPhases(action).total() * scale * fps)));
}

PlannedAction PlanAction(SyntheticAction action, const SyntheticCorpusOptions& options,
                         Random& random) {
  PlannedAction plan;
  plan.action = action;
  plan.rest_frames =
      RestFrames(random.Uniform(options.rest_min_s, options.rest_max_s), options.fps);
  plan.timing_scale = random.Uniform(options.timing_scale_min, options.timing_scale_max);
  plan.pose.lean = random.Uniform(-options.posture_lean_deg, options.posture_lean_deg) * kDeg;
  plan.pose.right_target = random.InCube(options.target_jitter_m);
  plan.pose.left_target = random.InCube(options.target_jitter_m);
  plan.pose.slouch_depth = random.Uniform(20.0, 35.0) * kDeg;

  // The whole action is stretched, then split into phases in their nominal proportions.
  const Phases phases = NominalPhases(action);
  const int n = ActionFrames(action, plan.timing_scale, options.fps);
  plan.rise_frames = std::max(1, static_cast<int>(std::lround(n * phases.rise / phases.total())));
  plan.fall_frames = std::max(1, static_cast<int>(std::lround(n * phases.fall / phases.total())));
  while (plan.rise_frames + plan.fall_frames > n - 1) {
    (plan.rise_frames >= plan.fall_frames ? plan.rise_frames : plan.fall_frames) -= 1;
  }
  plan.hold_frames = n - plan.rise_frames - plan.fall_frames;
  return plan;
}

}  // namespace

Phases NominalPhases(SyntheticAction action) {
  switch (action) {
    case SyntheticAction::kRightArmRaise:
    case SyntheticAction::kLeftArmRaise:
    case SyntheticAction::kBothArmsRaise:
      return {1.0, 0.6, 1.0};
    case SyntheticAction::kShrug:
      return {0.3, 0.25, 0.35};  // quick, as a shrug is
    case SyntheticAction::kSlouch:
      return {1.2, 1.0, 1.2};
  }
  return {1.0, 1.0, 1.0};
}

int RestFrames(double seconds, double fps) {
  return std::max(1, static_cast<int>(std::lround(seconds * fps)));
}

std::vector<PlannedAction> PlanLibrary(const SyntheticCorpusOptions& options, Random& random,
                                       int& final_rest_frames) {
  const int64_t target_frames =
      static_cast<int64_t>(std::ceil(options.target_duration_s * options.fps - 1e-9));
  std::vector<PlannedAction> plans;
  int64_t frames = 0;
  do {
    for (const SyntheticScriptStep& step : options.script) {
      for (int i = 0; i < step.count; ++i) {
        if (options.target_duration_s > 0.0 && frames >= target_frames) break;
        plans.push_back(PlanAction(step.action, options, random));
        frames += plans.back().rest_frames + plans.back().frames();
      }
    }
  } while (options.target_duration_s > 0.0 && frames < target_frames);
  final_rest_frames =
      RestFrames(random.Uniform(options.rest_min_s, options.rest_max_s), options.fps);
  return plans;
}

std::vector<ClipPlan> LayoutClips(const std::vector<PlannedAction>& plans, int final_rest_frames,
                                  int64_t max_frames) {
  std::vector<ClipPlan> clips;
  ClipPlan current;
  for (int k = 0; k < static_cast<int>(plans.size()); ++k) {
    const int unit = plans[k].rest_frames + plans[k].frames();
    const int after =
        k + 1 < static_cast<int>(plans.size()) ? plans[k + 1].rest_frames : final_rest_frames;
    if (current.end > current.first && int64_t{current.frames} + unit + after > max_frames) {
      current.trailing_rest_frames = plans[k].rest_frames;
      current.frames += current.trailing_rest_frames;
      clips.push_back(current);
      current = ClipPlan{.first = k, .end = k, .start_frame = current.start_frame + current.frames};
    }
    current.end = k + 1;
    current.frames += unit;
  }
  current.trailing_rest_frames = final_rest_frames;
  current.frames += final_rest_frames;
  clips.push_back(current);
  return clips;
}

std::vector<SyntheticSegment> Segments(const std::vector<PlannedAction>& plans,
                                       const std::vector<ClipPlan>& layout) {
  std::vector<SyntheticSegment> segments;
  segments.reserve(plans.size());
  for (int c = 0; c < static_cast<int>(layout.size()); ++c) {
    int frame = 0;
    for (int k = layout[c].first; k < layout[c].end; ++k) {
      const PlannedAction& plan = plans[k];
      frame += plan.rest_frames;
      segments.push_back({.clip = c,
                          .action = plan.action,
                          .first_frame = frame,
                          .last_frame = frame + plan.frames() - 1,
                          .peak_first_frame = frame + plan.rise_frames,
                          .peak_last_frame = frame + plan.rise_frames + plan.hold_frames - 1,
                          .timing_scale = plan.timing_scale});
      frame += plan.frames();
    }
  }
  return segments;
}

}  // namespace motiondb::testing::synthetic
