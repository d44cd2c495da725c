// The motiondb CLI, run as a user would run it: the offline commands, the command-line
// conventions (help, version, usage errors), and the server commands against a real server.
#include <stdlib.h>

#include <fstream>
#include <regex>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "storage/sqlite_connection.h"
#include "testing/server_process.h"
#include "tests/clip_builder.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using testing::RunCli;

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir("cli_test");
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
  const testing::CommandResult unknown = RunCli({"frobnicate"});
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_THAT(unknown.err, HasSubstr("unknown command 'frobnicate'"));
  EXPECT_EQ(RunCli({}).exit_code, 2);
  const testing::CommandResult help = RunCli({"help"});
  EXPECT_EQ(help.exit_code, 0);
  for (const char* command :
       {"inspect", "convert", "project", "ingest", "clips", "clip", "export", "space", "search",
        "label", "labels", "propagate", "jobs", "job", "info", "help"}) {
    EXPECT_THAT(help.out, HasSubstr(std::string("\n  ") + command + " ")) << command;
  }
  EXPECT_EQ(RunCli({"--help"}).out, help.out);
  EXPECT_EQ(RunCli({"help", "frobnicate"}).exit_code, 2);
}

TEST_F(CliTest, VersionIsTheProjectVersion) {
  const testing::CommandResult r = RunCli({"--version"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_TRUE(std::regex_match(r.out, std::regex("motiondb [0-9]+\\.[0-9]+\\.[0-9]+\n"))) << r.out;
}

TEST_F(CliTest, HelpSearchAndSearchHelpListEveryFlagWithItsDefault) {
  const testing::CommandResult help = RunCli({"help", "search"});
  const testing::CommandResult flag = RunCli({"search", "--help"});
  ASSERT_EQ(help.exit_code, 0) << help.err;
  ASSERT_EQ(flag.exit_code, 0) << flag.err;
  EXPECT_EQ(help.out, flag.out);
  EXPECT_THAT(help.out, HasSubstr("Usage: motiondb search [OPTIONS]"));
  for (const char* listed : {"--space NAME",
                             "--clip ID",
                             "--bvh FILE",
                             "--from F=0",
                             "--to T=last",
                             "--seeds frames|places|windows|shapes=frames",
                             "--shape-windows N=200",
                             "--shape-clips N=300",
                             "--shape-lengths N=2",
                             "--places N=128",
                             "--neighbours K=0",
                             "--threads N=0 = auto",
                             "--ann-dims N=5",
                             "--dtw-dims N=5",
                             "--slope S=2",
                             "--max N=20",
                             "--epsilon E=0",
                             "--char-frame F=auto",
                             "--char-frames F,F,...",
                             "--points K=1",
                             "--max-point-gap S=10",
                             "--second-anchor S=0.5",
                             "--neutral mean|boundary|origin=mean",
                             "--exact",
                             "--no-refine",
                             "--exclude-query,--include-query{false}=exclude",
                             "--path",
                             "--in-clip ID",
                             "--tag T",
                             "--server ADDR=127.0.0.1:50051",
                             "--token T",
                             "--token-file FILE",
                             "--tls-ca FILE",
                             "--timeout S=600",
                             "--json"}) {
    EXPECT_THAT(help.out, HasSubstr(listed));
  }
  // Two-word commands too, through either door.
  const testing::CommandResult create = RunCli({"help", "space", "create"});
  ASSERT_EQ(create.exit_code, 0);
  EXPECT_EQ(create.out, RunCli({"space", "create", "--help"}).out);
  for (const char* listed : {"Usage: motiondb space create [OPTIONS] NAME", "--skeleton ID",
                             "--yaw-rate-weight W=0.5", "--train CLIP_ID[:FROM-TO]"}) {
    EXPECT_THAT(create.out, HasSubstr(listed));
  }
}

TEST_F(CliTest, UsageErrorsAreOneLineAndAHintAndExit2) {
  const struct {
    std::vector<std::string> args;
    std::string command;
    std::string message;
  } cases[] = {
      {{"search", "--space", "s", "--clip", "1", "--bogus"}, "search", "unknown option --bogus"},
      {{"--bogus", "clips"}, "", "unknown option --bogus"},
      {{"search", "--space", "s", "--clip", "1", "--max", "0"},
       "search",
       "--max: must be at least 1, got 0"},
      {{"search", "--space", "s", "--clip", "x"}, "search", "--clip: expected a whole number"},
      {{"search", "--space", "s"}, "search", "give exactly one of --clip ID and --bvh FILE"},
      {{"search", "--clip", "1"}, "search", "--space is required"},
      {{"clips", "--timeout", "0"}, "clips", "--timeout: must be greater than 0"},
      {{"space", "create"}, "space create", "NAME is required"},
      {{"clip", "show", "1", "2"}, "clip show", "unexpected argument '2'"},
      {{"info", "--token-file", "/nonexistent/token"}, "info", "--token-file"},
      {{"inspect", walk_, "--bogus"}, "inspect", "unknown option --bogus"},
  };
  for (const auto& c : cases) {
    const testing::CommandResult r = RunCli(c.args);
    const std::string command = c.command.empty() ? "motiondb" : "motiondb " + c.command;
    EXPECT_EQ(r.exit_code, 2) << c.message;
    EXPECT_THAT(r.err, HasSubstr(command + ": " + c.message));
    EXPECT_THAT(r.err, HasSubstr("\nrun '" + command + " --help' for usage\n"));
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

// Sets an environment variable for the commands a test runs; restores its absence after.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() { ::unsetenv(name_); }

 private:
  const char* name_;
};

// The server commands against the real motiondb-server, on a temporary database holding one
// 54-frame clip (30 fps) and a space "body" over it.
class CliServerTest : public CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    ::unsetenv("MOTIONDB_TOKEN");
    ::unsetenv("MOTIONDB_TOKEN_FILE");
    ASSERT_TRUE(StartServer(&server_, {"--db", (dir_ / "motiondb.sqlite").string()}, ""));
    Clip clip = testing::SyntheticClip(testing::HumanoidSkeleton(false),
                                       {.frames = kFrames, .fps = 30, .seed = 3});
    const std::string path = (dir_ / "walk54.bvh").string();
    ASSERT_TRUE(WriteBvhFile(path, clip).ok());
    const testing::CommandResult ingest = Remote({"ingest", path, "--json"});
    ASSERT_EQ(ingest.exit_code, 0) << ingest.err;
    clip_id_ =
        std::to_string(nlohmann::json::parse(ingest.out)["ingested"][0]["clip_id"].get<int>());
    const testing::CommandResult space = Remote({"space", "create", "body"});
    ASSERT_EQ(space.exit_code, 0) << space.err;
  }
  void TearDown() override {
    if (HasFailure()) std::cerr << "---- server log ----\n" << server_.Log();
    CliTest::TearDown();
  }

  // Starts `server` with `args`, and waits until it serves (`token` authenticating the check).
  static bool StartServer(testing::ServerProcess* server, const std::vector<std::string>& args,
                          const std::string& token) {
    std::string error;
    if (!server->Start(args, &error)) {
      ADD_FAILURE() << error;
      return false;
    }
    return testing::WaitUntilServing(testing::InsecureChannel(server->address()), token);
  }
  // Runs a server command against this test's server.
  testing::CommandResult Remote(std::vector<std::string> args) {
    args.insert(args.end(), {"--server", server_.address()});
    return RunCli(args);
  }

  static constexpr int kFrames = 54;
  testing::ServerProcess server_;
  std::string clip_id_;
};

TEST_F(CliServerTest, GlobalOptionsGoBeforeOrAfterTheCommand) {
  const std::string address = server_.address();
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"--server", address, "clips", "--json"},
           {"clips", "--server", address, "--json"},
           {"--json", "--server=" + address, "--timeout", "30", "clips"},
           {"--timeout", "30", "clips", "--json", "--server", address},
           // The later of two wins.
           {"--server", "127.0.0.1:1", "clips", "--server", address, "--json"}}) {
    const testing::CommandResult r = RunCli(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json listed = nlohmann::json::parse(r.out);
    ASSERT_EQ(listed["clips"].size(), 1u) << r.out;
    EXPECT_EQ(std::to_string(listed["clips"][0]["clip_id"].get<int>()), clip_id_);
  }
  const testing::CommandResult two_words = RunCli({"--server", address, "space", "list", "--json"});
  ASSERT_EQ(two_words.exit_code, 0) << two_words.err;
  EXPECT_EQ(nlohmann::json::parse(two_words.out)["spaces"][0]["name"], "body");
}

