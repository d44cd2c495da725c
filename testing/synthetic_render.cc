#include "testing/internal/synthetic_render.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <numbers>
#include <thread>
#include <utility>

#include "absl/status/status.h"

namespace motiondb::testing::synthetic {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Quintic smootherstep: zero velocity and acceleration at both ends, so actions start and stop
// without a jolt.
double Ease(double u) { return u * u * u * (u * (6.0 * u - 15.0) + 10.0); }

// Idle sway under everything, as a person standing still never is: breathing in the chest, a
// slow weight shift of the hips (rotation and sideways translation), a drifting head turn.
// Incommensurate frequencies and seeded phases keep rest frames from repeating. The sway runs on
// the library's clock, as if recording never stopped between clips.
constexpr double kBreathHz = 0.25, kBreathAmplitude = 0.8 * kDeg;
constexpr double kShiftHz = 0.07, kShiftAmplitude = 0.6 * kDeg, kShiftCm = 1.0;
constexpr double kTurnHz = 0.11, kTurnAmplitude = 1.5 * kDeg;

// sin(2 pi hz t + phase) sampled frame by frame by rotating a phasor: no trigonometry per frame.
// Rounding drifts the amplitude by about 1e-16 per frame, under 1e-7 over the longest clip.
class Oscillator {
 public:
  Oscillator(double hz, double phase, double fps, int64_t start_frame) {
    const double step = kTwoPi * hz / fps;
    step_cos_ = std::cos(step);
    step_sin_ = std::sin(step);
    const double start = std::fmod(step * static_cast<double>(start_frame), kTwoPi) + phase;
    cos_ = std::cos(start);
    sin_ = std::sin(start);
  }
  double value() const { return sin_; }
  void Advance() {
    const double c = cos_ * step_cos_ - sin_ * step_sin_;
    sin_ = sin_ * step_cos_ + cos_ * step_sin_;
    cos_ = c;
  }

 private:
  double step_cos_, step_sin_, cos_, sin_;
};

// q <- q * (rotation by `angle` about `axis`), on a stored w, x, y, z quaternion, for the sway's
// small angles: the half-angle cosine and sine from their Taylor series, exact to double
// precision below 0.05 rad (the sway stays under 0.03).
void RotateLocalSmall(double* q, int axis, double angle) {
  const double h = 0.5 * angle, h2 = h * h;
  Quat r(1.0 - h2 / 2.0 * (1.0 - h2 / 12.0 * (1.0 - h2 / 30.0)), 0.0, 0.0, 0.0);
  r.vec()[axis] = h * (1.0 - h2 / 6.0 * (1.0 - h2 / 20.0 * (1.0 - h2 / 42.0)));
  const Quat out = Quat(q[0], q[1], q[2], q[3]) * r;
  q[0] = out.w();
  q[1] = out.x();
  q[2] = out.y();
  q[3] = out.z();
}

Eigen::Vector4d Wxyz(const Quat& q) { return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()); }

// The rest pose in the forms rendering needs; computed once, shared read-only by the threads.
struct RestData {
  Pose pose = RestPose();
  std::array<Eigen::Vector4d, kJointCount> quats;
  std::array<double, 4 * kJointCount> row;
  RestData() {
    for (int j = 0; j < kJointCount; ++j) {
      quats[j] = Wxyz(JointRotation(pose[j]));
      std::copy_n(quats[j].data(), 4, row.data() + 4 * j);
    }
  }
};

// A joint an action moves, with its rest and peak rotations (peak on the rest's hemisphere so
// that the blend takes the shorter arc).
struct MovingJoint {
  int joint;
  Eigen::Vector4d rest;  // w, x, y, z
  Eigen::Vector4d peak;
};

// Renders one clip front to back, straight into its preallocated blocks: nothing is allocated
// per frame.
class ClipRenderer {
 public:
  ClipRenderer(const RestData& rest, const SwayPhases& sway, double fps, const ClipPlan& plan)
      : rest_(rest),
        rotations_(plan.frames, 4 * kJointCount),
        positions_(plan.frames, 3),
        breath_(kBreathHz, sway.breath, fps, plan.start_frame),
        shift_(kShiftHz, sway.shift, fps, plan.start_frame),
        turn_(kTurnHz, sway.turn, fps, plan.start_frame) {}

  void Rest(int frames) {
    for (int i = 0; i < frames; ++i) NextFrame();
  }

