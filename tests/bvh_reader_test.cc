#include "core/bvh/bvh_reader.h"

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_join.h"
#include "absl/strings/str_replace.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr double kDeg = std::numbers::pi / 180.0;

// Two joints: a 6-channel ZXY root and a 3-channel XYZ child with an End Site. 9 values a row.
constexpr char kMinimal[] =
    "HIERARCHY\n"                                                                 // 1
    "ROOT Hips\n"                                                                 // 2
    "{\n"                                                                         // 3
    "\tOFFSET 0.0 0.0 0.0\n"                                                      // 4
    "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"  // 5
    "\tJOINT Chest\n"                                                             // 6
    "\t{\n"                                                                       // 7
    "\t\tOFFSET 0.0 5.5 0.0\n"                                                    // 8
    "\t\tCHANNELS 3 Xrotation Yrotation Zrotation\n"                              // 9
    "\t\tEnd Site\n"                                                              // 10
    "\t\t{\n"                                                                     // 11
    "\t\t\tOFFSET 0.0 3.0 0.0\n"                                                  // 12
    "\t\t}\n"                                                                     // 13
    "\t}\n"                                                                       // 14
    "}\n"                                                                         // 15
    "MOTION\n"                                                                    // 16
    "Frames: 2\n"                                                                 // 17
    "Frame Time: 0.0333333\n"                                                     // 18
    "1.0 90.0 -2.5 10.0 20.0 30.0 -40.0 50.0 60.0\n"                              // 19
    "1.5 91.0 -2.0 11.0 21.0 31.0 -41.0 51.0 61.0\n";                             // 20

absl::StatusOr<BvhReadResult> Read(absl::string_view text, const BvhReadOptions& options = {}) {
  return ReadBvh(text, options);
}

std::string Replace(absl::string_view text, absl::string_view from, absl::string_view to) {
  return absl::StrReplaceAll(text, {{from, to}});
}

TEST(BvhReader, ReadsHierarchyChannelsAndValues) {
  absl::StatusOr<BvhReadResult> result = Read(kMinimal);
  ASSERT_TRUE(result.ok()) << result.status();
  const Clip& clip = result->clip;
  const Skeleton& skeleton = clip.skeleton();
  ASSERT_EQ(skeleton.joint_count(), 2);
  EXPECT_EQ(skeleton.joint(0).name, "Hips");
  EXPECT_EQ(skeleton.joint(1).name, "Chest");
  EXPECT_EQ(skeleton.joint(1).parent, 0);
  EXPECT_EQ(skeleton.joint(1).offset, Eigen::Vector3d(0, 5.5, 0));
  ASSERT_TRUE(skeleton.joint(1).end_site.has_value());
  EXPECT_EQ(*skeleton.joint(1).end_site, Eigen::Vector3d(0, 3, 0));
  EXPECT_EQ(skeleton.channel_count(), 9);
  EXPECT_EQ(skeleton.rotation_order(0), EulerOrder::kZXY);
  EXPECT_EQ(skeleton.rotation_order(1), EulerOrder::kXYZ);
  EXPECT_EQ(clip.frame_count(), 2);
  EXPECT_NEAR(clip.fps(), 30.0, 1e-4);
  EXPECT_TRUE(result->warnings.empty());
  EXPECT_EQ(clip.root_position(1), Eigen::Vector3d(1.5, 91.0, -2.0));
  const Quat root = EulerToQuaternion(Eigen::Vector3d(11, 21, 31) * kDeg, EulerOrder::kZXY);
  const Quat chest = EulerToQuaternion(Eigen::Vector3d(-41, 51, 61) * kDeg, EulerOrder::kXYZ);
  EXPECT_LT(AngleBetween(clip.rotation(1, 0), root), 1e-12);
  EXPECT_LT(AngleBetween(clip.rotation(1, 1), chest), 1e-12);
}

// Every dialect below must parse to exactly the same clip as kMinimal.
void ExpectSameAsMinimal(const std::string& text) {
  absl::StatusOr<BvhReadResult> expected = Read(kMinimal);
  absl::StatusOr<BvhReadResult> result = Read(text);
  ASSERT_TRUE(result.ok()) << result.status() << "\n" << text;
  EXPECT_EQ(result->clip.rotations(), expected->clip.rotations());
  EXPECT_EQ(result->clip.positions(), expected->clip.positions());
  EXPECT_EQ(result->clip.frame_time(), expected->clip.frame_time());
  EXPECT_TRUE(result->warnings.empty());
}