TEST_F(CliServerTest, OutOfRangeFramesAreToldInTheFlagsThatSetThem) {
  const testing::CommandResult create =
      Remote({"space", "create", "arms", "--train", clip_id_ + ":0-400"});
  EXPECT_EQ(create.exit_code, 1);
  EXPECT_THAT(create.err, HasSubstr("motiondb space create: INVALID_ARGUMENT: --train " + clip_id_ +
                                    ":0-400: frame 400 is past the clip's last frame 53"));
  EXPECT_THAT(create.err, Not(HasSubstr("training[")));

  const testing::CommandResult search =
      Remote({"search", "--space", "body", "--clip", clip_id_, "--from", "40", "--to", "999"});
  EXPECT_EQ(search.exit_code, 1);
  EXPECT_THAT(search.err, HasSubstr("--to 999 is past the clip's last frame 53"));
  EXPECT_THAT(search.err, Not(HasSubstr("last_frame")));

  const testing::CommandResult from =
      Remote({"export", clip_id_, "--from", "60", "-o", (dir_ / "never.bvh").string()});
  EXPECT_EQ(from.exit_code, 1);
  EXPECT_THAT(from.err, HasSubstr("--from 60 is past the clip's last frame 53"));

  const testing::CommandResult dims =
      Remote({"search", "--space", "body", "--clip", clip_id_, "--ann-dims", "500"});
  EXPECT_EQ(dims.exit_code, 1);
  EXPECT_THAT(dims.err, HasSubstr("--ann-dims 500 is out of range"));
  EXPECT_THAT(dims.err, Not(HasSubstr("ann_dims")));
}

// backup writes the copy under its name only when it is whole, refuses to overwrite without
// --force, and a server started on the copy lists the same clip.
TEST_F(CliServerTest, BackupWritesACopyAServerStartsOn) {
  const std::string copy = (dir_ / "copy.sqlite").string();
  const testing::CommandResult r = Remote({"backup", copy});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("1 clips (54 frames), 1 spaces"));
  EXPECT_FALSE(std::filesystem::exists(copy + ".part"));
  const std::string first = testing::ReadFileOrDie(copy);

  const testing::CommandResult again = Remote({"backup", copy});
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_THAT(again.err, HasSubstr("exists; pass --force"));
  EXPECT_EQ(testing::ReadFileOrDie(copy), first);
  const testing::CommandResult forced = Remote({"backup", copy, "--force", "--json"});
  ASSERT_EQ(forced.exit_code, 0) << forced.err;
  const nlohmann::json summary = nlohmann::json::parse(forced.out);
  EXPECT_EQ(summary["clips"], 1);
  EXPECT_EQ(summary["bytes"], std::filesystem::file_size(copy));

  testing::ServerProcess restored;
  ASSERT_TRUE(StartServer(&restored, {"--db", copy}, ""));
  const testing::CommandResult clips = RunCli({"clips", "--json", "--server", restored.address()});
  ASSERT_EQ(clips.exit_code, 0) << clips.err;
  EXPECT_THAT(clips.out, HasSubstr("walk54"));
}

