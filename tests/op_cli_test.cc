// `motiondb op` (issue 16), run as a user would run it against a real server: each command's
// help, its result written with -o and kept with --store (provenance shown by `clip show`), the
// figures each prints, and the server's complaints told in the command's own words.

#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "testing/server_process.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using testing::RunCli;

constexpr int kFrames = 90;  // per clip, at 30 fps

class OpCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir("op_cli_test");
    std::string error;
    ASSERT_TRUE(server_.Start({"--db", (dir_ / "motiondb.sqlite").string()}, &error)) << error;
    ASSERT_TRUE(testing::WaitUntilServing(testing::InsecureChannel(server_.address()), ""));
    const auto skeleton = testing::HumanoidSkeleton(/*still_root=*/false);
    for (int seed = 1; seed <= 2; ++seed) {
      const std::string path = (dir_ / ("take" + std::to_string(seed) + ".bvh")).string();
      ASSERT_TRUE(WriteBvhFile(path, testing::SyntheticClip(
                                         skeleton, {.frames = kFrames, .fps = 30, .seed = seed}))
                      .ok());
      const testing::CommandResult ingest = Remote({"ingest", path, "--json"});
      ASSERT_EQ(ingest.exit_code, 0) << ingest.err;
      ids_.push_back(
          std::to_string(nlohmann::json::parse(ingest.out)["ingested"][0]["clip_id"].get<int>()));
    }
    const testing::CommandResult space = Remote({"space", "create", "body", "--rate", "30"});
    ASSERT_EQ(space.exit_code, 0) << space.err;
  }
  void TearDown() override {
    if (HasFailure()) std::cerr << "---- server log ----\n" << server_.Log();
    server_.Stop(SIGTERM);
    std::filesystem::remove_all(dir_);
  }

  testing::CommandResult Remote(std::vector<std::string> args) {
    args.insert(args.end(), {"--server", server_.address()});
    return RunCli(args);
  }
  // Runs an op command that must succeed, with --json, and returns its output.
  nlohmann::json Json(std::vector<std::string> args) {
    args.push_back("--json");
    const testing::CommandResult r = Remote(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return r.exit_code == 0 ? nlohmann::json::parse(r.out) : nlohmann::json::object();
  }
  int Frames(const std::string& path) {
    absl::StatusOr<BvhReadResult> read = ReadBvhFile(path);
    EXPECT_TRUE(read.ok()) << read.status();
    return read.ok() ? read->clip.frame_count() : -1;
  }
  std::string Path(const std::string& name) { return (dir_ / name).string(); }

  std::filesystem::path dir_;
  testing::ServerProcess server_;
  std::vector<std::string> ids_;
};

TEST_F(OpCliTest, EveryOperatorHasHelpAndTheGroupAsksForOne) {
  for (const std::string command :
       {"reconstruct", "interpolate", "blend", "fill-gap", "scale", "translate", "smooth"}) {
    const testing::CommandResult help = RunCli({"op", command, "--help"});
    EXPECT_EQ(help.exit_code, 0) << command;
    EXPECT_THAT(help.out, HasSubstr("--space")) << command;
    EXPECT_THAT(help.out, HasSubstr("--store")) << command;
    EXPECT_THAT(help.out, HasSubstr("-o,--out")) << command;
    EXPECT_EQ(RunCli({"help", "op", command}).out, help.out) << command;
  }
  EXPECT_THAT(RunCli({"op", "scale", "--help"}).out, HasSubstr("--gate"));
  EXPECT_THAT(RunCli({"op", "smooth", "--help"}).out, HasSubstr("--freeze"));
  for (const std::string command : {"fit", "run", "list", "delete"}) {
    EXPECT_EQ(RunCli({"op", "detect", command, "--help"}).exit_code, 0) << command;
  }
  const testing::CommandResult bare = RunCli({"op"});
  EXPECT_EQ(bare.exit_code, 2);
  EXPECT_THAT(bare.err, HasSubstr("reconstruct"));
  // A malformed clip range is a usage error, before any server is asked.
  const testing::CommandResult bad = RunCli({"op", "smooth", "12:x", "--space", "body"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.err, HasSubstr("12:x"));
}

TEST_F(OpCliTest, SmoothWritesAndStoresAClipThatShowsWhereItCameFrom) {
  const std::string out = Path("calm.bvh");
  const testing::CommandResult r = Remote({"op", "smooth", ids_[0] + ":10-69", "--space", "body",
                                           "--level", "0.5", "--store", "calm", "-o", out});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("60 frames at 30 fps"));
  EXPECT_THAT(r.out, HasSubstr("stored as clip"));
  EXPECT_EQ(Frames(out), 60);
  const nlohmann::json clips = Json({"clips"});
  ASSERT_EQ(clips["clips"].size(), 3u);
  const std::string stored = std::to_string(clips["clips"][2]["clip_id"].get<int>());
  const testing::CommandResult show = Remote({"clip", "show", stored});
  EXPECT_THAT(show.out,
              HasSubstr("made by:  smooth in space body from clip " + ids_[0] + " frames 10-69"));
  EXPECT_THAT(show.out, HasSubstr("\"level\":0.5"));
  const nlohmann::json shown = Json({"clip", "show", stored});
  EXPECT_EQ(shown["provenance"]["operator"], "smooth");
  EXPECT_EQ(shown["provenance"]["parameters"]["level"], 0.5);
  // Exported like any clip.
  EXPECT_EQ(Remote({"export", stored, "-o", Path("again.bvh")}).exit_code, 0);
  EXPECT_EQ(Frames(Path("again.bvh")), 60);
  // The same name again: refused, nothing stored.
  const testing::CommandResult taken =
      Remote({"op", "smooth", ids_[0], "--space", "body", "--store", "calm"});
  EXPECT_EQ(taken.exit_code, 1);
  EXPECT_THAT(taken.err, HasSubstr("--store: a clip named 'calm' already exists"));
  EXPECT_EQ(Json({"clips"})["clips"].size(), 3u);
}

