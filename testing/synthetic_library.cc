#include "testing/synthetic_library.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Longest library (or single script pass) accepted: beyond this the clips alone would need tens
// of gigabytes, which is a mistake in the options rather than a benchmark.
constexpr double kMaxDurationS = 100.0 * 3600.0;
constexpr double kMaxFps = 1000.0;
constexpr int kMaxStepCount = 1'000'000;

// Joint indices of SyntheticSkeleton(), in its construction order.
enum JointIndex : int {
  kHips,
  kSpine,
  kChest,
  kNeck,
  kHead,
  kLeftCollar,
  kLeftShoulder,
  kLeftElbow,
  kLeftWrist,
  kRightCollar,
  kRightShoulder,
  kRightElbow,
  kRightWrist,
  kLeftHip,
  kLeftKnee,
  kLeftAnkle,
  kLeftToe,
  kRightHip,
  kRightKnee,
  kRightAnkle,
  kRightToe,
  kJointCount,
};

// Height of the hips above the floor (cm), so that the feet stand on y = 0: hip joint 4 below
// the pelvis, thigh 43, shin 42, ankle 8 above the floor.
constexpr double kHipHeight = 97.0;

// Limb lengths (m) that map a hand-target offset to joint angles: shoulder to wrist, and the
// forearm, matching the skeleton's offsets.
constexpr double kArmLength = 0.53;
constexpr double kForearmLength = 0.25;

// The figure's sides, as the sign of the X coordinate of that side's limbs.
constexpr int kLeft = 1;
constexpr int kRight = -1;

struct JointSpec {
  const char* name;
  int parent;
  Eigen::Vector3d offset;
  std::optional<Eigen::Vector3d> end_site;
};

Skeleton BuildSkeleton() {
  using V = Eigen::Vector3d;
  const std::array<JointSpec, kJointCount> specs = {{
      {"Hips", -1, V(0, 0, 0), std::nullopt},
      {"Spine", kHips, V(0, 10, -1), std::nullopt},
      {"Chest", kSpine, V(0, 18, 0), std::nullopt},
      {"Neck", kChest, V(0, 24, 1), std::nullopt},
      {"Head", kNeck, V(0, 9, 1), V(0, 17, 0)},
      {"LeftCollar", kChest, V(2, 20, 0), std::nullopt},
      {"LeftShoulder", kLeftCollar, V(16, -1, -1), std::nullopt},
      {"LeftElbow", kLeftShoulder, V(0, -28, 0), std::nullopt},
      {"LeftWrist", kLeftElbow, V(0, -25, 0), V(0, -18, 0)},
      {"RightCollar", kChest, V(-2, 20, 0), std::nullopt},
      {"RightShoulder", kRightCollar, V(-16, -1, -1), std::nullopt},
      {"RightElbow", kRightShoulder, V(0, -28, 0), std::nullopt},
      {"RightWrist", kRightElbow, V(0, -25, 0), V(0, -18, 0)},
      {"LeftHip", kHips, V(9, -4, 0), std::nullopt},
      {"LeftKnee", kLeftHip, V(0, -43, 0), std::nullopt},
      {"LeftAnkle", kLeftKnee, V(0, -42, 0), std::nullopt},
      {"LeftToe", kLeftAnkle, V(0, -6, 13), V(0, 0, 5)},
      {"RightHip", kHips, V(-9, -4, 0), std::nullopt},
      {"RightKnee", kRightHip, V(0, -43, 0), std::nullopt},
      {"RightAnkle", kRightKnee, V(0, -42, 0), std::nullopt},
      {"RightToe", kRightAnkle, V(0, -6, 13), V(0, 0, 5)},
  }};
  std::vector<Joint> joints(kJointCount);
  for (int j = 0; j < kJointCount; ++j) {
    joints[j].name = specs[j].name;
    joints[j].parent = specs[j].parent;
    joints[j].offset = specs[j].offset;
    joints[j].end_site = specs[j].end_site;
    joints[j].channels = {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation};
  }
  joints[kHips].channels.insert(joints[kHips].channels.begin(),
                                {Channel::kXposition, Channel::kYposition, Channel::kZposition});
  absl::StatusOr<Skeleton> skeleton = Skeleton::Create(std::move(joints));
  if (!skeleton.ok()) {
    // The table above is constant, so this is a programming error, not a runtime condition.
    std::fprintf(stderr, "SyntheticSkeleton: %s\n",
                 std::string(skeleton.status().message()).c_str());
    std::abort();
  }
  return *std::move(skeleton);
}

// A pose as rotation angles (radians) about X, Y and Z per joint, composed in the skeleton's ZXY
// order: q = q_Z * q_X * q_Y. With arms hanging along -Y and the figure facing +Z: +X flexes the
// spine forward, -X swings a hanging arm (or forearm) forward, and +Z rotation lifts the outer
// end of the left collar (-Z the right one).
using Pose = std::array<Eigen::Vector3d, kJointCount>;