TEST_F(CliServerTest, SearchRowsShowTheClipId) {
  const testing::CommandResult r = Remote({"search", "--space", "body", "--clip", clip_id_,
                                           "--from", "10", "--to", "40", "--include-query"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("CLIP  NAME"));
  // The query finds itself first: rank, clip id, name, start and end (s), frames, score.
  EXPECT_TRUE(std::regex_search(
      r.out, std::regex("\n +1 +" + clip_id_ + " +walk54 +[0-9.]+ +[0-9.]+ +[0-9]+-[0-9]+ ")))
      << r.out;
}

// Every seed selection and a threaded exact search answer through the CLI; the query finds
// itself first in each. The server's range errors name the CLI's flags.
TEST_F(CliServerTest, SearchSeedsAndExactThreads) {
  for (const std::vector<std::string>& extra :
       {std::vector<std::string>{"--seeds", "places", "--places", "16"},
        {"--seeds", "frames", "--neighbours", "200"},
        {"--seeds", "windows", "--neighbours", "100"},
        {"--seeds", "shapes", "--shape-clips", "20", "--shape-lengths", "1"},
        {"--exact", "--threads", "2"},
        {"--char-frames", "15,35"},
        {"--points", "2", "--max-point-gap", "1"},
        {"--second-anchor", "0"}}) {
    std::vector<std::string> args = {"search", "--space",         "body",  "--clip",
                                     clip_id_, "--from",          "10",    "--to",
                                     "40",     "--include-query", "--json"};
    args.insert(args.end(), extra.begin(), extra.end());
    const testing::CommandResult r = Remote(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json found = nlohmann::json::parse(r.out);
    ASSERT_FALSE(found["results"].empty()) << r.out;
    EXPECT_EQ(found["results"][0]["start_frame"].get<int>(), 10) << extra[0] << " " << r.out;
  }
  const testing::CommandResult places = Remote(
      {"search", "--space", "body", "--clip", clip_id_, "--seeds", "places", "--places", "200000"});
  EXPECT_EQ(places.exit_code, 1);
  EXPECT_THAT(places.err, HasSubstr("--places 200000 is out of range; expected 1..100000"));
  const testing::CommandResult shapes = Remote({"search", "--space", "body", "--clip", clip_id_,
                                                "--seeds", "shapes", "--shape-lengths", "9"});
  EXPECT_EQ(shapes.exit_code, 1);
  EXPECT_THAT(shapes.err, HasSubstr("--shape-lengths 9 is out of range; expected 0..8"));
  const testing::CommandResult threads =
      Remote({"search", "--space", "body", "--clip", clip_id_, "--exact", "--threads", "5000"});
  EXPECT_EQ(threads.exit_code, 1);
  EXPECT_THAT(threads.err, HasSubstr("--threads 5000 is out of range"));
  const testing::CommandResult scatter =
      Remote({"search", "--space", "body", "--clip", clip_id_, "--second-anchor", "2"});
  EXPECT_EQ(scatter.exit_code, 1);
  EXPECT_THAT(scatter.err, HasSubstr("--second-anchor 2 is out of range; expected 0..1"));
  const testing::CommandResult frames =
      Remote({"search", "--space", "body", "--clip", clip_id_, "--char-frames", "30,20", "--json"});
  EXPECT_EQ(frames.exit_code, 1);
  EXPECT_THAT(frames.err, HasSubstr("--char-frames"));
  EXPECT_THAT(frames.err, HasSubstr("20 does not follow the frame before it, 30"));
}

TEST_F(CliServerTest, SearchLeavesOutTheQuerysOwnRangeUnlessAskedToKeepIt) {
  for (const bool include : {false, true}) {
    std::vector<std::string> args = {"search", "--space", "body", "--clip", clip_id_,
                                     "--from", "10",      "--to", "40",     "--json"};
    if (include) args.push_back("--include-query");
    const testing::CommandResult r = Remote(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    bool own = false;
    const nlohmann::json found = nlohmann::json::parse(r.out);
    for (const nlohmann::json& result : found["results"]) {
      own = own || (result["start_frame"].get<int>() <= 40 && result["end_frame"].get<int>() >= 10);
    }
    EXPECT_EQ(own, include) << r.out;
  }
}

TEST_F(CliServerTest, TokenFromAFileOrTheEnvironment) {
  const std::string token_file = WriteText("token", "  s3cret-token\n");
  testing::ServerProcess secured;
  ASSERT_TRUE(StartServer(
      &secured, {"--db", (dir_ / "secured.sqlite").string(), "--auth-token-file", token_file},
      "s3cret-token"));
  const std::string address = secured.address();
  const testing::CommandResult refused = RunCli({"info", "--server", address});
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_THAT(refused.err, HasSubstr("UNAUTHENTICATED"));
  EXPECT_EQ(RunCli({"info", "--server", address, "--token-file", token_file}).exit_code, 0);
  EXPECT_EQ(RunCli({"--token-file", token_file, "info", "--server", address}).exit_code, 0);
  EXPECT_EQ(RunCli({"info", "--server", address, "--token", "s3cret-token"}).exit_code, 0);
  {
    const ScopedEnv env("MOTIONDB_TOKEN_FILE", token_file);  // how the Docker healthcheck runs
    EXPECT_EQ(RunCli({"info", "--server", address}).exit_code, 0);
    EXPECT_EQ(RunCli({"info", "--server", address, "--token", "wrong"}).exit_code, 1)
        << "an explicit --token wins";
  }
  {
    const ScopedEnv env("MOTIONDB_TOKEN", "s3cret-token");
    EXPECT_EQ(RunCli({"info", "--server", address}).exit_code, 0);
  }
  const std::string empty = WriteText("empty", " \n");
  const testing::CommandResult blank = RunCli({"info", "--server", address, "--token-file", empty});
  EXPECT_EQ(blank.exit_code, 2);
  EXPECT_THAT(blank.err, HasSubstr("the token is empty"));
}

// Two takes of one file name in two session folders, as a studio's tree holds them.
TEST_F(CliServerTest, IngestNamesFolderClipsByRelativePathAndReportsEachOutcome) {
  const auto assimp = testing::AssimpBvhDir();
  if (!assimp) GTEST_SKIP() << "assimp-testmodels is not installed; skipped";
  const std::filesystem::path tree = dir_ / "tree";
  std::filesystem::create_directories(tree / "session1");
  std::filesystem::create_directories(tree / "session2");
  std::filesystem::copy_file(*assimp / "01_01.bvh", tree / "session1" / "take_001.bvh");
  std::filesystem::copy_file(*assimp / "01_03.bvh", tree / "session2" / "take_001.bvh");

  testing::CommandResult r = Remote({"ingest", tree.string(), "--recursive", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json listed = nlohmann::json::parse(r.out)["ingested"];
  ASSERT_EQ(listed.size(), 2u) << r.out;
  EXPECT_EQ(listed[0]["name"], "session1/take_001");
  EXPECT_EQ(listed[1]["name"], "session2/take_001");
  EXPECT_EQ(listed[0]["result"], "stored");

  // Again: what is stored is skipped, so a batch ingest can be re-run.
  r = Remote({"ingest", tree.string(), "--recursive"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("'session1/take_001' (2752 frames): skipped (identical)"));
  EXPECT_THAT(r.out, HasSubstr("ingested 2 of 2 files"));

  // A file named directly keeps its base name; identical content under it is warned about.
  const std::string copy = (dir_ / "copy.bvh").string();
  std::filesystem::copy_file(tree / "session1" / "take_001.bvh", copy);
  r = Remote({"ingest", copy});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("'copy' (2752 frames): stored"));
  EXPECT_THAT(r.err, HasSubstr("warning: identical content to clip"));
  EXPECT_THAT(r.err, HasSubstr("session1/take_001"));

  // Other motion under a taken name: refused by default, replaced when asked.
  const std::string other = (tree / "session2" / "take_001.bvh").string();
  r = Remote({"ingest", other, "--name", "session1/take_001"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("ALREADY_EXISTS"));
  r = Remote({"ingest", other, "--name", "session1/take_001", "--on-conflict", "replace"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("'session1/take_001'"));
  EXPECT_THAT(r.out,
              HasSubstr(": replaced clip " + std::to_string(listed[0]["clip_id"].get<int>())));
  r = Remote({"ingest", other, "--name", "session1/take_001", "--on-conflict", "skip", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["ingested"][0]["result"], "skipped");

  r = Remote({"ingest", tree.string(), "--recursive", "--name", "x"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--name names one clip, but the paths hold 2 files"));
  r = Remote({"ingest", copy, "--on-conflict", "overwrite"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--on-conflict"));
}

TEST_F(CliServerTest, ClipUpdateRenamesAndRetagsAndPrintsTheClip) {
  testing::CommandResult r =
      Remote({"clip", "update", clip_id_, "--name", "walks/slow", "--tag", "+gait", "--tag", "+a"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("clip " + clip_id_ + ": walks/slow (from walk54.bvh)"));
  EXPECT_THAT(r.out, HasSubstr("tags:     a, gait"));
  r = Remote({"clip", "update", clip_id_, "--tag", "-a", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json updated = nlohmann::json::parse(r.out);
  EXPECT_EQ(updated["name"], "walks/slow");
  EXPECT_EQ(updated["tags"], nlohmann::json({"gait"}));
  r = Remote({"clip", "show", clip_id_, "--json"});
  EXPECT_EQ(nlohmann::json::parse(r.out)["tags"], nlohmann::json({"gait"}));

  r = Remote({"clip", "update", clip_id_, "--name", "a//b"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--name 'a//b' has an empty segment"));
  r = Remote({"clip", "update", clip_id_, "--tag", "+x", "--tag", "-x"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--tag -x"));
  EXPECT_EQ(Remote({"clip", "update", "999", "--name", "x"}).exit_code, 1);
  r = Remote({"clip", "update", clip_id_, "--tag", "gait"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("neither +TAG (add) nor -TAG (remove)"));
}

TEST_F(CliServerTest, ClipsShowTheSkeletonAndPageFilterAndSort) {
  ASSERT_EQ(Remote({"ingest", walk_}).exit_code, 0);  // another skeleton
  ASSERT_EQ(Remote({"ingest", (dir_ / "walk54.bvh").string(), "--name", "b/walk54"}).exit_code, 0);
  testing::CommandResult r = Remote({"clips", "--sort", "name", "--limit", "2"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("ID +NAME +SKELETON +FRAMES"))) << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("b/walk54 +1 +54 "))) << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex(" walk +2 +61 "))) << r.out;
  EXPECT_THAT(r.out, Not(HasSubstr("  walk54 ")));
  std::smatch token;
  ASSERT_TRUE(std::regex_search(r.err, token, std::regex("next page: --page-token (\\S+)")))
      << r.err;
  r = Remote({"clips", "--sort", "name", "--limit", "2", "--page-token", token.str(1), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json page = nlohmann::json::parse(r.out);
  ASSERT_EQ(page["clips"].size(), 1u);
  EXPECT_EQ(page["clips"][0]["name"], "walk54");
  EXPECT_FALSE(page.contains("next_page_token"));
  EXPECT_TRUE(r.err.empty()) << r.err;

  r = Remote({"clips", "--limit", "1", "--json", "--name-contains", "walk5"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  page = nlohmann::json::parse(r.out);
  ASSERT_EQ(page["clips"].size(), 1u);
  EXPECT_EQ(page["clips"][0]["name"], "walk54");  // id order
  EXPECT_FALSE(page["next_page_token"].get<std::string>().empty());
  r = Remote({"clips", "--json", "--sort", "created"});  // every page
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["clips"].size(), 3u);

  r = Remote({"clips", "--sort", "size"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--sort"));
  r = Remote({"clips", "--page-token", "bogus"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("INVALID_ARGUMENT"));
}

TEST_F(CliServerTest, SkeletonsShowAndMapTheHumanoidMap) {
  testing::CommandResult r = Remote({"skeletons", "show", "1"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("skeleton 1: Hips (walk54), 19 joints, 1 clip\n"
                               "humanoid map: complete\n  Hips           Hips\n"));
  EXPECT_THAT(r.out, HasSubstr("  LeftHand       Hand_L\n"));
  EXPECT_THAT(r.out, HasSubstr("mirror pairs (7): Shoulder_L/Shoulder_R, UpperArm_L/UpperArm_R"));

  r = Remote({"skeletons", "map", "1", "--slot", "LeftHand=Hand_R", "--slot", "RightHand=Hand_L"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("  LeftHand       Hand_R  (override)\n"));
  EXPECT_THAT(r.out, HasSubstr("  LeftLowerArm   LowerArm_R\n"));

  // Bad overrides are told in the command line's words and change nothing.
  r = Remote({"skeletons", "map", "1", "--slot", "LeftHand=hand_l"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--slot LeftHand=hand_l: skeleton 1 has no joint named 'hand_l'"));
  r = Remote({"skeletons", "map", "1", "--clear", "Tail"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--clear Tail: 'Tail' is not a slot (Hips, Spine,"));
  r = Remote({"skeletons", "map", "1", "--slot", "LeftHand"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("'LeftHand' is not SLOT=JOINT"));
  r = Remote({"skeletons", "show", "1", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json shown = nlohmann::json::parse(r.out);
  EXPECT_EQ(shown["joint_count"], 19);
  EXPECT_EQ(shown["joints"][1], (nlohmann::json{{"name", "Spine"}, {"parent", 0}}));
  const nlohmann::json& map = shown["humanoid_map"];
  EXPECT_EQ(map["complete"], true);
  EXPECT_TRUE(map["missing_slots"].empty());
  // The arms' sides follow the swapped hands, and so do their pairs.
  EXPECT_EQ(map["mirror_pairs"][0],
            (nlohmann::json{{"left", "Shoulder_R"}, {"right", "Shoulder_L"}}));
  EXPECT_THAT(
      map["slots"].dump(),
      HasSubstr(R"({"joint":"Hand_R","overridden":true,"required":true,"slot":"LeftHand"})"));

  r = Remote({"skeletons", "map", "1", "--clear", "LeftHand", "--clear", "RightHand"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, Not(HasSubstr("(override)")));

  // A skeleton that is no humanoid: shown, with what it misses.
  ASSERT_EQ(Remote({"ingest", walk_}).exit_code, 0);
  r = Remote({"skeletons", "show", "2"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out,
              HasSubstr("humanoid map: incomplete, missing Hips, Spine, Head, LeftUpperArm"));
  r = Remote({"skeletons", "show", "9"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("skeleton 9 not found"));
}

TEST_F(CliServerTest, SkeletonsListAndSpaceCreateWithSeveralSaysWhichToGive) {
  testing::CommandResult r = Remote({"skeletons"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::regex_search(
      r.out, std::regex("ID +NAME +JOINTS +CLIPS\n +1  Hips \\(walk54\\) +[0-9]+ +1\n")))
      << r.out;
  // One skeleton: space create needs no flag (the fixture's "body" was made so).
  ASSERT_EQ(Remote({"ingest", walk_, "--tag", "chain"}).exit_code, 0);
  r = Remote({"skeletons", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json skeletons = nlohmann::json::parse(r.out)["skeletons"];
  ASSERT_EQ(skeletons.size(), 2u) << r.out;
  EXPECT_EQ(skeletons[1]["skeleton_id"], 2);
  EXPECT_EQ(skeletons[1]["name"], "root (walk)");
  EXPECT_EQ(skeletons[1]["root_joint"], "root");
  EXPECT_EQ(skeletons[1]["joint_count"], 3);
  EXPECT_EQ(skeletons[1]["clip_count"], 1);

  r = Remote({"space", "create", "second"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("the database holds 2 skeletons (skeleton 1 'Hips (walk54)' with 1 "
                               "clip; skeleton 2 'root (walk)' with 1 clip): give --skeleton"));
  EXPECT_THAT(r.err, Not(HasSubstr("skeleton_id")));
  EXPECT_EQ(Remote({"space", "create", "second", "--skeleton", "2"}).exit_code, 0);
}

TEST_F(CliServerTest, SpaceListAndShowCountTheClipsIngestedSinceTheBuild) {
  ASSERT_EQ(Remote({"ingest", (dir_ / "walk54.bvh").string(), "--name", "again"}).exit_code, 0);
  testing::CommandResult r = Remote({"space", "list"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr(", 2 clips"));
  r = Remote({"space", "show", "body"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("1 clips projected when built"));
  EXPECT_THAT(r.out, HasSubstr("index: 2 clips"));
  r = Remote({"space", "list", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json listed = nlohmann::json::parse(r.out);
  EXPECT_EQ(listed["spaces"][0]["clips"], 2);
  EXPECT_EQ(listed["spaces"][0]["projected_clips"], 1);
  ASSERT_EQ(Remote({"clip", "delete", clip_id_}).exit_code, 0);
  r = Remote({"space", "show", "body", "--json"});
  EXPECT_EQ(nlohmann::json::parse(r.out)["clips"], 1);
}

// `space create --learned-metric`: refused while no descriptor labels two clips, in the flag's
// name; built once one does, its report saying what it was fitted on; the shrink only with it.
TEST_F(CliServerTest, SpaceCreateWithALearnedMetric) {
  testing::CommandResult r =
      Remote({"space", "create", "styles", "--learned-metric-shrink", "0.5"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--learned-metric-shrink requires --learned-metric"));
  r = Remote({"space", "create", "styles", "--learned-metric", "--learned-metric-shrink", "1"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("INVALID_ARGUMENT: --learned-metric-shrink: 1 is outside [0, 1)"));
  ASSERT_EQ(Remote({"label", "add", "walk54:0-20", "step"}).exit_code, 0);
  r = Remote({"space", "create", "styles", "--learned-metric"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("FAILED_PRECONDITION: --learned-metric: needs one descriptor "
                               "labelled (manual labels, value >= 0.5) on at least two clips of "
                               "the space's skeleton; of its 1 such labels, no descriptor is on "
                               "two clips"));

  const std::string path = (dir_ / "walk54b.bvh").string();
  ASSERT_TRUE(WriteBvhFile(path, testing::SyntheticClip(testing::HumanoidSkeleton(false),
                                                        {.frames = kFrames, .fps = 30, .seed = 4}))
                  .ok());
  ASSERT_EQ(Remote({"ingest", path}).exit_code, 0);
  ASSERT_EQ(Remote({"label", "add", "walk54b:10-30", "step"}).exit_code, 0);
  r = Remote({"space", "create", "styles", "--learned-metric", "--learned-metric-shrink", "0.9",
              "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json space = nlohmann::json::parse(r.out);
  EXPECT_EQ(space["learned_metric"],
            nlohmann::json({{"shrink", 0.9}, {"examples", 2}, {"descriptors", 1}}));
  r = Remote({"space", "show", "styles"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(
      r.out,
      HasSubstr("search metric learned from 2 labelled ranges of 1 descriptors (shrink 0.9)"));
}

// A propagation on the fixture's clip: started and waited for, listed, shown, and the errors of
// each job command in its own words.
TEST_F(CliServerTest, PropagateWaitJobsAndJobCommands) {
  testing::CommandResult r = Remote({"propagate", "--space", "body", "--wait"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("FAILED_PRECONDITION"));
  EXPECT_THAT(r.err, HasSubstr("no manual label"));
  ASSERT_EQ(Remote({"label", "add", "walk54:0-20", "step"}).exit_code, 0);
  ASSERT_EQ(Remote({"label", "add", "walk54:30-50", "turn", "--value", "0.5"}).exit_code, 0);

  r = Remote({"propagate", "--space", "body", "--descriptor", "step", "--max-results", "3",
              "--wait", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json job = nlohmann::json::parse(r.out);
  EXPECT_EQ(job["state"], "succeeded");
  EXPECT_EQ(job["descriptors"], nlohmann::json::array({"step"}));
  EXPECT_EQ(job["total"], 1);
  EXPECT_EQ(job["done"], 1);
  EXPECT_EQ(job["parameters"]["max_results"], 3);
  const std::string id = job["job_id"];
  r = Remote({"propagate", "--space", "body", "--descriptor", "step", "--seeds", "shapes",
              "--dtw-dims", "10", "--rival-share", "0.8", "--wait", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json parameters = nlohmann::json::parse(r.out)["parameters"];
  EXPECT_EQ(parameters["seed_selection"], "shape_windows");
  EXPECT_EQ(parameters["dtw_dims"], 10);
  EXPECT_EQ(parameters["rival_share"], 0.8);
  r = Remote({"propagate", "--space", "body", "--wait"});  // every manual descriptor
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr(" succeeded: step, turn in space body, 2/2 labels searched"));

  r = Remote({"jobs", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json jobs = nlohmann::json::parse(r.out)["jobs"];
  ASSERT_EQ(jobs.size(), 3u);
  EXPECT_EQ(jobs[2]["job_id"], id);
  // Unset, a job's max_results is propagation's 100, not a search's 20.
  EXPECT_EQ(jobs[0]["parameters"]["max_results"], 100);
  r = Remote({"jobs"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("JOB"));
  EXPECT_THAT(r.out, HasSubstr(id + " "));
  r = Remote({"job", "show", id, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["state"], "succeeded");
  r = Remote({"job", "watch", id});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr(id + " succeeded"));

  for (const auto& [args, error] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"job", "cancel", id}, "FAILED_PRECONDITION: " + id + " has already ended"},
           {{"job", "show", "job-999"}, "NOT_FOUND"},
           {{"job", "watch", "job-999"}, "NOT_FOUND"},
           {{"propagate", "--space", "nosuch", "--descriptor", "step"}, "NOT_FOUND"},
           {{"propagate", "--space", "body", "--descriptor", ""}, "--descriptor ''"},
           {{"propagate", "--space", "body", "--rival-share", "1.5"}, "--rival-share: 1.5"},
           {{"propagate", "--space", "body", "--dtw-dims", "999"}, "--dtw-dims"}}) {
    r = Remote(args);
    EXPECT_EQ(r.exit_code, 1) << args[0] << " " << args[1];
    EXPECT_THAT(r.err, HasSubstr(error)) << args[0] << " " << args[1];
  }
  EXPECT_EQ(Remote({"propagate", "--wait"}).exit_code, 2);  // --space is required
  for (const std::vector<std::string>& help :
       std::vector<std::vector<std::string>>{{"propagate", "--help"},
                                             {"jobs", "--help"},
                                             {"job", "show", "--help"},
                                             {"job", "watch", "--help"},
                                             {"job", "cancel", "--help"}}) {
    EXPECT_EQ(RunCli(help).exit_code, 0) << help[0];
  }
}

// Labels on the fixture's clip (54 frames at 30 fps): added by id or name, in frames or seconds;
// listed, found, deleted; the server's complaints told in the command's words.
TEST_F(CliServerTest, LabelAddListFindDeleteAndTheirErrors) {
  testing::CommandResult r =
      Remote({"label", "add", "walk54:10-20", "step", "--value", "0.8", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json framed = nlohmann::json::parse(r.out);
  EXPECT_EQ(framed["clip_name"], "walk54");
  EXPECT_EQ(framed["first_frame"], 10);
  EXPECT_EQ(framed["last_frame"], 20);
  EXPECT_EQ(framed["origin"], "manual");
  r = Remote({"label", "add", "id:" + clip_id_ + ":0.5-1", "step", "--seconds"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("clip " + clip_id_ + " (walk54) frames 15-30 (0.500-1.000 s)"));
  ASSERT_EQ(Remote({"label", "add", "id:" + clip_id_, "whole"}).exit_code, 0);

  r = Remote({"labels", "list", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json listed = nlohmann::json::parse(r.out)["labels"];
  ASSERT_EQ(listed.size(), 3u) << r.out;
  EXPECT_EQ(listed[2]["first_frame"], 0);
  EXPECT_EQ(listed[2]["last_frame"], kFrames - 1);
  r = Remote({"labels", "list", "--descriptor", "step", "--min", "0.9", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  listed = nlohmann::json::parse(r.out)["labels"];
  ASSERT_EQ(listed.size(), 1u) << r.out;
  EXPECT_EQ(listed[0]["first_frame"], 15);
  r = Remote({"labels", "list", "--limit", "1", "--origin", "manual"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("ID +CLIP +NAME +FRAMES"))) << r.out;
  EXPECT_TRUE(
      std::regex_search(r.out, std::regex(" walk54 +10-20 +0.33-0.67 +step +0.800 +manual")))
      << r.out;
  EXPECT_THAT(r.err, HasSubstr("next page: --page-token "));

  r = Remote({"labels", "find", "step", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  listed = nlohmann::json::parse(r.out)["labels"];
  ASSERT_EQ(listed.size(), 2u) << r.out;
  EXPECT_EQ(listed[0]["value"], 1.0);  // strongest first
  EXPECT_EQ(listed[1]["label_id"], framed["label_id"]);
  r = Remote({"labels", "find", "step", "--tag", "nosuch", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::parse(r.out)["labels"].empty());

  const struct {
    std::vector<std::string> args;
    std::string message;
  } errors[] = {
      {{"label", "add", "walk54:10-99", "step"},
       "INVALID_ARGUMENT: TO: 99 is past the clip's last frame 53"},
      {{"label", "add", "walk54:20-10", "step"}, "TO: 10 is before first_frame 20"},
      {{"label", "add", "walk54", "step", "--value", "1.5"}, "--value: 1.5 is outside [0, 1]"},
      {{"label", "add", "walk54", ""}, "DESCRIPTOR must not be empty"},
      {{"label", "add", "nosuch", "step"}, "NOT_FOUND: CLIP: no clip is named 'nosuch'"},
      {{"label", "add", "walk54:1.5-3", "step"}, "frames are whole numbers"},
      {{"label", "add", "walk54:10-", "step"},
       "'walk54:10-': the range '10-' is not FROM-TO, two numbers from 0 (e.g. 10-20)"},
      {{"label", "add", "walk54:-1-5", "step"}, "the range '-1-5' is not FROM-TO"},
      {{"label", "add", "walk54", "step", "--seconds"},
       "--seconds: 'walk54' has no range; give CLIP:FROM-TO"},
      {{"label", "add", "id:x", "step"}, "'id:x': id:N gives a clip by id"},
      {{"label", "add", "id:999999", "step"}, "NOT_FOUND: CLIP: clip 999999 not found"},
      {{"label", "add", clip_id_, "step"}, "NOT_FOUND: CLIP: no clip is named '" + clip_id_ + "'"},
      {{"labels", "find", "step", "--min", "2"}, "--min: 2 is outside [0, 1]"},
      {{"labels", "delete", "999999"}, "NOT_FOUND: ID 999999: label 999999 not found"},
      {{"labels", "delete"}, "give label ids or a filter"},
      {{"labels", "list", "--clip", "999999"}, "NOT_FOUND: --clip: clip 999999 not found"},
      {{"labels", "delete", "--clip", "999999"}, "NOT_FOUND: --clip: clip 999999 not found"},
      {{"labels", "export", "--clip", "999999"}, "NOT_FOUND: --clip: clip 999999 not found"},
  };
  for (const auto& e : errors) {
    r = Remote(e.args);
    EXPECT_EQ(r.exit_code, 1) << e.message;
    EXPECT_THAT(r.err, HasSubstr(e.message));
  }

  r = Remote({"labels", "delete", framed["label_id"].dump(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["deleted"], 1);
  r = Remote({"labels", "delete", "--descriptor", "whole"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("deleted 1 labels"));
  r = Remote({"labels", "list", "--json"});
  EXPECT_EQ(nlohmann::json::parse(r.out)["labels"].size(), 1u) << r.out;

  for (const std::vector<std::string>& help : {std::vector<std::string>{"label", "add", "--help"},
                                               {"labels", "list", "--help"},
                                               {"labels", "find", "--help"},
                                               {"labels", "delete", "--help"},
                                               {"labels", "import", "--help"},
                                               {"labels", "export", "--help"}}) {
    r = RunCli(help);
    EXPECT_EQ(r.exit_code, 0) << help[1];
    EXPECT_THAT(r.out, HasSubstr("Usage: motiondb " + help[0] + " " + help[1])) << r.out;
  }
  EXPECT_THAT(RunCli({"label", "add", "--help"}).out, HasSubstr("CLIP[:FROM-TO]"));
  EXPECT_THAT(RunCli({"label", "add", "--help"}).out, HasSubstr("or id:N for clip N"));
  EXPECT_THAT(RunCli({"labels", "import", "--help"}).out, HasSubstr("use a clip_id column"));
  EXPECT_THAT(RunCli({"labels", "export", "--help"}).out,
              HasSubstr("Exports manual labels unless --origin propagated"));
  EXPECT_THAT(RunCli({"labels", "list", "--help"}).out, HasSubstr("--origin manual|propagated"));
}

// `labels export` writes what `labels import` reads: exported, deleted, imported and exported
// again, the file is the same. Import is one batch: a bad line stores nothing, and is named.
TEST_F(CliServerTest, LabelsExportAndImportRoundTripCsvAndJson) {
  ASSERT_EQ(Remote({"label", "add", "walk54:0-9", "step, left", "--value", "0.25"}).exit_code, 0);
  ASSERT_EQ(Remote({"label", "add", "walk54:10-20", "say \"hi\"", "--value", "0.7"}).exit_code, 0);
  for (const std::string format : {"csv", "json"}) {
    const std::string first = (dir_ / ("labels." + format)).string();
    const std::string second = (dir_ / ("again." + format)).string();
    testing::CommandResult r = Remote({"labels", "export", "-o", first});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_THAT(r.out, HasSubstr("wrote 2 labels to " + first));
    ASSERT_EQ(Remote({"labels", "delete", "--clip", clip_id_}).exit_code, 0);
    r = Remote({"labels", "import", first, "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["imported"], 2);
    ASSERT_EQ(Remote({"labels", "export", "-o", second}).exit_code, 0);
    EXPECT_EQ(testing::ReadFileOrDie(second), testing::ReadFileOrDie(first)) << format;
  }
  EXPECT_THAT(testing::ReadFileOrDie((dir_ / "labels.csv").string()),
              HasSubstr("walk54,0,9,\"step, left\",0.25,frames\n"));
  testing::CommandResult r =
      Remote({"labels", "export", "--format", "json", "--descriptor", "say \"hi\""});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json exported = nlohmann::json::parse(r.out);
  ASSERT_EQ(exported.size(), 1u);
  EXPECT_EQ(exported[0]["value"], 0.7);

  // Another column order, seconds, an empty value (1) and end (the last frame).
  const std::string seconds =
      WriteText("seconds.csv",
                "descriptor,clip,clip_id,end,start,value,unit\r\nkick,walk54,,1,0.5,,seconds\r\n"
                "turn,," +
                    clip_id_ + ",,40,0.5,\r\n");
  r = Remote({"labels", "import", seconds});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("imported 2 labels from " + seconds));
  r = Remote({"labels", "list", "--json", "--descriptor", "kick"});
  nlohmann::json listed = nlohmann::json::parse(r.out)["labels"];
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_EQ(listed[0]["first_frame"], 15);
  EXPECT_EQ(listed[0]["last_frame"], 30);
  EXPECT_EQ(listed[0]["value"], 1.0);
  r = Remote({"labels", "list", "--json", "--descriptor", "turn"});
  EXPECT_EQ(nlohmann::json::parse(r.out)["labels"][0]["last_frame"], kFrames - 1);

  const struct {
    std::string name;
    std::string text;
    std::string message;
  } bad[] = {
      {"value.csv", "clip,start,end,descriptor,value\nwalk54,0,5,a,1\n\nwalk54,0,5,b,1.5\n",
       "value.csv: line 4, value: 1.5 is outside [0, 1]"},
      {"frames.csv", "clip,start,end,descriptor,value\nwalk54,0,60,a,1\n",
       "frames.csv: line 2, end: 60 is past the clip's last frame 53"},
      {"clip.json",
       R"([{"clip": "walk54", "descriptor": "a"}, {"clip": "nosuch", "descriptor": "b"}])",
       "clip.json: item 1, clip: no clip is named 'nosuch'"},
      {"number.csv", "clip,start,end,descriptor,value\nwalk54,x,5,a,1\n",
       "number.csv: line 2: start: 'x' is not a number"},
      {"header.csv", "clip,begin,end,descriptor,value\n",
       "header.csv: line 1: header: unknown "
       "column 'begin'"},
      {"item.json", R"([{"clip": "walk54", "descriptor": "a", "start": "0"}])",
       "item.json: item 0: start: expected a number"},
      {"labels.txt", "clip,start,end,descriptor,value\n", "expected a .csv or .json file"},
      {"twice.csv", "clip,start,end,descriptor,value,start\nwalk54,0,5,a,1,0\n",
       "twice.csv: line 1: header: column 'start' is named twice (2 and 6)"},
      {"noclip.csv", "start,end,descriptor,value\n", "header: no 'clip' (or 'clip_id') column"},
      {"nan.csv", "clip,start,end,descriptor,value\nwalk54,nan,5,a,1\n",
       "nan.csv: line 2: start: nan is not a frame number (at most 2147483647)"},
      {"inf.csv", "clip,start,end,descriptor,value\nwalk54,0,inf,a,1\n",
       "inf.csv: line 2: end: inf is not a frame number"},
      {"big.csv", "clip,start,end,descriptor,value\nwalk54,0,1e10,a,1\n",
       "big.csv: line 2: end: 1e+10 is not a frame number"},
      {"small.csv", "clip,start,end,descriptor,value\nwalk54,-3e9,5,a,1\n",
       "small.csv: line 2: start: -3e+09 is not a frame number"},
      {"clipid.csv", "clip_id,start,end,descriptor,value\nwalk54,0,5,a,1\n",
       "clipid.csv: line 2: clip_id: 'walk54' is not a clip id"},
      {"unknownid.csv", "clip,clip_id,start,end,descriptor,value\n,999999,0,5,a,1\n",
       "unknownid.csv: line 2, clip_id: clip 999999 not found"},
      {"number.json", R"([{"clip": 1, "descriptor": "a"}])",
       "number.json: item 0: clip: expected a clip name (give an id as clip_id)"},
  };
  // A byte order mark (as spreadsheets write it) before the header.
  r = Remote({"labels", "import",
              WriteText("bom.csv",
                        "\xEF\xBB\xBF"
                        "clip,start,end,descriptor,value\nwalk54,0,5,bom,1\n")});
  ASSERT_EQ(r.exit_code, 0) << r.err;

  const size_t before =
      nlohmann::json::parse(Remote({"labels", "list", "--json"}).out)["labels"].size();
  for (const auto& b : bad) {
    r = Remote({"labels", "import", WriteText(b.name, b.text)});
    EXPECT_EQ(r.exit_code, 1) << b.name;
    EXPECT_THAT(r.err, HasSubstr(b.message));
  }
  EXPECT_EQ(nlohmann::json::parse(Remote({"labels", "list", "--json"}).out)["labels"].size(),
            before);
}

// A clip's name is a name, digits too: a clip named like another's id is labelled by name,
// in files and on the command line; ids are explicit (id:N, clip_id).
TEST_F(CliServerTest, ClipNamesOfDigitsAreNamesAndIdsAreExplicit) {
  // A second clip named as the fixture's clip's id, and one named with leading zeros.
  const std::string walk = (dir_ / "walk54.bvh").string();
  testing::CommandResult r = Remote({"ingest", walk, "--name", clip_id_, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const int digits = nlohmann::json::parse(r.out)["ingested"][0]["clip_id"].get<int>();
  ASSERT_NE(std::to_string(digits), clip_id_);
  r = Remote({"ingest", walk, "--name", "000" + clip_id_});
  ASSERT_EQ(r.exit_code, 0) << r.err;

  r = Remote({"label", "add", clip_id_ + ":1-2", "by-name", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["clip_id"], digits);
  r = Remote({"label", "add", "id:" + clip_id_ + ":1-2", "by-id", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["clip_id"].dump(), clip_id_);
  r = Remote({"label", "add", "000" + clip_id_, "zeros", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["clip_name"], "000" + clip_id_);

  // Files: clip is a name, clip_id an id; both must agree. Export writes names.
  r = Remote(
      {"labels", "import",
       WriteText("digits.csv", "clip,clip_id,start,end,descriptor,value\n" + clip_id_ +
                                   ",,0,1,file-name,1\n," + clip_id_ + ",0,1,file-id,1\nwalk54," +
                                   clip_id_ + ",0,1,file-both,1\n")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = Remote({"labels", "import",
              WriteText("digits.json", R"([{"clip": ")" + clip_id_ +
                                           R"(", "descriptor": "json-name"}, {"clip_id": )" +
                                           clip_id_ + R"(, "descriptor": "json-id"}])")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json listed = nlohmann::json::parse(Remote({"labels", "list", "--json"}).out);
  std::map<std::string, std::string> clip_of;
  for (const nlohmann::json& label : listed["labels"]) {
    clip_of[label["descriptor"]] = label["clip_id"].dump();
  }
  const std::string named = std::to_string(digits);
  EXPECT_EQ(clip_of, (std::map<std::string, std::string>{{"by-name", named},
                                                         {"by-id", clip_id_},
                                                         {"zeros", clip_of["zeros"]},
                                                         {"file-name", named},
                                                         {"file-id", clip_id_},
                                                         {"file-both", clip_id_},
                                                         {"json-name", named},
                                                         {"json-id", clip_id_}}));
  r = Remote({"labels", "import",
              WriteText("disagree.csv", "clip,clip_id,start,end,descriptor,value\nwalk54," +
                                            std::to_string(digits) + ",0,1,x,1\n")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("disagree.csv: line 2: clip_id " + std::to_string(digits) +
                               " and clip_name 'walk54'"));
  r = Remote({"labels", "export", "--clip", named});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("\n" + clip_id_ + ",1,2,by-name,1,frames\n"));
  EXPECT_THAT(r.out, Not(HasSubstr(named + ",1,2,by-name")));
}

// `labels export` writes manual labels unless told otherwise: its file has no origin column,
// so propagated labels exported with them would come back as manual ones.
TEST_F(CliServerTest, LabelsExportManualLabelsByDefault) {
  testing::CommandResult r = Remote({"label", "add", "walk54:0-9", "kick", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string source = nlohmann::json::parse(r.out)["label_id"].dump();
  {
    // A propagated label, as a propagation job would write it.
    const absl::StatusOr<std::unique_ptr<storage::SqliteConnection>> db =
        storage::SqliteConnection::Open((dir_ / "motiondb.sqlite").string(),
                                        storage::SqliteConnection::Mode::kReadWrite, 5000);
    ASSERT_TRUE(db.ok()) << db.status();
    const absl::Status inserted = (*db)->Execute(
        "INSERT INTO labels (clip_id, first_frame, last_frame, descriptor, value, origin, "
        "source_label_id, score, created_unix_ms) VALUES (" +
        clip_id_ + ", 20, 29, 'kick', 0.5, 'propagated', " + source + ", 0.9, 1)");
    ASSERT_TRUE(inserted.ok()) << inserted;
  }
  r = Remote({"labels", "list", "--json"});
  ASSERT_EQ(nlohmann::json::parse(r.out)["labels"].size(), 2u) << r.out;

  r = Remote({"labels", "export"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "clip,start,end,descriptor,value,unit\nwalk54,0,9,kick,1,frames\n");
  r = Remote({"labels", "export", "--origin", "propagated"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "clip,start,end,descriptor,value,unit\nwalk54,20,29,kick,0.5,frames\n");
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
