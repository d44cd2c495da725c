#include "testing/synthetic_corpus.h"

#include <algorithm>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using testing::GenerateSyntheticCorpus;
using testing::SyntheticAction;
using testing::SyntheticActionName;
using testing::SyntheticActionNominalDuration;
using testing::SyntheticCorpus;
using testing::SyntheticCorpusOptions;
using testing::SyntheticScriptStep;
using testing::SyntheticSegment;
using testing::SyntheticSkeleton;
using testing::ThesisSyntheticScript;

constexpr double kDeg = std::numbers::pi / 180.0;

SyntheticCorpus Generate(const SyntheticCorpusOptions& options) {
  absl::StatusOr<SyntheticCorpus> library = GenerateSyntheticCorpus(options);
  EXPECT_TRUE(library.ok()) << library.status();
  return library.ok() ? *std::move(library) : SyntheticCorpus{};
}

// The default library, generated once: several tests read it.
const SyntheticCorpus& DefaultLibrary() {
  static const SyntheticCorpus* const library = new SyntheticCorpus(Generate({}));
  return *library;
}

// The thesis script, one action per entry.
std::vector<SyntheticAction> ThesisActions() {
  std::vector<SyntheticAction> actions;
  for (const SyntheticScriptStep& step : ThesisSyntheticScript()) {
    actions.insert(actions.end(), step.count, step.action);
  }
  return actions;
}

int Joint(absl::string_view name) {
  const int index = SyntheticSkeleton()->FindJoint(name);
  EXPECT_GE(index, 0) << name;
  return index;
}

// The largest rotation of `joint` during the segment away from its pose on the rest frame just
// before it.
double MaxAngleFromRest(const SyntheticCorpus& library, const SyntheticSegment& segment,
                        int joint) {
  const Clip& clip = library.clips[segment.clip];
  const Quat rest = clip.rotation(segment.first_frame - 1, joint);
  double angle = 0.0;
  for (int f = segment.first_frame; f <= segment.last_frame; ++f) {
    angle = std::max(angle, AngleBetween(clip.rotation(f, joint), rest));
  }
  return angle;
}

// Forward kinematics: every joint's position in the world (cm) on `frame`.
std::vector<Eigen::Vector3d> WorldPositions(const Clip& clip, int frame) {
  const Skeleton& skeleton = clip.skeleton();
  std::vector<Quat> orientation(skeleton.joint_count());
  std::vector<Eigen::Vector3d> position(skeleton.joint_count());
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    const int parent = skeleton.joint(j).parent;
    if (parent < 0) {
      position[j] = clip.root_position(frame);
      orientation[j] = clip.rotation(frame, j);
    } else {
      position[j] = position[parent] + orientation[parent] * skeleton.joint(j).offset;
      orientation[j] = orientation[parent] * clip.rotation(frame, j);
    }
  }
  return position;
}

TEST(SyntheticSkeleton, IsAHumanoidWithBvhChannels) {
  const std::shared_ptr<const Skeleton> skeleton = SyntheticSkeleton();
  EXPECT_EQ(skeleton, SyntheticSkeleton());
  EXPECT_GE(skeleton->joint_count(), 18);
  EXPECT_LE(skeleton->joint_count(), 24);
  EXPECT_EQ(skeleton->joint(0).name, "Hips");
  EXPECT_EQ(skeleton->joint(0).channels,
            (std::vector<Channel>{Channel::kXposition, Channel::kYposition, Channel::kZposition,
                                  Channel::kZrotation, Channel::kXrotation, Channel::kYrotation}));
  for (int j = 1; j < skeleton->joint_count(); ++j) {
    EXPECT_EQ(skeleton->joint(j).channels,
              (std::vector<Channel>{Channel::kZrotation, Channel::kXrotation, Channel::kYrotation}))
        << skeleton->joint(j).name;
    EXPECT_EQ(skeleton->Children(j).empty(), skeleton->joint(j).end_site.has_value())
        << skeleton->joint(j).name;
  }
  for (const char* name :
       {"Spine",        "Chest",      "Neck",      "Head",        "LeftCollar",
        "LeftShoulder", "LeftElbow",  "LeftWrist", "RightCollar", "RightShoulder",
        "RightElbow",   "RightWrist", "LeftHip",   "LeftKnee",    "LeftAnkle",
        "LeftToe",      "RightHip",   "RightKnee", "RightAnkle",  "RightToe"}) {
    EXPECT_GE(skeleton->FindJoint(name), 0) << name;
  }

  // Standing at rest: Y up, the head about 1.6 m up, feet on the floor, left on +X.
  const Clip& clip = DefaultLibrary().clips.at(0);
  const std::vector<Eigen::Vector3d> p = WorldPositions(clip, 0);
  EXPECT_NEAR(p[Joint("Head")].y(), 160.0, 15.0);
  EXPECT_NEAR(p[Joint("LeftAnkle")].y(), 8.0, 4.0);
  EXPECT_GT(p[Joint("LeftWrist")].x(), 10.0);
  EXPECT_LT(p[Joint("RightWrist")].x(), -10.0);
  EXPECT_LT(p[Joint("RightWrist")].y(), p[Joint("RightShoulder")].y() - 40.0);  // arms hang
}