Quat JointRotation(const Eigen::Vector3d& xyz) {
  return EulerToQuaternion(Eigen::Vector3d(xyz.z(), xyz.x(), xyz.y()), EulerOrder::kZXY);
}

// Relaxed standing: arms slightly out from the body with soft elbows, knees slightly bent (the
// thigh, shin and foot angles cancel so the feet stay flat).
Pose RestPose() {
  Pose pose;
  pose.fill(Eigen::Vector3d::Zero());
  for (int side : {kLeft, kRight}) {
    const bool left = side == kLeft;
    pose[left ? kLeftShoulder : kRightShoulder].z() = side * 5.0 * kDeg;
    pose[left ? kLeftElbow : kRightElbow].x() = -10.0 * kDeg;
    pose[left ? kLeftHip : kRightHip].x() = -2.0 * kDeg;
    pose[left ? kLeftKnee : kRightKnee].x() = 4.0 * kDeg;
    pose[left ? kLeftAnkle : kRightAnkle].x() = -2.0 * kDeg;
  }
  return pose;
}

// Nominal phases of each action in seconds: rising to the peak pose, holding it, returning.
struct Phases {
  double rise;
  double hold;
  double fall;
  double total() const { return rise + hold + fall; }
};

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
  double lean;                  // radians, + forward
  Eigen::Vector3d left_target;  // hand-target offsets in metres (x left, y up, z forward)
  Eigen::Vector3d right_target;
  double slouch_depth;  // radians, total over spine, chest and neck
  int frames() const { return rise_frames + hold_frames + fall_frames; }
};

int RestFrames(double seconds, double fps) {
  return std::max(1, static_cast<int>(std::lround(seconds * fps)));
}

// At least 3 frames, so that rise, hold and fall each get one.
int ActionFrames(SyntheticAction action, double scale, double fps) {
  return std::max(3, static_cast<int>(std::lround(NominalPhases(action).total() * scale * fps)));
}

