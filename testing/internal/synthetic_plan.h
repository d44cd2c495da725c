// The synthetic library's plan (testing/synthetic_corpus.h): every random draw, made in one
// sequence before anything is rendered, and the library's layout into clips, which together fix
// every frame and segment. Part of GenerateSyntheticCorpus.
#ifndef MOTIONDB_TESTING_INTERNAL_SYNTHETIC_PLAN_H_
#define MOTIONDB_TESTING_INTERNAL_SYNTHETIC_PLAN_H_

#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "testing/internal/synthetic_figure.h"
#include "testing/synthetic_corpus.h"

namespace motiondb::testing::synthetic {

// Nominal phases of each action in seconds: rising to the peak pose, holding it, returning.
struct Phases {
  double rise;
  double hold;
  double fall;
  double total() const { return rise + hold + fall; }
};

Phases NominalPhases(SyntheticAction action);

// Uniform draws mapped from the raw 64-bit output by hand: std::uniform_real_distribution's
// algorithm is implementation-defined, so it would break bit-identical output across standard
// libraries.
class Random {
 public:
  explicit Random(uint64_t seed) : engine_(seed) {}
  // [0, 1) with the 53 high bits.
  double Uniform01() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double Uniform(double low, double high) { return low + (high - low) * Uniform01(); }
  // A point of the cube of side `side` centred on the origin.
  Eigen::Vector3d InCube(double side) {
    const double x = Uniform(-0.5, 0.5), y = Uniform(-0.5, 0.5), z = Uniform(-0.5, 0.5);
    return side * Eigen::Vector3d(x, y, z);
  }

 private:
  std::mt19937_64 engine_;
};

// Everything drawn for one action. Every action draws the same values in the same order, so the
// stream never depends on which actions the script holds or how the library is split.
struct PlannedAction {
  SyntheticAction action;
  int rest_frames;  // the rest before the action
  int rise_frames;
  int hold_frames;
  int fall_frames;
  double timing_scale;
  PoseDraws pose;  // the variation of the peak pose
  int frames() const { return rise_frames + hold_frames + fall_frames; }
};

// A rest of `seconds`, at least one frame.
int RestFrames(double seconds, double fps);

// The run of actions [first, end) of the plan that one clip holds, and the rest that closes it.
struct ClipPlan {
  int first = 0;
  int end = 0;
  int trailing_rest_frames = 0;
  int frames = 0;
  int64_t start_frame = 0;  // frames of the library before this clip
};

// Draws every action of the library in order, then the closing rest.
std::vector<PlannedAction> PlanLibrary(const SyntheticCorpusOptions& options, Random& random,
                                       int& final_rest_frames);

// Packs the actions greedily into clips of at most `max_frames`. A clip closes with the rest
// that precedes the next action, and the next clip opens with that same rest, so the draws do
// not depend on where the library is cut.
std::vector<ClipPlan> LayoutClips(const std::vector<PlannedAction>& plans, int final_rest_frames,
                                  int64_t max_frames);

// Where each action lies, from the layout alone.
std::vector<SyntheticSegment> Segments(const std::vector<PlannedAction>& plans,
                                       const std::vector<ClipPlan>& layout);

}  // namespace motiondb::testing::synthetic

#endif  // MOTIONDB_TESTING_INTERNAL_SYNTHETIC_PLAN_H_