TEST(SyntheticCorpus, DefaultScriptIsTheThesisValidationSet) {
  const SyntheticCorpus& library = DefaultLibrary();
  ASSERT_EQ(library.clips.size(), 1u);  // about 300 s, under the 600 s clip limit
  const Clip& clip = library.clips[0];
  EXPECT_DOUBLE_EQ(clip.fps(), 50.0);
  EXPECT_EQ(clip.shared_skeleton(), SyntheticSkeleton());
  EXPECT_GT(clip.duration_s(), 250.0);
  EXPECT_LT(clip.duration_s(), 350.0);

  std::vector<SyntheticAction> actions;
  for (const SyntheticSegment& segment : library.segments) actions.push_back(segment.action);
  EXPECT_EQ(actions, ThesisActions());
  ASSERT_EQ(actions.size(), 75u);
  EXPECT_EQ(std::count(actions.begin(), actions.end(), SyntheticAction::kRightArmRaise), 15);
  EXPECT_EQ(std::count(actions.begin(), actions.end(), SyntheticAction::kSlouch), 10);
  EXPECT_EQ(SyntheticActionName(SyntheticAction::kRightArmRaise), "right-arm-raise");
  EXPECT_EQ(SyntheticActionName(SyntheticAction::kBothArmsRaise), "both-arms-raise");
  EXPECT_EQ(SyntheticActionName(SyntheticAction::kSlouch), "slouch");
}

// Checks what every library must satisfy: segments inside their clips, at rest on both sides,
// in order without overlap, with the peak inside; rest frames near the clip's first frame.
void ExpectWellFormed(const SyntheticCorpus& library) {
  for (size_t i = 0; i < library.segments.size(); ++i) {
    const SyntheticSegment& s = library.segments[i];
    ASSERT_GE(s.clip, 0);
    ASSERT_LT(s.clip, static_cast<int>(library.clips.size()));
    const Clip& clip = library.clips[s.clip];
    ASSERT_GE(s.first_frame, 1) << i;                      // a rest frame before
    ASSERT_LE(s.last_frame, clip.frame_count() - 2) << i;  // and after
    EXPECT_LE(s.first_frame, s.peak_first_frame) << i;
    EXPECT_LE(s.peak_first_frame, s.peak_last_frame) << i;
    EXPECT_LE(s.peak_last_frame, s.last_frame) << i;
    if (i > 0) {
      const SyntheticSegment& previous = library.segments[i - 1];
      ASSERT_GE(s.clip, previous.clip);
      if (s.clip == previous.clip) {
        EXPECT_GT(s.first_frame, previous.last_frame + 1) << i;
      }
    }
    // The frames around the segment are the rest pose but for the idle sway; the peak is not.
    for (int f : {s.first_frame - 1, s.last_frame + 1}) {
      for (int j = 0; j < clip.skeleton().joint_count(); ++j) {
        EXPECT_LT(AngleBetween(clip.rotation(f, j), clip.rotation(0, j)), 4.0 * kDeg)
            << i << " frame " << f << " joint " << clip.skeleton().joint(j).name;
      }
    }
    double peak_angle = 0.0;
    for (int j = 0; j < clip.skeleton().joint_count(); ++j) {
      peak_angle = std::max(peak_angle, AngleBetween(clip.rotation(s.peak_first_frame, j),
                                                     clip.rotation(s.first_frame - 1, j)));
    }
    EXPECT_GT(peak_angle, 5.0 * kDeg) << i;
  }
}