TEST(BvhReaderDialects, CrlfLineEndings) { ExpectSameAsMinimal(Replace(kMinimal, "\n", "\r\n")); }

TEST(BvhReaderDialects, NoFinalNewline) {
  std::string text = kMinimal;
  text.pop_back();
  ExpectSameAsMinimal(text);
  ExpectSameAsMinimal(Replace(text, "\n", "\r\n"));
}

TEST(BvhReaderDialects, SpacesInsteadOfTabsAndIndentedRows) {
  std::string text = Replace(kMinimal, "\t", "    ");
  text = Replace(text, "\n1.", "\n    1.");
  ExpectSameAsMinimal(text);
}

TEST(BvhReaderDialects, TabAfterFramesAndGluedValues) {
  ExpectSameAsMinimal(Replace(kMinimal, "Frames: 2", "Frames:\t2"));
  ExpectSameAsMinimal(Replace(kMinimal, "Frames: 2", "Frames:2"));
  ExpectSameAsMinimal(Replace(kMinimal, "Frame Time: 0.0333333", "Frame Time:\t0.0333333"));
}

TEST(BvhReaderDialects, ENotationAndExplicitPlus) {
  ExpectSameAsMinimal(Replace(Replace(kMinimal, "90.0 -2.5", "9.0E+01 -2.5e0"), "1.5 ", "+1.5 "));
}

TEST(BvhReaderDialects, ByteOrderMarkAndBlankLines) {
  ExpectSameAsMinimal("\xEF\xBB\xBF" + Replace(kMinimal, "\n1.5", "\n\n   \n1.5") + "\n\n");
}

TEST(BvhReaderDialects, BraceOnTheJointLine) {
  ExpectSameAsMinimal(Replace(kMinimal, "JOINT Chest\n\t{\n", "JOINT Chest {\n"));
}

TEST(BvhReaderDialects, ColonsAndSpacesInJointNames) {
  absl::StatusOr<BvhReadResult> result = Read(Replace(
      Replace(kMinimal, "ROOT Hips", "ROOT mixamorig:Hips"), "JOINT Chest", "JOINT Upper Chest"));
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->clip.skeleton().joint(0).name, "mixamorig:Hips");
  EXPECT_EQ(result->clip.skeleton().joint(1).name, "Upper Chest");
}

TEST(BvhReaderDialects, LeafWithoutEndSiteAndSixChannelsOnAChild) {
  std::string text =
      Replace(kMinimal, "\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0.0 3.0 0.0\n\t\t}\n", "");
  text = Replace(text, "CHANNELS 3 Xrotation Yrotation Zrotation",
                 "CHANNELS 6 Xposition Yposition Zposition Xrotation Yrotation Zrotation");
  text = Replace(Replace(text, "-40.0", "7 8 9 -40.0"), "-41.0", "7 8 9 -41.0");
  absl::StatusOr<BvhReadResult> result = Read(text);
  ASSERT_TRUE(result.ok()) << result.status();
  const Skeleton& skeleton = result->clip.skeleton();
  EXPECT_FALSE(skeleton.joint(1).end_site.has_value());
  EXPECT_EQ(skeleton.position_slot(1), 1);
  EXPECT_EQ(result->clip.positions().row(0).tail<3>(), Eigen::RowVector3d(7, 8, 9));
}

TEST(BvhReaderDialects, JointWithoutChannelsIsIdentity) {
  std::string text = Replace(kMinimal, "\t\tCHANNELS 3 Xrotation Yrotation Zrotation\n", "");
  text = Replace(Replace(text, " -40.0 50.0 60.0", ""), " -41.0 51.0 61.0", "");
  absl::StatusOr<BvhReadResult> result = Read(text);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_FALSE(result->clip.skeleton().has_rotation(1));
  EXPECT_LT(AngleBetween(result->clip.rotation(0, 1), Quat::Identity()), 1e-15);
}