TEST_F(OpCliTest, EachOperatorRunsAndPrintsItsFigures) {
  const std::string a = ids_[0], b = ids_[1];
  const nlohmann::json rebuilt =
      Json({"op", "reconstruct", a, "--space", "body", "--dims", "5", "--curve"});
  EXPECT_EQ(rebuilt["dims"], 5);
  EXPECT_EQ(rebuilt["frames"], kFrames);
  EXPECT_LT(rebuilt["curve"].back()["max_rad"].get<double>(), 1e-6);

  const nlohmann::json between =
      Json({"op", "interpolate", a + ":10", b + ":40-60", "--space", "body", "--steps", "3",
            "--other-out", Path("slerp.bvh"), "-o", Path("lerp.bvh")});
  EXPECT_EQ(between["steps"].size(), 3u);
  EXPECT_EQ(Frames(Path("lerp.bvh")), 3);
  EXPECT_EQ(Frames(Path("slerp.bvh")), 3);

  const nlohmann::json blended =
      Json({"op", "blend", "--space", "body", "--pose", a + ":20@0,0", "--pose", b + ":50@1,0",
            "--path", "0,0", "--path", "1,0", "--frames-per-segment", "4"});
  ASSERT_EQ(blended["weights"].size(), 5u);
  EXPECT_NEAR(blended["weights"][2][0].get<double>(), 0.5, 1e-9);

  const nlohmann::json gap =
      Json({"op", "fill-gap", a + ":0-40", b + ":30-89", "--space", "body", "--gap", "0.4"});
  EXPECT_EQ(gap["transition_frames"], 12);
  EXPECT_EQ(gap["frames"], 41 + 12 + 60);
  EXPECT_EQ(gap["seams"].size(), 2u);
  const nlohmann::json overlap =
      Json({"op", "fill-gap", a + ":0-40", a + ":30-89", "--space", "body", "--overlap", "0.3"});
  EXPECT_EQ(overlap["transition_frames"], 9);

  EXPECT_EQ(
      Json({"op", "scale", a, "--space", "body", "--factor", "1.5", "--gate", "1,2", "--lead-in",
            "0.2", "--lead-out", "0.2", "--about", "mean", "--freeze", "Head"})["frames"],
      kFrames);
  EXPECT_EQ(Json({"op", "translate", a, "--space", "body", "--toward", b + ":45", "--amount", "0.3",
                  "--max-angle", "Head=0.2"})["frames"],
            kFrames);

  const nlohmann::json model = Json({"op", "detect", "fit", "still", "--space", "body", "--example",
                                     a + ":40-50", "--components", "1"});
  EXPECT_EQ(model["dims"], 3);
  const nlohmann::json found = Json({"op", "detect", "run", "still", a, "--curve"});
  ASSERT_GE(found["intervals"].size(), 1u);
  EXPECT_EQ(found["log_likelihood"].size(), static_cast<size_t>(kFrames));
  EXPECT_EQ(Json({"op", "detect", "list"})["models"].size(), 1u);
  EXPECT_EQ(Remote({"op", "detect", "delete", "still"}).exit_code, 0);
  EXPECT_EQ(Json({"op", "detect", "list"})["models"].size(), 0u);
}