TEST(SyntheticCorpus, SegmentsLieInsideTheirClipsSeparatedByRest) {
  const SyntheticCorpus& library = DefaultLibrary();
  ExpectWellFormed(library);
  // The idle sway keeps rest frames apart, but small.
  const Clip& clip = library.clips[0];
  EXPECT_NE(clip.rotations().row(0), clip.rotations().row(1));
  EXPECT_NE(clip.positions().row(0), clip.positions().row(10));
}

TEST(SyntheticCorpus, ActionDurationsScaleWithinTheTimingRange) {
  const SyntheticCorpus& library = DefaultLibrary();
  double lowest = 10.0, highest = 0.0;
  for (const SyntheticSegment& s : library.segments) {
    const double nominal_frames = SyntheticActionNominalDuration(s.action) * 50.0;
    const int frames = s.last_frame - s.first_frame + 1;
    EXPECT_GE(s.timing_scale, 0.7);
    EXPECT_LE(s.timing_scale, 1.5);
    EXPECT_NEAR(frames, s.timing_scale * nominal_frames, 0.5 + 1e-9);
    const double ratio = frames / nominal_frames;
    EXPECT_GE(ratio, 0.7 - 0.5 / nominal_frames);
    EXPECT_LE(ratio, 1.5 + 0.5 / nominal_frames);
    lowest = std::min(lowest, ratio);
    highest = std::max(highest, ratio);
  }
  // 75 uniform draws cover the range.
  EXPECT_LT(lowest, 0.8);
  EXPECT_GT(highest, 1.4);
}

TEST(SyntheticCorpus, IsDeterministicPerSeed) {
  SyntheticCorpusOptions options;
  options.seed = 7;
  const SyntheticCorpus a = Generate(options);
  const SyntheticCorpus b = Generate(options);
  ASSERT_EQ(a.clips.size(), b.clips.size());
  for (size_t c = 0; c < a.clips.size(); ++c) {
    EXPECT_EQ(a.clips[c].rotations(), b.clips[c].rotations());  // bit-identical
    EXPECT_EQ(a.clips[c].positions(), b.clips[c].positions());
  }
  ASSERT_EQ(a.segments.size(), b.segments.size());
  for (size_t i = 0; i < a.segments.size(); ++i) {
    EXPECT_EQ(a.segments[i].first_frame, b.segments[i].first_frame);
    EXPECT_EQ(a.segments[i].last_frame, b.segments[i].last_frame);
    EXPECT_EQ(a.segments[i].timing_scale, b.segments[i].timing_scale);
  }

  // Clips rendered on several threads are the same as on one.
  SyntheticCorpusOptions threaded = options;
  threaded.max_clip_duration_s = 30.0;
  threaded.threads = 1;
  const SyntheticCorpus serial = Generate(threaded);
  threaded.threads = 4;
  const SyntheticCorpus parallel = Generate(threaded);
  ASSERT_GT(serial.clips.size(), 8u);
  ASSERT_EQ(serial.clips.size(), parallel.clips.size());
  for (size_t c = 0; c < serial.clips.size(); ++c) {
    EXPECT_EQ(serial.clips[c].rotations(), parallel.clips[c].rotations()) << c;
    EXPECT_EQ(serial.clips[c].positions(), parallel.clips[c].positions()) << c;
  }

  options.seed = 8;
  const SyntheticCorpus other = Generate(options);
  ASSERT_EQ(other.segments.size(), a.segments.size());  // the same script
  EXPECT_NE(other.segments[0].timing_scale, a.segments[0].timing_scale);
  EXPECT_FALSE(other.clips[0].frame_count() == a.clips[0].frame_count() &&
               other.clips[0].rotations() == a.clips[0].rotations());
}