TEST(BvhReaderWarnings, FramesHeaderDisagreeingWithRowsKeepsTheRows) {
  for (const char* header : {"Frames: 3", "Frames: 1"}) {
    absl::StatusOr<BvhReadResult> result = Read(Replace(kMinimal, "Frames: 2", header));
    ASSERT_TRUE(result.ok()) << result.status();
    EXPECT_EQ(result->clip.frame_count(), 2);
    ASSERT_EQ(result->warnings.size(), 1u);
    EXPECT_THAT(result->warnings[0], HasSubstr("line 17"));
    EXPECT_THAT(result->warnings[0], HasSubstr("2 frame rows"));
  }
}

// Malformed input: the error names the line and what was expected.
struct MalformedCase {
  const char* name;
  std::string text;
  absl::StatusCode code;
  std::vector<std::string> message_parts;
};

std::string Truncated(size_t keep) { return std::string(kMinimal).substr(0, keep); }

std::vector<MalformedCase> MalformedCases() {
  const std::string minimal = kMinimal;
  const size_t last_row = minimal.find("1.5 91.0");
  return {
      {"EmptyFile", "", absl::StatusCode::kInvalidArgument, {"empty file"}},
      {"OnlyWhitespace", " \r\n\t\n", absl::StatusCode::kInvalidArgument, {"empty file"}},
      {"BinaryGarbage",
       std::string("\x7f"
                   "ELF\x02\x01\x01\0\0\0",
                   10),
       absl::StatusCode::kInvalidArgument,
       {"line 1", "expected 'HIERARCHY'", "binary data"}},
      {"NotBvh",
       "{\"hello\": 1}\n",
       absl::StatusCode::kInvalidArgument,
       {"line 1", "expected 'HIERARCHY'"}},
      {"TruncatedInOffset",
       Truncated(minimal.find("0.0 5.5") + 8),
       absl::StatusCode::kInvalidArgument,
       {"line 8", "OFFSET", "end of file"}},
      {"TruncatedBeforeMotion",
       Truncated(minimal.find("MOTION")),
       absl::StatusCode::kInvalidArgument,
       {"expected 'MOTION'", "end of file"}},
      {"TruncatedHierarchyBraces",
       Truncated(minimal.find("\t}\n}")),
       absl::StatusCode::kInvalidArgument,
       {"line 14", "'}'", "end of file"}},
      {"TruncatedLastRow",
       Truncated(last_row + 12),
       absl::StatusCode::kInvalidArgument,
       {"line 20", "expected 9 values, found 3", "truncated"}},
      {"ShortLastRowEndingInANewline",
       Replace(minimal, "1.5 91.0 -2.0 11.0 21.0 31.0 -41.0 51.0 61.0", "1.5 91.0 -2.0"),
       absl::StatusCode::kInvalidArgument,
       {"line 20", "expected 9 values, found 3 (the file is truncated)"}},
      {"TooFewValuesOnARow",
       Replace(minimal, "10.0 20.0 30.0 ", ""),
       absl::StatusCode::kInvalidArgument,
       {"line 19", "expected 9 values, found 6"}},
      {"TooManyValuesOnARow",
       Replace(minimal, "61.0", "61.0 62.0"),
       absl::StatusCode::kInvalidArgument,
       {"line 20", "expected 9 values, found more"}},
      {"NotANumber",
       Replace(minimal, "50.0", "5O.0"),
       absl::StatusCode::kInvalidArgument,
       {"line 19", "a number (value 8 of 9)", "'5O.0'"}},
      {"NaNValue",
       Replace(minimal, "51.0", "nan"),
       absl::StatusCode::kInvalidArgument,
       {"line 20", "value 8 is nan", "finite"}},
      {"InfValue",
       Replace(minimal, "1.0 90.0", "1.0 -inf"),
       absl::StatusCode::kInvalidArgument,
       {"line 19", "value 2 is -inf"}},
      {"HugeRotation",
       Replace(minimal, "50.0", "1e308"),
       absl::StatusCode::kInvalidArgument,
       {"line 19", "value 8 (Chest Yrotation) is 1e308 degrees", "beyond +-100000"}},
      {"RotationJustBeyondTheBound",
       Replace(minimal, "10.0 20.0", "-100000.5 20.0"),
       absl::StatusCode::kInvalidArgument,
       {"line 19", "value 4 (Hips Zrotation) is -100000.5"}},
      {"NaNOffset",
       Replace(minimal, "0.0 5.5 0.0", "0.0 NaN 0.0"),
       absl::StatusCode::kInvalidArgument,
       {"line 8", "finite number in OFFSET", "'NaN'"}},
      {"UnknownChannel",
       Replace(minimal, "Xrotation Yrotation Zrotation", "Xrotation Wrotation Zrotation"),
       absl::StatusCode::kInvalidArgument,
       {"line 9", "channel name", "'Wrotation'"}},
      {"BadChannelCount",
       Replace(minimal, "CHANNELS 3", "CHANNELS 7"),
       absl::StatusCode::kInvalidArgument,
       {"line 9", "channel count from 0 to 6", "'7'"}},
      {"TwoRotationChannels",
       Replace(minimal, "CHANNELS 3 Xrotation Yrotation Zrotation",
               "CHANNELS 2 Xrotation Yrotation"),
       absl::StatusCode::kInvalidArgument,
       {"line 9", "expected 0 or 3 rotation channels"}},
      {"RepeatedChannel",
       Replace(minimal, "Xrotation Yrotation Zrotation", "Xrotation Yrotation Xrotation"),
       absl::StatusCode::kInvalidArgument,
       {"line 9", "listed twice"}},
      {"DuplicateJointName",
       Replace(minimal, "JOINT Chest", "JOINT Hips"),
       absl::StatusCode::kInvalidArgument,
       {"line 6", "'Hips' is already used on line 2"}},
      {"BraceInJointName",
       Replace(minimal, "JOINT Chest", "JOINT Chest{{"),
       absl::StatusCode::kInvalidArgument,
       {"line 6", "joint name without braces", "'Chest{'"}},
      {"UnexpectedKeyword",
       Replace(minimal, "\tJOINT Chest", "\tJIONT Chest"),
       absl::StatusCode::kInvalidArgument,
       {"line 6", "'JIONT'"}},
      {"MissingMotion",
       Replace(minimal, "MOTION", "MOTOIN"),
       absl::StatusCode::kInvalidArgument,
       {"line 16", "expected 'MOTION'", "'MOTOIN'"}},
      {"SecondRoot",
       Replace(minimal, "MOTION", "ROOT Other\n{\n}\nMOTION"),
       absl::StatusCode::kInvalidArgument,
       {"line 16", "second ROOT"}},
      {"NegativeFrames",
       Replace(minimal, "Frames: 2", "Frames: -2"),
       absl::StatusCode::kInvalidArgument,
       {"line 17", "non-negative frame count", "'-2'"}},
      {"AbsurdFrames",
       Replace(minimal, "Frames: 2", "Frames: 99999999999"),
       absl::StatusCode::kResourceExhausted,
       {"line 17", "over the limit"}},
      {"OverflowingFrames",
       Replace(minimal, "Frames: 2", "Frames: 999999999999999999999999"),
       absl::StatusCode::kResourceExhausted,
       {"line 17", "over the limit"}},
      {"MissingFrames",
       Replace(minimal, "Frames: 2\n", ""),
       absl::StatusCode::kInvalidArgument,
       {"line 17", "'Frames:'", "'Frame'"}},
      {"ZeroFrameTime",
       Replace(minimal, "0.0333333", "0"),
       absl::StatusCode::kInvalidArgument,
       {"line 18", "positive frame time"}},
      {"NaNFrameTime",
       Replace(minimal, "0.0333333", "nan"),
       absl::StatusCode::kInvalidArgument,
       {"line 18", "positive frame time"}},
      {"NoRows",
       Truncated(minimal.find("1.0 90.0")),
       absl::StatusCode::kInvalidArgument,
       {"expected frame rows", "end of file"}},
  };
}