  void Action(const PlannedAction& plan) {
    const Pose peak_pose = PeakPose(plan.action, plan.pose, rest_.pose);
    // Only the joints the action moves are blended; the rest row covers the others.
    std::array<MovingJoint, kJointCount> moving;
    int moving_count = 0;
    for (int j = 0; j < kJointCount; ++j) {
      if (peak_pose[j] == rest_.pose[j]) continue;
      Eigen::Vector4d peak = Wxyz(JointRotation(peak_pose[j]));
      if (peak.dot(rest_.quats[j]) < 0.0) peak = -peak;
      moving[moving_count++] = {j, rest_.quats[j], peak};
    }
    const int hold_start = plan.rise_frames, fall_start = plan.rise_frames + plan.hold_frames;
    for (int i = 0; i < plan.frames(); ++i) {
      // Sampled at frame centres, so the first and last frames are already off the rest pose
      // (the weight is 0 only at rest) and the hold is exactly the peak.
      double weight = 1.0;
      if (i < hold_start) {
        weight = Ease((i + 0.5) / plan.rise_frames);
      } else if (i >= fall_start) {
        weight = Ease(1.0 - (i - fall_start + 0.5) / plan.fall_frames);
      }
      double* row = NextFrame();
      // Normalised linear blend: the same great arc as slerp, without its trigonometry; the
      // ease already shapes the speed.
      for (int m = 0; m < moving_count; ++m) {
        double* q = row + 4 * moving[m].joint;
        const Eigen::Vector4d blend = (1.0 - weight) * moving[m].rest + weight * moving[m].peak;
        Eigen::Map<Eigen::Vector4d> out(q);
        out = blend / blend.norm();
        ReapplySway(moving[m].joint, q);  // the blend overwrote the sway of the rest row
      }
    }
  }

  absl::StatusOr<Clip> Finish(std::shared_ptr<const Skeleton> skeleton, double fps) && {
    return Clip::Create(std::move(skeleton), 1.0 / fps, std::move(rotations_),
                        std::move(positions_));
  }

 private:
  // Writes the next frame as the rest pose with this frame's sway, and returns its row.
  double* NextFrame() {
    double* row = rotations_.data() + Eigen::Index{frame_} * 4 * kJointCount;
    std::copy_n(rest_.row.data(), 4 * kJointCount, row);
    breath_angle_ = kBreathAmplitude * breath_.value();
    shift_angle_ = kShiftAmplitude * shift_.value();
    turn_angle_ = kTurnAmplitude * turn_.value();
    RotateLocalSmall(row + 4 * kChest, 0, breath_angle_);
    RotateLocalSmall(row + 4 * kHips, 2, shift_angle_);
    RotateLocalSmall(row + 4 * kNeck, 1, turn_angle_);
    double* position = positions_.data() + Eigen::Index{frame_} * 3;
    position[0] = kShiftCm * shift_.value();
    position[1] = kHipHeight;
    position[2] = 0.0;
    breath_.Advance();
    shift_.Advance();
    turn_.Advance();
    ++frame_;
    return row;
  }

  // The sway of the current frame on `joint`'s rotation, for the chest, hips and neck.
  void ReapplySway(int joint, double* q) const {
    if (joint == kChest) RotateLocalSmall(q, 0, breath_angle_);
    if (joint == kHips) RotateLocalSmall(q, 2, shift_angle_);
    if (joint == kNeck) RotateLocalSmall(q, 1, turn_angle_);
  }

  const RestData& rest_;
  RowMatrixXd rotations_;
  RowMatrixXd positions_;
  Oscillator breath_, shift_, turn_;
  double breath_angle_ = 0.0, shift_angle_ = 0.0, turn_angle_ = 0.0;  // of the last frame
  int frame_ = 0;
};

absl::StatusOr<Clip> RenderClip(const RestData& rest, const SwayPhases& sway, double fps,
                                const std::vector<PlannedAction>& plans, const ClipPlan& clip) {
  ClipRenderer renderer(rest, sway, fps, clip);
  for (int k = clip.first; k < clip.end; ++k) {
    renderer.Rest(plans[k].rest_frames);
    renderer.Action(plans[k]);
  }
  renderer.Rest(clip.trailing_rest_frames);
  return std::move(renderer).Finish(SyntheticSkeleton(), fps);
}

}  // namespace

SwayPhases DrawSwayPhases(Random& random) {
  SwayPhases sway;
  sway.breath = random.Uniform(0.0, kTwoPi);
  sway.shift = random.Uniform(0.0, kTwoPi);
  sway.turn = random.Uniform(0.0, kTwoPi);
  return sway;
}

absl::StatusOr<std::vector<Clip>> RenderClips(const SwayPhases& sway, double fps,
                                              const std::vector<PlannedAction>& plans,
                                              const std::vector<ClipPlan>& layout, int threads) {
  const int clip_count = static_cast<int>(layout.size());
  const RestData rest;
  SyntheticSkeleton();  // built before the threads start (a function-local static is safe anyway)
  std::vector<absl::StatusOr<Clip>> rendered(clip_count, absl::UnknownError("not rendered"));
  std::atomic<int> next_clip{0};
  const auto work = [&] {
    for (int c = next_clip++; c < clip_count; c = next_clip++) {
      rendered[c] = RenderClip(rest, sway, fps, plans, layout[c]);
    }
  };
  std::vector<std::thread> workers;
  for (int t = 1; t < std::min(clip_count, threads); ++t) workers.emplace_back(work);
  work();
  for (std::thread& worker : workers) worker.join();

  std::vector<Clip> clips;
  clips.reserve(clip_count);
  for (absl::StatusOr<Clip>& clip : rendered) {
    if (!clip.ok()) return std::move(clip).status();
    clips.push_back(*std::move(clip));
  }
  return clips;
}

}  // namespace motiondb::testing::synthetic