TEST(SyntheticCorpus, EachActionMovesItsOwnJoints) {
  const SyntheticCorpus& library = DefaultLibrary();
  const int right = Joint("RightShoulder"), left = Joint("LeftShoulder");
  const int spine = Joint("Spine"), chest = Joint("Chest");
  const int left_collar = Joint("LeftCollar"), right_collar = Joint("RightCollar");
  std::vector<double> peak_leans;
  for (size_t i = 0; i < library.segments.size(); ++i) {
    const SyntheticSegment& s = library.segments[i];
    const double r = MaxAngleFromRest(library, s, right);
    const double l = MaxAngleFromRest(library, s, left);
    const double torso =
        std::max(MaxAngleFromRest(library, s, spine), MaxAngleFromRest(library, s, chest));
    double any = 0.0;
    for (int j = 0; j < SyntheticSkeleton()->joint_count(); ++j) {
      any = std::max(any, MaxAngleFromRest(library, s, j));
    }
    SCOPED_TRACE(::testing::Message() << "segment " << i << " " << SyntheticActionName(s.action));
    switch (s.action) {
      case SyntheticAction::kRightArmRaise:
        EXPECT_GT(r, 100.0 * kDeg);
        EXPECT_LT(l, 2.0 * kDeg);
        peak_leans.push_back(library.clips[s.clip].rotation(s.peak_first_frame, spine).x());
        break;
      case SyntheticAction::kLeftArmRaise:
        EXPECT_GT(l, 100.0 * kDeg);
        EXPECT_LT(r, 2.0 * kDeg);
        break;
      case SyntheticAction::kBothArmsRaise:
        EXPECT_GT(r, 100.0 * kDeg);
        EXPECT_GT(l, 100.0 * kDeg);
        break;
      case SyntheticAction::kShrug:
        EXPECT_LT(any, 30.0 * kDeg);
        EXPECT_GT(MaxAngleFromRest(library, s, left_collar), 15.0 * kDeg);
        EXPECT_GT(MaxAngleFromRest(library, s, right_collar), 15.0 * kDeg);
        EXPECT_LT(torso, 3.0 * kDeg);
        break;
      case SyntheticAction::kSlouch:
        EXPECT_GT(torso, 7.0 * kDeg);
        EXPECT_LT(any, 40.0 * kDeg);
        EXPECT_GT(torso, 5.0 * std::max(r, l));
        break;
    }
  }
  // The posture (spine lean) differs from raise to raise.
  ASSERT_EQ(peak_leans.size(), 15u);
  const auto [low, high] = std::minmax_element(peak_leans.begin(), peak_leans.end());
  EXPECT_GT(*high - *low, std::sin(0.5 * 3.0 * kDeg));
}

TEST(SyntheticCorpus, RaisedHandGoesAboveTheHeadOnItsSideAndVaries) {
  const SyntheticCorpus& library = DefaultLibrary();
  const int head = Joint("Head");
  Eigen::Vector3d low = Eigen::Vector3d::Constant(1e9), high = -low;
  for (const SyntheticSegment& s : library.segments) {
    if (s.action != SyntheticAction::kRightArmRaise && s.action != SyntheticAction::kLeftArmRaise) {
      continue;
    }
    const bool right_arm = s.action == SyntheticAction::kRightArmRaise;
    const Clip& clip = library.clips[s.clip];
    const std::vector<Eigen::Vector3d> rest = WorldPositions(clip, s.first_frame - 1);
    const std::vector<Eigen::Vector3d> peak = WorldPositions(clip, s.peak_first_frame);
    const int wrist = Joint(right_arm ? "RightWrist" : "LeftWrist");
    const int other = Joint(right_arm ? "LeftWrist" : "RightWrist");
    EXPECT_GT(peak[wrist].y(), peak[head].y() + 10.0);
    const int shoulder = Joint(right_arm ? "RightShoulder" : "LeftShoulder");
    EXPECT_GT(peak[wrist].y(), peak[shoulder].y() + 40.0);
    EXPECT_GT(peak[wrist].z(), peak[shoulder].z() + 2.0);  // raised forward, not sideways
    EXPECT_GT((right_arm ? -1.0 : 1.0) * peak[wrist].x(), 5.0);
    EXPECT_LT((peak[other] - rest[other]).norm(), 15.0);  // moves only with the lean
    if (right_arm) {
      low = low.cwiseMin(peak[wrist]);
      high = high.cwiseMax(peak[wrist]);
    }
  }
  // The hand targets spread, about as much as a 10 cm cube plus the posture lean.
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_GT(high[axis] - low[axis], 1.0) << axis;
    EXPECT_LT(high[axis] - low[axis], 40.0) << axis;
  }
}