PlannedAction PlanAction(SyntheticAction action, const SyntheticLibraryOptions& options,
                         Random& random) {
  PlannedAction plan;
  plan.action = action;
  plan.rest_frames =
      RestFrames(random.Uniform(options.rest_min_s, options.rest_max_s), options.fps);
  plan.timing_scale = random.Uniform(options.timing_scale_min, options.timing_scale_max);
  plan.lean = random.Uniform(-options.posture_lean_deg, options.posture_lean_deg) * kDeg;
  plan.right_target = random.InCube(options.target_jitter_m);
  plan.left_target = random.InCube(options.target_jitter_m);
  plan.slouch_depth = random.Uniform(20.0, 35.0) * kDeg;

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

// Raises the arm on `side` forward and up to a hand target displaced by `target` (m) from the
// nominal one: shoulder flexion 150 deg, 12 deg out to the side, elbow bent 25 deg, collar
// lifted 8 deg as the shoulder blade turns up. The cube offset is linearised about the nominal
// raised arm, direction u: its component along the flexion arc p moves the hand by flexion
// (angle = d / arm length), its sideways component by abduction (d / arm length), and its
// component along the arm changes the reach, which the elbow supplies (angle = d / forearm
// length; exact reach geometry is not the point, a bounded, uniform variation of the pose is).
void RaiseArm(int side, const Eigen::Vector3d& target, Pose& pose) {
  const double flexion = 150.0 * kDeg;
  const Eigen::Vector3d u(0.0, -std::cos(flexion), std::sin(flexion));
  const Eigen::Vector3d p(0.0, std::sin(flexion), std::cos(flexion));
  const double flex = flexion + target.dot(p) / kArmLength;
  const double abduction = 12.0 * kDeg + side * target.x() / kArmLength;
  const double elbow = std::max(0.0, 25.0 * kDeg - target.dot(u) / kForearmLength);
  const bool left = side == kLeft;
  // With the arm above the shoulder, -Z tilts the left arm out (+X) and +Z the right one.
  pose[left ? kLeftShoulder : kRightShoulder] = Eigen::Vector3d(-flex, 0.0, -side * abduction);
  pose[left ? kLeftElbow : kRightElbow].x() = -elbow;
  pose[left ? kLeftCollar : kRightCollar].z() += side * 8.0 * kDeg;
}

void Lean(double angle, double spine, double chest, double neck, Pose& pose) {
  pose[kSpine].x() += spine * angle;
  pose[kChest].x() += chest * angle;
  pose[kNeck].x() += neck * angle;
}

Pose PeakPose(const PlannedAction& plan, const Pose& rest) {
  Pose pose = rest;
  switch (plan.action) {
    case SyntheticAction::kRightArmRaise:
      RaiseArm(kRight, plan.right_target, pose);
      Lean(plan.lean, 0.5, 0.3, 0.2, pose);
      break;
    case SyntheticAction::kLeftArmRaise:
      RaiseArm(kLeft, plan.left_target, pose);
      Lean(plan.lean, 0.5, 0.3, 0.2, pose);
      break;
    case SyntheticAction::kBothArmsRaise:
      RaiseArm(kRight, plan.right_target, pose);
      RaiseArm(kLeft, plan.left_target, pose);
      Lean(plan.lean, 0.5, 0.3, 0.2, pose);
      break;
    case SyntheticAction::kShrug:
      // The thesis's shrugs are identical but for speed: no drawn values. The collars lift 20 deg
      // and the shoulders turn back by as much, so the arms still hang straight down.
      for (int side : {kLeft, kRight}) {
        pose[side == kLeft ? kLeftCollar : kRightCollar].z() += side * 20.0 * kDeg;
        pose[side == kLeft ? kLeftShoulder : kRightShoulder].z() -= side * 20.0 * kDeg;
      }
      break;
    case SyntheticAction::kSlouch:
      // The slouch is itself a posture change: its depth varies instead of a lean. The head
      // lifts back a little to keep looking ahead; the collars roll the shoulders forward.
      Lean(plan.slouch_depth, 0.4, 0.35, 0.25, pose);
      pose[kHead].x() -= 0.3 * plan.slouch_depth;
      pose[kLeftCollar].y() -= kLeft * 0.3 * plan.slouch_depth;
      pose[kRightCollar].y() -= kRight * 0.3 * plan.slouch_depth;
      break;
  }
  return pose;
}

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

struct SwayPhases {
  double breath = 0.0;
  double shift = 0.0;
  double turn = 0.0;
};

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

// The run of actions [first, end) of the plan that one clip holds, and the rest that closes it.
struct ClipPlan {
  int first = 0;
  int end = 0;
  int trailing_rest_frames = 0;
  int frames = 0;
  int64_t start_frame = 0;  // frames of the library before this clip
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
    const Pose peak_pose = PeakPose(plan, rest_.pose);
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

absl::Status ValidateOptions(const SyntheticLibraryOptions& options) {
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

// Draws every action of the library in order, then the closing rest.
std::vector<PlannedAction> PlanLibrary(const SyntheticLibraryOptions& options, Random& random,
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

// Packs the actions greedily into clips of at most `max_frames`. A clip closes with the rest
// that precedes the next action, and the next clip opens with that same rest, so the draws do
// not depend on where the library is cut.
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

// Where each action lies, from the layout alone.
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
  return NominalPhases(action).total();
}

std::shared_ptr<const Skeleton> SyntheticSkeleton() {
  static const std::shared_ptr<const Skeleton> skeleton =
      std::make_shared<const Skeleton>(BuildSkeleton());
  return skeleton;
}

std::vector<SyntheticScriptStep> ThesisSyntheticScript() {
  return {{SyntheticAction::kRightArmRaise, 15},
          {SyntheticAction::kLeftArmRaise, 20},
          {SyntheticAction::kBothArmsRaise, 20},
          {SyntheticAction::kShrug, 10},
          {SyntheticAction::kSlouch, 10}};
}

absl::StatusOr<SyntheticLibrary> GenerateSyntheticLibrary(const SyntheticLibraryOptions& options) {
  MOTIONDB_RETURN_IF_ERROR(ValidateOptions(options));
  // Every draw happens here, in one sequence, before any rendering: the clips then depend only
  // on the plan, whatever the thread count.
  Random random(options.seed);
  SwayPhases sway;
  sway.breath = random.Uniform(0.0, kTwoPi);
  sway.shift = random.Uniform(0.0, kTwoPi);
  sway.turn = random.Uniform(0.0, kTwoPi);
  int final_rest_frames = 0;
  const std::vector<PlannedAction> plans = PlanLibrary(options, random, final_rest_frames);
  const std::vector<ClipPlan> layout = LayoutClips(
      plans, final_rest_frames,
      static_cast<int64_t>(std::floor(options.max_clip_duration_s * options.fps + 1e-9)));

  const int clip_count = static_cast<int>(layout.size());
  const RestData rest;
  SyntheticSkeleton();  // built before the threads start (a function-local static is safe anyway)
  std::vector<absl::StatusOr<Clip>> rendered(clip_count, absl::UnknownError("not rendered"));
  std::atomic<int> next_clip{0};
  const auto work = [&] {
    for (int c = next_clip++; c < clip_count; c = next_clip++) {
      rendered[c] = RenderClip(rest, sway, options.fps, plans, layout[c]);
    }
  };
  const int threads = std::min(
      clip_count, options.threads > 0
                      ? options.threads
                      : std::max(1, static_cast<int>(std::thread::hardware_concurrency())));
  std::vector<std::thread> workers;
  for (int t = 1; t < threads; ++t) workers.emplace_back(work);
  work();
  for (std::thread& worker : workers) worker.join();

  SyntheticLibrary library;
  library.clips.reserve(clip_count);
  for (absl::StatusOr<Clip>& clip : rendered) {
    if (!clip.ok()) return std::move(clip).status();
    library.clips.push_back(*std::move(clip));
  }
  library.segments = Segments(plans, layout);
  return library;
}

}  // namespace motiondb