TEST_F(OpCliTest, TheServersComplaintsNameTheArgumentsAndFlags) {
  const std::string a = ids_[0];
  const testing::CommandResult past =
      Remote({"op", "smooth", a + ":0-999", "--space", "body", "--store", "never"});
  EXPECT_EQ(past.exit_code, 1);
  EXPECT_THAT(past.err, HasSubstr(a + ":0-999: frame 999 is past the clip's last frame 89"));
  const testing::CommandResult dims =
      Remote({"op", "scale", a, "--space", "body", "--only-dims", "0,900"});
  EXPECT_THAT(dims.err, HasSubstr("--only-dims 900 is out of range"));
  EXPECT_THAT(dims.err, Not(HasSubstr("dims[1]")));
  const testing::CommandResult level =
      Remote({"op", "smooth", a, "--space", "body", "--level", "-1"});
  EXPECT_THAT(level.err, HasSubstr("--level -1 is out of range"));
  const testing::CommandResult joint =
      Remote({"op", "smooth", a, "--space", "body", "--joint-weight", "Tail=0.5"});
  EXPECT_THAT(joint.err, HasSubstr("--joint-weight Tail: the skeleton has no such joint"));
  const testing::CommandResult both = Remote(
      {"op", "translate", a, "--space", "body", "--toward", a + ":3", "--axis-from", a + ":4"});
  EXPECT_THAT(both.err, HasSubstr("--toward"));
  const testing::CommandResult space = Remote({"op", "smooth", a, "--space", "nowhere"});
  EXPECT_THAT(space.err, HasSubstr("NOT_FOUND: no space named 'nowhere'"));
  const testing::CommandResult model = Remote({"op", "detect", "run", "nothing", a});
  EXPECT_THAT(model.err, HasSubstr("NOT_FOUND: no pose model named 'nothing'"));
  EXPECT_EQ(Json({"clips"})["clips"].size(), 2u);
}

TEST_F(OpCliTest, NonFiniteNumbersAndTheOperatorsLimitsAreToldInFlags) {
  const std::string a = ids_[0], b = ids_[1];
  for (const std::string point : {"nan,0", "0,inf", "-inf,1"}) {
    const testing::CommandResult pose =
        Remote({"op", "blend", "--space", "body", "--pose", a + ":20@" + point, "--pose",
                b + ":50@1,0", "--path", "0,0"});
    EXPECT_NE(pose.exit_code, 0);
    EXPECT_THAT(pose.err, HasSubstr("--pose: expected X,Y (two finite numbers), got '" + point));
    const testing::CommandResult path =
        Remote({"op", "blend", "--space", "body", "--pose", a + ":20@0,0", "--path", point});
    EXPECT_NE(path.exit_code, 0);
    EXPECT_THAT(path.err, HasSubstr("--path: expected X,Y (two finite numbers), got '" + point));
  }
  const testing::CommandResult overlap =
      Remote({"op", "fill-gap", a + ":0-10", b, "--space", "body", "--overlap", "1"});
  EXPECT_THAT(overlap.err, HasSubstr("--overlap 1 is out of range"));
  EXPECT_THAT(overlap.err, Not(HasSubstr("overlap_frames")));
  // The warp's slope limit, as the API has it.
  EXPECT_EQ(Json({"op", "fill-gap", a + ":0-40", a + ":30-89", "--space", "body", "--overlap",
                  "0.3", "--slope-limit", "1"})["transition_frames"],
            9);
  const testing::CommandResult slope =
      Remote({"op", "fill-gap", a + ":0-40", a + ":30-89", "--space", "body", "--overlap", "0.3",
              "--slope-limit", "9"});
  EXPECT_THAT(slope.err, HasSubstr("--slope-limit 9 is out of range"));
  const testing::CommandResult gate =
      Remote({"op", "scale", a, "--space", "body", "--gate", "2,1"});
  EXPECT_THAT(gate.err, HasSubstr("--gate T1 1 is out of range"));
  const testing::CommandResult axis = Remote({"op", "translate", a, "--space", "body",
                                              "--axis-from", a + ":3", "--axis-to", b + ":0-900"});
  EXPECT_THAT(axis.err, HasSubstr(b + ":0-900: frame 900 is past the clip's last frame 89"));
  const testing::CommandResult pose =
      Remote({"op", "blend", "--space", "body", "--pose", a + ":20@0,0", "--pose", b + ":95@1,0",
              "--path", "0,0"});
  EXPECT_THAT(pose.err, HasSubstr(b + ":95@1,0: frame 95 is past the clip's last frame 89"));
  EXPECT_EQ(Json({"clips"})["clips"].size(), 2u);
}

}  // namespace
}  // namespace motiondb