TEST(SyntheticCorpus, TargetDurationRepeatsTheScriptInClipsNeverCuttingAnAction) {
  SyntheticCorpusOptions options;
  options.fps = 30.0;
  options.target_duration_s = 3600.0;
  const SyntheticCorpus library = Generate(options);
  double total = 0.0;
  for (const Clip& clip : library.clips) {
    EXPECT_LE(clip.duration_s(), options.max_clip_duration_s + 1e-9);
    EXPECT_DOUBLE_EQ(clip.fps(), 30.0);
    total += clip.duration_s();
  }
  EXPECT_GE(total, 3600.0);
  EXPECT_LT(total, 3640.0);
  EXPECT_GE(library.clips.size(), 7u);
  EXPECT_LE(library.clips.size(), 8u);
  ExpectWellFormed(library);

  // The script repeats in order with fresh draws; every clip holds actions.
  const std::vector<SyntheticAction> script = ThesisActions();
  std::vector<int> per_clip(library.clips.size(), 0);
  for (size_t i = 0; i < library.segments.size(); ++i) {
    EXPECT_EQ(library.segments[i].action, script[i % script.size()]) << i;
    ++per_clip[library.segments[i].clip];
  }
  EXPECT_GT(library.segments.size(), 10 * script.size());
  for (int count : per_clip) EXPECT_GT(count, 0);
  EXPECT_NE(library.segments[0].timing_scale, library.segments[script.size()].timing_scale);

  // Where the library is cut does not change what is drawn.
  options.max_clip_duration_s = 60.0;
  const SyntheticCorpus short_clips = Generate(options);
  EXPECT_GT(short_clips.clips.size(), 50u);
  for (const Clip& clip : short_clips.clips) EXPECT_LE(clip.duration_s(), 60.0 + 1e-9);
  ASSERT_EQ(short_clips.segments.size(), library.segments.size());
  for (size_t i = 0; i < library.segments.size(); ++i) {
    const SyntheticSegment& a = library.segments[i];
    const SyntheticSegment& b = short_clips.segments[i];
    EXPECT_EQ(a.timing_scale, b.timing_scale) << i;
    EXPECT_EQ(a.last_frame - a.first_frame, b.last_frame - b.first_frame) << i;
  }
  ExpectWellFormed(short_clips);
}

TEST(SyntheticCorpus, FrameRateChangesOnlyTheSampling) {
  SyntheticCorpusOptions options;
  options.fps = 120.0;
  const SyntheticCorpus fast = Generate(options);
  const SyntheticCorpus& slow = DefaultLibrary();
  ASSERT_EQ(fast.segments.size(), slow.segments.size());
  EXPECT_NEAR(fast.clips[0].duration_s(), slow.clips[0].duration_s(), 0.5);
  for (size_t i = 0; i < fast.segments.size(); ++i) {
    EXPECT_EQ(fast.segments[i].timing_scale, slow.segments[i].timing_scale) << i;
    EXPECT_NEAR(fast.segments[i].first_frame / 120.0, slow.segments[i].first_frame / 50.0, 0.5);
  }
}

TEST(SyntheticCorpus, CustomScriptAndWideTargets) {
  // The thesis's second set: arm raises only, with a larger target volume.
  SyntheticCorpusOptions options;
  options.script = {{SyntheticAction::kLeftArmRaise, 2}, {SyntheticAction::kRightArmRaise, 3}};
  options.target_jitter_m = 0.3;
  const SyntheticCorpus library = Generate(options);
  ASSERT_EQ(library.segments.size(), 5u);
  EXPECT_EQ(library.segments[1].action, SyntheticAction::kLeftArmRaise);
  EXPECT_EQ(library.segments[2].action, SyntheticAction::kRightArmRaise);
  ExpectWellFormed(library);
}

