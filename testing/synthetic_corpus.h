// A deterministic synthetic motion library for tests and benchmarks of the search engine, after
// the validation set of the thesis (6.3.1): a standing figure raises its right arm 15 times, its
// left arm 20 times, both arms 20 times, then shrugs 10 times and slouches 10 times, with rest
// between actions. Each instance varies its target pose, its posture and its timing, and the
// library records where every action lies, which is the ground truth a search should find.
//
// Motions are built in joint-rotation space (no physics): each action blends every joint it
// moves from the rest pose to a per-instance peak pose and back with a smooth ease, and a small
// deterministic idle sway (breathing, weight shift, head turn) runs underneath everything so that
// no two rest frames are identical.
//
// Memory: every clip is stored whole; 10 h at 120 fps is 4.3M frames x 84 doubles = 2.9 GB.
// All functions are pure and thread-safe.
#ifndef MOTIONDB_TESTING_SYNTHETIC_CORPUS_H_
#define MOTIONDB_TESTING_SYNTHETIC_CORPUS_H_

#include <cstdint>
#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/motion/clip.h"
#include "core/motion/skeleton.h"

namespace motiondb::testing {

enum class SyntheticAction { kRightArmRaise, kLeftArmRaise, kBothArmsRaise, kShrug, kSlouch };

// "right-arm-raise", "left-arm-raise", "both-arms-raise", "shrug", "slouch".
absl::string_view SyntheticActionName(SyntheticAction action);

// The action's length in seconds at timing scale 1, from the start of its movement to its end.
double SyntheticActionNominalDuration(SyntheticAction action);

// The humanoid every synthetic clip uses: 21 joints, offsets in centimetres, Y up, facing +Z,
// the figure's left on +X, arms hanging down in the offsets. Hips is the root with channels
// Xposition Yposition Zposition Zrotation Xrotation Yrotation; every other joint has
// Zrotation Xrotation Yrotation; Head, the wrists and the toes end in End Sites. Joint names:
// Hips, Spine, Chest, Neck, Head, {Left,Right}{Collar,Shoulder,Elbow,Wrist},
// {Left,Right}{Hip,Knee,Ankle,Toe}. The same instance on every call.
std::shared_ptr<const Skeleton> SyntheticSkeleton();

// `count` consecutive instances of `action`.
struct SyntheticScriptStep {
  SyntheticAction action;
  int count = 0;
};

// The thesis's validation script: 15 right-arm raises, 20 left-arm raises, 20 both-arms
// raises, 10 shrugs, 10 slouches (about 300 s with the default options).
std::vector<SyntheticScriptStep> ThesisSyntheticScript();

struct SyntheticCorpusOptions {
  // Seeds the std::mt19937_64 behind every random draw: equal options give bit-identical clips
  // (with the same build; std::sin and std::cos come from the platform's libm).
  uint64_t seed = 1;
  // Frame rate of every clip, in (0, 1000] frames per second.
  double fps = 50.0;
  // The actions in order; at least one action in all, each count in [0, 1000000].
  std::vector<SyntheticScriptStep> script = ThesisSyntheticScript();
  // 0 plays the script once. Otherwise the script is repeated, with fresh draws, until the
  // library lasts at least this many seconds (it stops between actions, possibly mid-script;
  // at most 100 h).
  double target_duration_s = 0.0;
  // The library is split into clips no longer than this (seconds), always between actions, so
  // it must hold at least one action with the longest rest on either side.
  double max_clip_duration_s = 600.0;
  // Each action is stretched as a whole by a factor drawn uniformly from [min, max] (> 0).
  double timing_scale_min = 0.7;
  double timing_scale_max = 1.5;
  // Side in metres of the cube from which each raised hand's target is drawn, in [0, 1]. There
  // is no inverse kinematics: the offset is mapped to shoulder and elbow angle jitter (a hand
  // offset d across a limb of length L is an angle of d / L; see the .cc).
  double target_jitter_m = 0.10;
  // Each arm raise leans the spine, chest and neck forward (+) or back (-) by an angle drawn
  // uniformly from +/- this many degrees, in [0, 45]: the thesis's random posture along the
  // Alberts axis from 0.25 to 0.75. The lean comes and goes with the action, so that every
  // rest is the same upright pose (the single rest cluster of the thesis's figure 6.2).
  double posture_lean_deg = 6.0;
  // The rest before every action (and after the last of each clip) lasts a uniform draw from
  // [min, max] seconds, and at least one frame. At most 3600 s.
  double rest_min_s = 0.5;
  double rest_max_s = 2.0;
  // Clips are rendered on this many threads, in [0, 1024]; 0 means
  // std::thread::hardware_concurrency(). The output does not depend on it.
  int threads = 0;
};

// One action's place in the library, at the clip's frame rate, inclusive.
struct SyntheticSegment {
  int clip = 0;  // index into SyntheticCorpus::clips
  SyntheticAction action = SyntheticAction::kRightArmRaise;
  int first_frame = 0;  // the first frame off the rest pose
  int last_frame = 0;   // the last frame before the rest pose is back
  // The frames holding the peak pose (the characteristic moment of the action, e.g. the arm at
  // its highest), inside [first_frame, last_frame].
  int peak_first_frame = 0;
  int peak_last_frame = 0;
  double timing_scale = 1.0;  // the drawn stretch of the action's nominal duration
};

struct SyntheticCorpus {
  std::vector<Clip> clips;  // all on SyntheticSkeleton(), each starting and ending at rest
  std::vector<SyntheticSegment> segments;  // in the order performed: by clip, then by frame
};

// Generates the library. INVALID_ARGUMENT names the offending option.
absl::StatusOr<SyntheticCorpus> GenerateSyntheticCorpus(const SyntheticCorpusOptions& options);

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTING_SYNTHETIC_CORPUS_H_
