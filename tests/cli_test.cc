// The motiondb CLI's offline commands, run as a user would run them.
#include <fstream>
#include <regex>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "tests/clip_builder.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using testing::RunCli;

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(::testing::TempDir()) /
           ("cli_test_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::create_directories(dir_);
    // 61 frames at 30 fps: two seconds of a slow turn.
    const Clip clip = testing::MakeClip(
        testing::ChainSkeleton(), 61, 1.0 / 30,
        [](int f, int j) {
          return Quat(Eigen::AngleAxisd(0.02 * f * (j + 1), Eigen::Vector3d::UnitY()));
        },
        [](int f, int) { return Eigen::Vector3d(0.1 * f, 90, 0); });
    walk_ = (dir_ / "walk.bvh").string();
    ASSERT_TRUE(WriteBvhFile(walk_, clip).ok());
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string WriteText(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  std::filesystem::path dir_;
  std::string walk_;
};

TEST_F(CliTest, InspectJsonHasOneObjectPerFileWithTheDocumentedKeys) {
  const testing::CommandResult r = RunCli({"inspect", walk_, walk_, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  int objects = 0;
  while (std::getline(lines, line)) {
    const nlohmann::json info = nlohmann::json::parse(line);
    EXPECT_EQ(info["file"], walk_);
    EXPECT_EQ(info["joint_count"], 3);
    EXPECT_EQ(info["joints"], nlohmann::json({"root", "child", "leaf"}));
    EXPECT_EQ(info["frames"], 61);
    EXPECT_NEAR(info["fps"].get<double>(), 30.0, 1e-9);
    EXPECT_NEAR(info["duration_s"].get<double>(), 61.0 / 30, 1e-9);
    EXPECT_TRUE(info["warnings"].is_array());
    EXPECT_TRUE(info["warnings"].empty());
    ++objects;
  }
  EXPECT_EQ(objects, 2);
}

TEST_F(CliTest, InspectTextAndWarnings) {
  std::ifstream in(walk_);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string mismatched =
      WriteText("mismatch.bvh", std::regex_replace(text, std::regex("Frames: 61"), "Frames: 70"));
  const testing::CommandResult r = RunCli({"inspect", mismatched});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("frames:   61"));
  EXPECT_THAT(r.out, HasSubstr("Frames: 70"));
  const testing::CommandResult json = RunCli({"inspect", "--json", mismatched});
  EXPECT_EQ(nlohmann::json::parse(json.out)["warnings"].size(), 1u);
}

TEST_F(CliTest, InspectNamesTheFileAndLineOfABadFileAndKeepsGoing) {
  const std::string bad = WriteText("bad.bvh", "HIERARCHY\nROOT a\n{\nOFFSET 0 0\n");
  const testing::CommandResult r = RunCli({"inspect", "--json", bad, walk_});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr(bad + ": line 5"));
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line per failed file";
  EXPECT_THAT(r.out, HasSubstr("\"frames\":61"));  // the good file is still described
  EXPECT_NE(RunCli({"inspect", "/nonexistent.bvh"}).exit_code, 0);
  EXPECT_NE(RunCli({"inspect"}).exit_code, 0);
  EXPECT_NE(RunCli({"inspect", walk_, "--bogus"}).exit_code, 0);
}

TEST_F(CliTest, ConvertCutsAndResamples) {
  const std::string out = (dir_ / "out.bvh").string();
  testing::CommandResult r = RunCli({"convert", walk_, out, "--from", "10", "--to", "40"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  absl::StatusOr<BvhReadResult> cut = ReadBvhFile(out);
  ASSERT_TRUE(cut.ok()) << cut.status();
  EXPECT_EQ(cut->clip.frame_count(), 31);
  absl::StatusOr<BvhReadResult> original = ReadBvhFile(walk_);
  EXPECT_LT(AngleBetween(cut->clip.rotation(0, 2), original->clip.rotation(10, 2)), 1e-6);

  r = RunCli({"convert", walk_, out, "--fps", "120"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  absl::StatusOr<BvhReadResult> fine = ReadBvhFile(out);
  ASSERT_TRUE(fine.ok());
  EXPECT_EQ(fine->clip.frame_count(), 241);
  EXPECT_NEAR(fine->clip.fps(), 120.0, 1e-9);
  EXPECT_LT(AngleBetween(fine->clip.rotation(4, 1), original->clip.rotation(1, 1)), 1e-6);

  r = RunCli({"convert", walk_, out, "--from=30", "--fps=60"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(ReadBvhFile(out)->clip.frame_count(), 61);
}

TEST_F(CliTest, ConvertRejectsBadArgumentsAndWritesNothing) {
  const std::string out = (dir_ / "never.bvh").string();
  for (const std::vector<std::string>& args :
       std::vector<std::vector<std::string>>{{"convert", walk_, out, "--from", "50", "--to", "70"},
                                             {"convert", walk_, out, "--from", "20", "--to", "10"},
                                             {"convert", walk_, out, "--fps", "0"},
                                             {"convert", walk_, out, "--fps", "abc"},
                                             {"convert", walk_, out, "--from", "1.5"},
                                             {"convert", walk_},
                                             {"convert", "/nonexistent.bvh", out}}) {
    const testing::CommandResult r = RunCli(args);
    EXPECT_NE(r.exit_code, 0) << args.back();
    EXPECT_THAT(r.err, HasSubstr("motiondb convert: "));
    EXPECT_FALSE(std::filesystem::exists(out)) << args.back();
  }
}

TEST_F(CliTest, UnknownCommandAndHelp) {
  EXPECT_EQ(RunCli({"frobnicate"}).exit_code, 2);
  const testing::CommandResult help = RunCli({"help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_THAT(help.out, HasSubstr("inspect"));
}

TEST(CliAssimp, InspectsDebianTestModels) {
  const auto dir = testing::AssimpBvhDir();
  if (!dir) GTEST_SKIP() << "assimp-testmodels is not installed; skipped";
  const testing::CommandResult r = RunCli({"inspect", "--json", (*dir / "01_01.bvh").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json info = nlohmann::json::parse(r.out);
  EXPECT_EQ(info["joint_count"], 31);
  EXPECT_EQ(info["frames"], 2752);
}

}  // namespace
}  // namespace motiondb