TEST(SyntheticCorpus, ClipWritesToBvhAndReadsBack) {
  const SyntheticCorpus& library = DefaultLibrary();
  const SyntheticSegment& s = library.segments.at(0);
  const Clip& clip = library.clips[s.clip];
  const FrameRange range{s.first_frame - 1, s.last_frame + 1};
  absl::StatusOr<std::string> text = WriteBvh(clip, range);
  ASSERT_TRUE(text.ok()) << text.status();
  absl::StatusOr<BvhReadResult> back = ReadBvh(*text);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_TRUE(back->warnings.empty()) << back->warnings.front();
  absl::StatusOr<Clip> expected = clip.Slice(range);
  ASSERT_TRUE(expected.ok());
  ASSERT_EQ(back->clip.frame_count(), range.size());
  ASSERT_TRUE(back->clip.skeleton().SameTopology(clip.skeleton()));
  for (int j = 0; j < clip.skeleton().joint_count(); ++j) {
    EXPECT_EQ(back->clip.skeleton().joint(j).channels, clip.skeleton().joint(j).channels);
    EXPECT_EQ(back->clip.skeleton().joint(j).offset, clip.skeleton().joint(j).offset);
  }
  EXPECT_NEAR(back->clip.fps(), 50.0, 1e-6);
  EXPECT_LT(testing::MaxRotationError(back->clip, *expected), 1e-6);
  EXPECT_LT(testing::MaxRelativePositionError(back->clip, *expected), 1e-6);
}

TEST(SyntheticCorpus, RejectsBadOptions) {
  const std::vector<std::pair<std::string, std::function<void(SyntheticCorpusOptions&)>>> cases = {
      {"fps", [](SyntheticCorpusOptions& o) { o.fps = 0.0; }},
      {"fps", [](SyntheticCorpusOptions& o) { o.fps = -50.0; }},
      {"fps", [](SyntheticCorpusOptions& o) { o.fps = std::nan(""); }},
      {"fps", [](SyntheticCorpusOptions& o) { o.fps = 1e6; }},
      {"timing_scale_min", [](SyntheticCorpusOptions& o) { o.timing_scale_min = 1.6; }},
      {"timing_scale_min", [](SyntheticCorpusOptions& o) { o.timing_scale_min = 0.0; }},
      {"timing_scale_max", [](SyntheticCorpusOptions& o) { o.timing_scale_max = INFINITY; }},
      {"target_jitter_m", [](SyntheticCorpusOptions& o) { o.target_jitter_m = NAN; }},
      {"target_jitter_m", [](SyntheticCorpusOptions& o) { o.target_jitter_m = -0.1; }},
      {"posture_lean_deg", [](SyntheticCorpusOptions& o) { o.posture_lean_deg = 90.0; }},
      {"rest_min_s", [](SyntheticCorpusOptions& o) { o.rest_min_s = 3.0; }},
      {"rest_min_s", [](SyntheticCorpusOptions& o) { o.rest_min_s = -1.0; }},
      {"target_duration_s", [](SyntheticCorpusOptions& o) { o.target_duration_s = 101 * 3600.0; }},
      {"target_duration_s", [](SyntheticCorpusOptions& o) { o.target_duration_s = NAN; }},
      {"max_clip_duration_s", [](SyntheticCorpusOptions& o) { o.max_clip_duration_s = 5.0; }},
      {"threads", [](SyntheticCorpusOptions& o) { o.threads = -1; }},
      {"script", [](SyntheticCorpusOptions& o) { o.script.clear(); }},
      {"count", [](SyntheticCorpusOptions& o) { o.script[0].count = -1; }},
      {"script",
       [](SyntheticCorpusOptions& o) {
         o.script = {{SyntheticAction::kShrug, 0}};
       }},
      {"script may last",
       [](SyntheticCorpusOptions& o) {
         o.script = {{SyntheticAction::kSlouch, 1'000'000}};
       }},
  };
  for (const auto& [expected, change] : cases) {
    SyntheticCorpusOptions options;
    change(options);
    const absl::StatusOr<SyntheticCorpus> library = GenerateSyntheticCorpus(options);
    EXPECT_EQ(library.status().code(), absl::StatusCode::kInvalidArgument) << expected;
    EXPECT_NE(library.status().message().find(expected), absl::string_view::npos)
        << library.status();
  }
}

}  // namespace
}  // namespace motiondb
