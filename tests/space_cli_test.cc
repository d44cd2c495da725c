// `motiondb space build` and `motiondb project`, run as a user would run them.
#include <fstream>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "core/space/space_serialization.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using testing::RunCli;

constexpr int kJoints = 20;  // testing::HumanoidSkeleton(/*still_root=*/true)

std::vector<std::string> Lines(const std::string& text) {
  return absl::StrSplit(text, '\n', absl::SkipEmpty());
}

class SpaceCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir("space_cli_test");
    const auto skeleton = testing::HumanoidSkeleton(/*still_root=*/true);
    // 120 frames at 60 fps each: 60 samples at the default 30 Hz.
    a_ = Write("a.bvh", testing::SyntheticClip(skeleton, {.turn_rate = 0.5, .seed = 1}));
    b_ = Write("b.bvh", testing::SyntheticClip(skeleton, {.seed = 2}));
    other_ = Write("other.bvh", testing::SyntheticClip(testing::HumanoidSkeleton(false)));
    space_ = (dir_ / "space.mcs").string();
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string Write(const std::string& name, const Clip& clip) {
    const std::string path = (dir_ / name).string();
    EXPECT_TRUE(WriteBvhFile(path, clip).ok());
    return path;
  }
  std::string WriteText(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  // Runs `space build` expecting success and returns its --json report.
  nlohmann::json BuildJson(std::vector<std::string> args) {
    args.insert(args.begin(), {"space", "build"});
    args.push_back("--json");
    const testing::CommandResult r = RunCli(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(r.out, nullptr, /*allow_exceptions=*/false);
  }

  std::filesystem::path dir_;
  std::string a_, b_, other_, space_;
};

TEST_F(SpaceCliTest, BuildReportsDimsVarianceAndErrors) {
  const nlohmann::json report = BuildJson({"--train", a_, b_, "--out", space_});
  ASSERT_TRUE(report.is_object());
  const int dims = report["dims"];
  EXPECT_EQ(dims, 3 * kJoints + 3);
  ASSERT_EQ(report["explained_variance"].size(), static_cast<size_t>(dims));
  double total = 0.0;
  for (const double share : report["explained_variance"]) total += share;
  EXPECT_NEAR(total, 1.0, 1e-9);
  const nlohmann::json& errors = report["reconstruction_error"];
  ASSERT_EQ(errors.size(), 5u);
  int previous = 0;
  for (const nlohmann::json& level : errors) {
    EXPECT_GT(level["dims"].get<int>(), previous);
    previous = level["dims"];
    EXPECT_GE(level["max_rad"].get<double>(), level["mean_rad"].get<double>());
  }
  EXPECT_EQ(errors.back()["dims"], dims);
  EXPECT_LT(errors.back()["max_rad"].get<double>(), 1e-6);
  EXPECT_GT(errors.front()["mean_rad"].get<double>(), errors.back()["mean_rad"].get<double>());
  EXPECT_EQ(report["pelvis"], "Hips");
  EXPECT_EQ(report["heading_removed"], true);
  EXPECT_EQ(report["training_ranges"], 2);

  // The file holds the same space.
  const absl::StatusOr<MotionSpace> space = ReadSpaceFile(space_);
  ASSERT_TRUE(space.ok()) << space.status();
  EXPECT_EQ(space->dims(), dims);
  EXPECT_NEAR(space->ExplainedVariance()[0], report["explained_variance"][0].get<double>(), 1e-12);

  // The text report says the same in words.
  const testing::CommandResult text =
      RunCli({"space", "build", "--train", a_, "--train=" + b_, "--out", space_});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_THAT(text.out, HasSubstr("dims:     63"));
  EXPECT_THAT(text.out, HasSubstr("reconstruction error"));
}

TEST_F(SpaceCliTest, BuildOptions) {
  const nlohmann::json kept = BuildJson({"--train", a_ + ":10-100", "--out", space_,
                                         "--keep-heading", "--rate", "20", "--weights", "uniform"});
  EXPECT_EQ(kept["dims"], 3 * kJoints);
  EXPECT_EQ(kept["sample_rate"], 20.0);
  EXPECT_EQ(kept["joint_weights"]["Hand_L"], 1.0);
  const MotionSpace space = *ReadSpaceFile(space_);
  EXPECT_EQ(space.data().training[0].frames.first, 10);
  EXPECT_EQ(space.data().training[0].frames.last, 100);

  const std::string weights = WriteText("legs.json", R"({"UpperLeg_L": 4, "UpperLeg_R": 4})");
  const nlohmann::json heavy = BuildJson(
      {"--train", a_, "--out", space_, "--weights", weights, "--yaw-rate-weight", "0.25"});
  EXPECT_EQ(heavy["joint_weights"]["UpperLeg_L"], 4.0);
  EXPECT_EQ(heavy["joint_weights"]["Hips"], 1.0);  // the mass preset elsewhere
  EXPECT_EQ(heavy["yaw_rate_weight"], 0.25);
  EXPECT_EQ(heavy["root_velocity_weight"], 0.5);  // the default

  const nlohmann::json fast =
      BuildJson({"--train", a_, "--out", space_, "--root-velocity-weight", "2.5"});
  EXPECT_EQ(fast["root_velocity_weight"], 2.5);
  EXPECT_EQ(fast["dims"], 3 * kJoints + 3);
  const nlohmann::json still =
      BuildJson({"--train", a_, "--out", space_, "--root-velocity-weight", "0"});
  EXPECT_EQ(still["root_velocity_weight"], 0.0);
  EXPECT_EQ(still["dims"], 3 * kJoints + 1);
}

TEST_F(SpaceCliTest, ProjectPrintsOneLinePerFrameAtTheSpaceRate) {
  ASSERT_EQ(RunCli({"space", "build", "--train", a_, b_, "--out", space_}).exit_code, 0);
  const MotionSpace space = *ReadSpaceFile(space_);
  const RowMatrixXd expected = *space.ProjectClip(ReadBvhFile(a_)->clip, 5);

  const testing::CommandResult plain = RunCli({"project", a_, "--space", space_});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const std::vector<std::string> lines = Lines(plain.out);
  ASSERT_EQ(lines.size(), 1u + 60u);  // a comment, then 120 frames at 60 fps -> 60 at 30 Hz
  EXPECT_EQ(lines[0][0], '#');
  const std::vector<std::string> fields = absl::StrSplit(lines[3], ' ');
  ASSERT_EQ(fields.size(), 2u + 3u);
  EXPECT_EQ(fields[0], "2");
  EXPECT_EQ(fields[1], "0.066667");

  const testing::CommandResult csv =
      RunCli({"project", a_, "--space", space_, "--dims", "5", "--csv"});
  ASSERT_EQ(csv.exit_code, 0) << csv.err;
  const std::vector<std::string> rows = Lines(csv.out);
  ASSERT_EQ(rows.size(), 1u + 60u);
  EXPECT_EQ(rows[0], "frame,time_s,c0,c1,c2,c3,c4");
  for (size_t f = 0; f < 60; ++f) {
    const std::vector<std::string> cells = absl::StrSplit(rows[f + 1], ',');
    ASSERT_EQ(cells.size(), 7u);
    for (int i = 0; i < 5; ++i) {
      double value = 0;
      ASSERT_TRUE(absl::SimpleAtod(cells[2 + i], &value));
      EXPECT_NEAR(value, expected(f, i), 1e-7 * (1 + std::abs(expected(f, i))));
    }
  }
}

TEST_F(SpaceCliTest, BadInputIsOneLineNamingTheFile) {
  ASSERT_EQ(RunCli({"space", "build", "--train", a_, "--out", space_}).exit_code, 0);
  const std::string missing = (dir_ / "missing.bvh").string();
  const std::string garbage = WriteText("garbage.bvh", "HIERARCHY\nROOT\n");
  const std::string bad_json = WriteText("bad.json", R"({"UpperLeg_L": -1})");
  const std::string tail_json = WriteText("tail.json", R"({"Tail": 2})");
  const std::string bad_space = WriteText("bad.mcs", "MDBSPACE but not really");
  const struct {
    std::vector<std::string> args;
    std::string message;
  } cases[] = {
      {{"space", "build", "--train", missing, "--out", space_}, "missing.bvh"},
      {{"space", "build", "--train", garbage, "--out", space_}, "garbage.bvh"},
      {{"space", "build", "--train", a_, other_, "--out", space_}, "other.bvh: skeleton differs"},
      {{"space", "build", "--train", a_ + ":50-500", "--out", space_}, "a.bvh:50-500: frame range"},
      {{"space", "build", "--train", a_ + ":9-", "--out", space_}, "FROM-TO"},
      {{"space", "build", "--train", a_, "--out", space_, "--weights", bad_json}, "bad.json"},
      {{"space", "build", "--train", a_, "--out", space_, "--weights", tail_json},
       "tail.json: weight given for unknown joint 'Tail'"},
      {{"project", a_, "--space", bad_space}, "bad.mcs"},
      {{"project", other_, "--space", space_}, "other.bvh"},
      {{"project", a_, "--space", space_, "--dims", "64"}, "--dims must be in 1..63"},
  };
  for (const auto& c : cases) {
    const testing::CommandResult r = RunCli(c.args);
    EXPECT_EQ(r.exit_code, 1) << c.message;
    EXPECT_THAT(r.err, HasSubstr(c.message));
    EXPECT_EQ(Lines(r.err).size(), 1u) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

TEST_F(SpaceCliTest, UsageErrorsNameTheFlagAndPointToTheHelp) {
  ASSERT_EQ(RunCli({"space", "build", "--train", a_, "--out", space_}).exit_code, 0);
  const struct {
    std::vector<std::string> args;
    std::string message;
  } cases[] = {
      {{"space", "build", "--train", a_, "--out", space_, "--weights", "heavy"}, "'heavy'"},
      {{"space", "build", "--train", a_, "--out", space_, "--rate", "0"}, "--rate: must be"},
      {{"space", "build", "--train", a_, "--out", space_, "--metric", "cosine"}, "cosine"},
      {{"space", "build", "--out", space_}, "--train is required"},
      {{"space", "build", "--train", a_}, "--out is required"},
      {{"space", "build", "--train", a_, "--out", space_, "--bogus"}, "unknown option --bogus"},
      {{"project", (dir_ / "missing.bvh").string(), "--space", space_}, "missing.bvh"},
      {{"project", a_, "--space", (dir_ / "none.mcs").string()}, "none.mcs"},
      {{"project", a_, "--space", space_, "--dims", "0"}, "--dims: must be at least 1"},
      {{"project", a_}, "--space is required"},
  };
  for (const auto& c : cases) {
    const testing::CommandResult r = RunCli(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.message;
    const std::string command = c.args[0] == "project" ? "project" : "space build";
    EXPECT_THAT(r.err, HasSubstr("motiondb " + command + ": "));
    EXPECT_THAT(r.err, HasSubstr(c.message));
    EXPECT_THAT(r.err, HasSubstr("run 'motiondb " + command + " --help'"));
    EXPECT_EQ(Lines(r.err).size(), 2u) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

TEST_F(SpaceCliTest, HelpListsEveryFlagWithItsDefault) {
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"space", "build", "--help"}, {"help", "space", "build"}}) {
    const testing::CommandResult r = RunCli(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const char* flag : {"--train FILE[:FROM-TO]", "--out SPACE.mcs", "--rate R=30",
                             "--weights mass|uniform|FILE.json=mass", "--yaw-rate-weight W=0.5",
                             "--metric unit|eigen=unit", "--keep-heading", "--json"}) {
      EXPECT_THAT(r.out, HasSubstr(flag)) << args.back();
    }
  }
}

}  // namespace
}  // namespace motiondb