class BvhReaderMalformed : public ::testing::TestWithParam<MalformedCase> {};

TEST_P(BvhReaderMalformed, IsRejectedWithLineAndExpectation) {
  const MalformedCase& c = GetParam();
  absl::StatusOr<BvhReadResult> result = Read(c.text);
  ASSERT_FALSE(result.ok()) << "accepted:\n" << c.text;
  EXPECT_EQ(result.status().code(), c.code) << result.status();
  for (const std::string& part : c.message_parts) {
    EXPECT_THAT(std::string(result.status().message()), HasSubstr(part));
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, BvhReaderMalformed, ::testing::ValuesIn(MalformedCases()),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(BvhReaderLimits, InputOverTheSizeLimitIsRefusedBeforeParsing) {
  BvhReadOptions options;
  options.max_bytes = 100;
  absl::StatusOr<BvhReadResult> result = Read(kMinimal, options);
  EXPECT_EQ(result.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(std::string(result.status().message()), HasSubstr("over the limit of 100"));
}

TEST(BvhReaderLimits, MoreRowsThanTheFrameLimitAreRefused) {
  BvhReadOptions options;
  options.max_frames = 1;
  absl::StatusOr<BvhReadResult> result = Read(Replace(kMinimal, "Frames: 2", "Frames: 1"), options);
  EXPECT_EQ(result.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(std::string(result.status().message()), HasSubstr("line 20"));
}

// Many turns within the bound keep their meaning: 270 + 138 x 720 degrees is 270 degrees (an even
// number of turns, so the same quaternion, not its negation).
TEST(BvhReaderLimits, RotationsWithinTheBoundKeepTheirAngle) {
  absl::StatusOr<BvhReadResult> wound = Read(Replace(kMinimal, "10.0 20.0", "99630.0 20.0"));
  absl::StatusOr<BvhReadResult> plain = Read(Replace(kMinimal, "10.0 20.0", "270.0 20.0"));
  ASSERT_TRUE(wound.ok()) << wound.status();
  ASSERT_TRUE(plain.ok()) << plain.status();
  EXPECT_TRUE(wound->clip.rotations().isApprox(plain->clip.rotations(), 1e-9));
}

TEST(BvhReaderLimits, TheRotationBoundIsAnOption) {
  BvhReadOptions options;
  options.max_abs_rotation_degrees = 45;
  absl::StatusOr<BvhReadResult> result = Read(kMinimal, options);
  EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(result.status().message()),
              HasSubstr("line 19: value 8 (Chest Yrotation) is 50.0"));
}

TEST(BvhReaderLimits, TooManyJointsAreRefused) {
  BvhReadOptions options;
  options.max_joints = 1;
  EXPECT_EQ(Read(kMinimal, options).status().code(), absl::StatusCode::kResourceExhausted);
}

// A chain of `depth` + 1 joints, each inside the last, and `frames` rows.
std::string DeepChainBvh(int depth, int frames) {
  std::string text =
      "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n";
  for (int i = 1; i <= depth; ++i) {
    text += "JOINT j" + std::to_string(i) +
            "\n{\nOFFSET 0 1 0\nCHANNELS 3 Xrotation Yrotation Zrotation\n";
  }
  for (int i = 0; i <= depth; ++i) text += "}\n";
  text += "MOTION\nFrames: " + std::to_string(frames) + "\nFrame Time: 0.01\n";
  for (int row = 0; row < frames; ++row) {
    for (int i = 0; i <= depth; ++i) text += std::to_string((i + row) % 90) + " 1 2 ";
    text += "\n";
  }
  return text;
}

TEST(BvhReaderLimits, DeepHierarchiesDoNotOverflowTheStack) {
  const int depth = 999;
  absl::StatusOr<BvhReadResult> result = Read(DeepChainBvh(depth, 1));
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->clip.skeleton().joint_count(), depth + 1);
}

TEST(BvhReaderFile, MissingFileIsNotFoundAndErrorsNameThePath) {
  absl::StatusOr<BvhReadResult> missing = ReadBvhFile("/nonexistent/walk.bvh");
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(std::string(missing.status().message()), HasSubstr("/nonexistent/walk.bvh"));

  const std::filesystem::path dir = testing::MakeTempDir("bvh_reader_test");
  const std::filesystem::path path = dir / "bad.bvh";
  FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  const std::string text = Replace(kMinimal, "50.0", "x");
  std::fwrite(text.data(), 1, text.size(), f);
  std::fclose(f);
  absl::StatusOr<BvhReadResult> bad = ReadBvhFile(path);
  EXPECT_THAT(std::string(bad.status().message()), HasSubstr(path.string() + ": line 19"));
  std::filesystem::remove_all(dir);
}

// The conformance corpus: each real quirk, with what the corpus README says about it.
class ConformanceTest : public ::testing::Test {
 protected:
  BvhReadResult Load(const std::string& name) {
    const std::filesystem::path path = *testing::MocapDir() / "conformance" / name;
    absl::StatusOr<BvhReadResult> result = ReadBvhFile(path.string());
    EXPECT_TRUE(result.ok()) << result.status();
    return result.ok() ? *std::move(result) : BvhReadResult{Read(kMinimal)->clip, {"failed"}};
  }
  void SetUp() override {
    if (!testing::MocapDir()) GTEST_SKIP() << "../shared/mocap is absent; skipped";
  }
};

TEST_F(ConformanceTest, NoEndSiteXyz) {
  const BvhReadResult r = Load("no_end_site_xyz.bvh");
  ASSERT_EQ(r.clip.skeleton().joint_count(), 4);
  for (const Joint& joint : r.clip.skeleton().joints()) EXPECT_FALSE(joint.end_site.has_value());
  EXPECT_EQ(r.clip.skeleton().rotation_order(1), EulerOrder::kXYZ);
  EXPECT_TRUE(r.warnings.empty());
}

TEST_F(ConformanceTest, LeavesWithoutEndSite) {
  for (const char* name : {"leaf_no_end_site_handspring.bvh", "leaf_no_end_site_cartwheel.bvh"}) {
    const BvhReadResult r = Load(name);
    const Skeleton& skeleton = r.clip.skeleton();
    int bare_leaves = 0;
    for (int j = 0; j < skeleton.joint_count(); ++j) {
      bare_leaves += skeleton.Children(j).empty() && !skeleton.joint(j).end_site;
    }
    EXPECT_GT(bare_leaves, 0) << name;
    EXPECT_GT(r.clip.frame_count(), 100) << name;
  }
}

TEST_F(ConformanceTest, CrlfFiles) {
  EXPECT_EQ(Load("crlf_no_final_newline.bvh").clip.frame_count(), 60);
  const BvhReadResult mixed = Load("crlf_mixed_orders_zyx_zxy.bvh");
  const Skeleton& skeleton = mixed.clip.skeleton();
  EXPECT_EQ(skeleton.rotation_order(0), EulerOrder::kZYX);
  int zxy = 0;
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    zxy += skeleton.has_rotation(j) && skeleton.rotation_order(j) == EulerOrder::kZXY;
  }
  EXPECT_GT(zxy, 0);
  EXPECT_GT(Load("crlf_example.bvh").clip.frame_count(), 0);
  EXPECT_GT(Load("tab_after_frames_crlf.bvh").clip.frame_count(), 0);
}

TEST_F(ConformanceTest, OneAndTwoFrames) {
  EXPECT_EQ(Load("single_frame.bvh").clip.frame_count(), 1);
  EXPECT_EQ(Load("two_frames.bvh").clip.frame_count(), 2);
}

TEST_F(ConformanceTest, ColonNamesENotationIndentedRowsPymo) {
  EXPECT_EQ(Load("colon_joint_names.bvh").clip.skeleton().joint(0).name, "mixamorig:Hips");
  EXPECT_GT(Load("e_notation.bvh").clip.frame_count(), 0);
  EXPECT_GT(Load("indented_rows.bvh").clip.frame_count(), 0);
  EXPECT_GT(Load("pymo_walk.bvh").clip.frame_count(), 0);
}

TEST_F(ConformanceTest, FramesHeaderMismatchKeepsRowsAndWarns) {
  const BvhReadResult r = Load("frames_header_mismatch.bvh");
  EXPECT_EQ(r.clip.frame_count(), 3070);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_THAT(r.warnings[0], HasSubstr("Frames: 3069"));
}

// BvhStreamReader: whatever the pieces, ReadBvh's result or error for the whole text.

// `text` appended in the pieces that `cuts` (increasing offsets) make, then Finish().
absl::StatusOr<BvhReadResult> ReadInPieces(absl::string_view text, const std::vector<size_t>& cuts,
                                           const BvhReadOptions& options = {}) {
  BvhStreamReader reader(options);
  size_t begin = 0;
  for (size_t cut : cuts) {
    if (absl::Status status = reader.Append(text.substr(begin, cut - begin)); !status.ok()) {
      return status;
    }
    begin = cut;
  }
  if (absl::Status status = reader.Append(text.substr(begin)); !status.ok()) return status;
  return reader.Finish();
}

// The cuts tried: every single cut, every byte a piece, and random pieces of 1-16 bytes.
std::vector<std::vector<size_t>> CutsToTry(size_t size) {
  std::vector<std::vector<size_t>> tries;
  for (size_t cut = 0; cut <= size; ++cut) tries.push_back({cut});
  std::vector<size_t> bytes;
  for (size_t cut = 1; cut < size; ++cut) bytes.push_back(cut);
  tries.push_back(bytes);
  std::mt19937 random(7);
  for (int run = 0; run < 20; ++run) {
    std::vector<size_t> cuts;
    for (size_t cut = 1 + random() % 16; cut < size; cut += 1 + random() % 16) cuts.push_back(cut);
    tries.push_back(cuts);
  }
  return tries;
}

std::string Describe(const std::vector<size_t>& cuts) {
  return "cuts: " + absl::StrJoin(cuts, " ");
}

void ExpectSameInEveryPieces(const std::string& text, const BvhReadOptions& options = {}) {
  const absl::StatusOr<BvhReadResult> whole = ReadBvh(text, options);
  for (const std::vector<size_t>& cuts : CutsToTry(text.size())) {
    const absl::StatusOr<BvhReadResult> pieces = ReadInPieces(text, cuts, options);
    ASSERT_EQ(pieces.status(), whole.status()) << Describe(cuts);
    if (!whole.ok()) continue;
    ASSERT_EQ(pieces->clip.rotations(), whole->clip.rotations()) << Describe(cuts);
    ASSERT_EQ(pieces->clip.positions(), whole->clip.positions()) << Describe(cuts);
    ASSERT_EQ(pieces->clip.frame_time(), whole->clip.frame_time()) << Describe(cuts);
    ASSERT_EQ(pieces->clip.skeleton().joints().size(), whole->clip.skeleton().joints().size());
    for (int j = 0; j < whole->clip.skeleton().joint_count(); ++j) {
      ASSERT_EQ(pieces->clip.skeleton().joint(j).name, whole->clip.skeleton().joint(j).name);
    }
    ASSERT_EQ(pieces->warnings, whole->warnings) << Describe(cuts);
  }
}

TEST(BvhStreamReader, EveryDialectParsesTheSameInAnyPieces) {
  std::string no_final_newline = kMinimal;
  no_final_newline.pop_back();
  for (const std::string& text :
       {std::string(kMinimal), Replace(kMinimal, "\n", "\r\n"), no_final_newline,
        Replace(no_final_newline, "\n", "\r\n"),
        "\xEF\xBB\xBF" + Replace(kMinimal, "\n1.5", "\n\n   \n1.5") + "\n\n",
        Replace(kMinimal, "Frames: 2", "Frames:2"), Replace(kMinimal, "Frames: 2", "Frames: 5"),
        Replace(kMinimal, "JOINT Chest\n\t{\n", "JOINT Chest {\n"),
        Replace(Replace(kMinimal, "90.0 -2.5", "9.0E+01 -2.5e0"), "1.5 ", "+1.5 ")}) {
    SCOPED_TRACE(text);
    ExpectSameInEveryPieces(text);
  }
}

TEST_P(BvhReaderMalformed, IsRejectedTheSameWhenStreamedInAnyPieces) {
  ExpectSameInEveryPieces(GetParam().text);
}

// "Truncated" is said of the text's last line only, however the text arrives.
TEST(BvhReaderMalformedRows, AShortRowFollowedByABlankLineIsNotCalledTruncated) {
  const std::string text =
      Replace(kMinimal, "1.5 91.0 -2.0 11.0 21.0 31.0 -41.0 51.0 61.0\n", "1.5 91.0 -2.0\n\n");
  const absl::StatusOr<BvhReadResult> result = Read(text);
  EXPECT_THAT(std::string(result.status().message()), HasSubstr("line 20: expected 9 values"));
  EXPECT_THAT(std::string(result.status().message()), Not(HasSubstr("truncated")));
  ExpectSameInEveryPieces(text);
}

TEST(BvhReaderLimits, TheHeaderRowAndClipLimitsAreRefusedInAnyPieces) {
  struct Case {
    BvhReadOptions options;
    std::string message;
  };
  std::vector<Case> cases(3);
  cases[0].options.max_header_bytes = 100;
  cases[0].message = "the header (HIERARCHY to the frame time) is over the limit of 100 bytes";
  cases[1].options.max_row_bytes = 20;
  cases[1].message = "line 19: a frame row longer than the limit of 20 bytes";
  cases[2].options.max_clip_bytes = 100;  // a frame takes 8 x (4 x 2 joints + 3) = 88 bytes
  cases[2].message = "line 20: the clip would take more than 100 bytes of memory";
  for (const Case& c : cases) {
    const absl::StatusOr<BvhReadResult> result = Read(kMinimal, c.options);
    EXPECT_EQ(result.status().code(), absl::StatusCode::kResourceExhausted) << result.status();
    EXPECT_THAT(std::string(result.status().message()), HasSubstr(c.message));
    ExpectSameInEveryPieces(kMinimal, c.options);
  }
}

TEST(BvhStreamReader, LimitsHoldInAnyPieces) {
  BvhReadOptions frames;
  frames.max_frames = 1;
  ExpectSameInEveryPieces(Replace(kMinimal, "Frames: 2", "Frames: 1"), frames);
  BvhReadOptions joints;
  joints.max_joints = 1;
  ExpectSameInEveryPieces(kMinimal, joints);
  BvhReadOptions rotation;
  rotation.max_abs_rotation_degrees = 45;
  ExpectSameInEveryPieces(kMinimal, rotation);
}

TEST(BvhStreamReader, TheSizeLimitCountsEveryPiece) {
  BvhReadOptions options;
  options.max_bytes = 100;
  BvhStreamReader reader(options);
  const absl::string_view text = kMinimal;
  ASSERT_TRUE(reader.Append(text.substr(0, 60)).ok());
  const absl::Status over = reader.Append(text.substr(60, 60));
  EXPECT_EQ(over.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(std::string(over.message()), HasSubstr("over the limit of 100"));
  EXPECT_EQ(reader.Finish().status(), over);
}

// The error comes with the piece that completes its line: a client streaming a large file learns
// of it without sending the rest.
TEST(BvhStreamReader, AnErrorIsReportedByThePieceThatCompletesItsLine) {
  const std::string text = Replace(kMinimal, "50.0", "5O.0");
  const size_t row_end = text.find('\n', text.find("5O.0"));
  BvhStreamReader reader;
  ASSERT_TRUE(reader.Append(text.substr(0, row_end)).ok());
  const absl::Status error = reader.Append("\n");
  EXPECT_THAT(std::string(error.message()), HasSubstr("line 19"));
  EXPECT_EQ(reader.Append("1.5 91.0 -2.0 11.0 21.0 31.0 -41.0 51.0 61.0\n"), error);
  EXPECT_EQ(reader.Finish().status(), error);
}

TEST(BvhStreamReader, AHierarchyOfAThousandJointsArrivesAByteAtATime) {
  const int depth = 999;
  const std::string text = DeepChainBvh(depth, 2);
  BvhStreamReader reader;
  for (char c : text) ASSERT_TRUE(reader.Append(absl::string_view(&c, 1)).ok());
  absl::StatusOr<BvhReadResult> streamed = reader.Finish();
  ASSERT_TRUE(streamed.ok()) << streamed.status();
  EXPECT_EQ(streamed->clip.skeleton().joint_count(), depth + 1);
  EXPECT_EQ(streamed->clip.rotations(), ReadBvh(text)->clip.rotations());
}

// Real files of every quirk, in random pieces.
TEST(BvhStreamReader, ConformanceFilesParseTheSameInRandomPieces) {
  if (!testing::MocapDir()) GTEST_SKIP() << "../shared/mocap is absent; skipped";
  const std::vector<std::filesystem::path> files =
      testing::BvhFilesUnder(*testing::MocapDir() / "conformance");
  ASSERT_FALSE(files.empty());
  std::mt19937 random(11);
  for (const std::filesystem::path& file : files) {
    const std::string text = testing::ReadFileOrDie(file);
    const absl::StatusOr<BvhReadResult> whole = ReadBvh(text);
    for (size_t max_piece : {size_t{7}, size_t{4096}, size_t{65536}}) {
      std::vector<size_t> cuts;
      for (size_t cut = 1 + random() % max_piece; cut < text.size();
           cut += 1 + random() % max_piece) {
        cuts.push_back(cut);
      }
      const absl::StatusOr<BvhReadResult> pieces = ReadInPieces(text, cuts);
      ASSERT_EQ(pieces.status(), whole.status()) << file;
      if (!whole.ok()) continue;
      EXPECT_EQ(pieces->clip.rotations(), whole->clip.rotations()) << file;
      EXPECT_EQ(pieces->clip.positions(), whole->clip.positions()) << file;
      EXPECT_EQ(pieces->warnings, whole->warnings) << file;
    }
  }
}

}  // namespace
}  // namespace motiondb
