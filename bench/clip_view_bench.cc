// What the web page's clip and hit views cost on a long take (issue 38, item 6): a 10-minute take
// at 120 fps (72,000 frames of the synthetic humanoid) ingested into the real motiondb-server
// with a space over it, then over gRPC, each call a view makes: GetClip (the clip's record and
// joint names), GetClipPoses of a 4 s range at the page's 60 Hz, GetCurve of that range in 3
// dimensions. Client-side latency (median and p95 of --repetitions calls each, ranges spread
// over the take) and the server's peak resident memory (VmHWM) before and after the views.
// The program uses the API only, so the same source measures any build: build it on two commits
// and run both, back to back.
//
// usage: clip_view_bench [--repetitions 20] [--minutes 10] [--fps 120]
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "CLI/CLI.hpp"
#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "bench/call_context.h"
#include "bench/measure.h"
#include "core/bvh/bvh_writer.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "testing/server_process.h"
#include "testing/synthetic_corpus.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using Clock = std::chrono::steady_clock;
using testing::GenerateSyntheticCorpus;
using testing::SyntheticCorpus;
using testing::SyntheticCorpusOptions;

struct Flags {
  int repetitions = 20;
  double minutes = 10;
  double fps = 120;
};

std::unique_ptr<grpc::ClientContext> Context() {
  return bench::ContextWithin(std::chrono::minutes(10));
}

// Median and p95 of `ms`, in milliseconds.
std::string Summary(const std::vector<double>& ms) {
  return absl::StrCat(absl::SixDigits(bench::Percentile(ms, 0.5)), " ms median, ",
                      absl::SixDigits(bench::Percentile(ms, 0.95)), " ms p95");
}

absl::Status Run(const Flags& flags) {
  const std::filesystem::path work =
      std::filesystem::temp_directory_path() / ("motiondb_clip_view_" + std::to_string(::getpid()));
  std::filesystem::create_directories(work);
  SyntheticCorpusOptions options;
  options.fps = flags.fps;
  options.target_duration_s = flags.minutes * 60;
  options.max_clip_duration_s = flags.minutes * 60 + 60;  // one take
  options.threads = 2;
  MOTIONDB_ASSIGN_OR_RETURN(const SyntheticCorpus corpus, GenerateSyntheticCorpus(options));
  if (corpus.clips.size() != 1) {
    return absl::InternalError(absl::StrCat("expected one take, got ", corpus.clips.size()));
  }
  const Clip& take = corpus.clips.front();
  MOTIONDB_ASSIGN_OR_RETURN(const std::string bvh, WriteBvh(take));

  testing::ServerProcess server;
  std::string error;
  if (!server.Start({"--db", (work / "library.sqlite").string(), "--quiet"}, &error,
                    std::chrono::seconds(600)) ||
      !testing::WaitUntilServing(testing::InsecureChannel(server.address()), "")) {
    return absl::InternalError(absl::StrCat("the server did not start: ", error));
  }
  grpc::ChannelArguments arguments;
  arguments.SetMaxSendMessageSize(-1);
  arguments.SetMaxReceiveMessageSize(-1);
  const auto channel =
      grpc::CreateCustomChannel(server.address(), grpc::InsecureChannelCredentials(), arguments);
  auto clips = v1::ClipService::NewStub(channel);
  auto spaces = v1::SpaceService::NewStub(channel);
  v1::IngestClipRequest ingest;
  ingest.set_file_name("take.bvh");
  ingest.set_bvh(bvh);
  v1::IngestClipResponse ingested;
  grpc::Status status = clips->IngestClip(Context().get(), ingest, &ingested);
  if (!status.ok()) return absl::InternalError("ingest: " + status.error_message());
  const int64_t clip_id = ingested.clip().clip_id();
  v1::CreateSpaceRequest create;
  create.set_name("body");
  v1::Space space;
  status = spaces->CreateSpace(Context().get(), create, &space);
  if (!status.ok()) return absl::InternalError("space: " + status.error_message());

  const int frames = take.frame_count();
  const int range = static_cast<int>(4 * flags.fps);
  std::printf("clip_view_bench: a %d-frame take at %.0f fps (%.1f MB of BVH), %d joints\n", frames,
              flags.fps, static_cast<double>(bvh.size()) / 1e6, take.skeleton().joint_count());
  std::printf("server VmHWM before the views: %.1f MiB\n", bench::StatusMiB(server.pid(), "VmHWM"));

  std::vector<double> clip_ms, poses_ms, curve_ms;
  for (int i = 0; i < flags.repetitions; ++i) {
    const int first = static_cast<int>(static_cast<int64_t>(frames - range) * i /
                                       std::max(1, flags.repetitions - 1));
    v1::GetClipRequest get;
    get.set_clip_id(clip_id);
    v1::Clip clip;
    Clock::time_point start = Clock::now();
    status = clips->GetClip(Context().get(), get, &clip);
    clip_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    if (!status.ok()) return absl::InternalError("GetClip: " + status.error_message());

    v1::GetClipPosesRequest poses;
    poses.mutable_clip()->set_clip_id(clip_id);
    poses.mutable_clip()->set_first_frame(first);
    poses.mutable_clip()->set_last_frame(first + range - 1);
    poses.set_max_rate(60);
    v1::ClipPoses posed;
    start = Clock::now();
    status = clips->GetClipPoses(Context().get(), poses, &posed);
    poses_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    if (!status.ok()) return absl::InternalError("GetClipPoses: " + status.error_message());

    v1::GetCurveRequest curve;
    curve.set_space("body");
    *curve.mutable_clip() = poses.clip();
    curve.set_dims(3);
    v1::GetCurveResponse curved;
    start = Clock::now();
    status = spaces->GetCurve(Context().get(), curve, &curved);
    curve_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    if (!status.ok()) return absl::InternalError("GetCurve: " + status.error_message());
  }
  std::printf("GetClip:                       %s\n", Summary(clip_ms).c_str());
  std::printf("GetClipPoses (4 s at 60 Hz):   %s\n", Summary(poses_ms).c_str());
  std::printf("GetCurve (4 s, 3 dimensions):  %s\n", Summary(curve_ms).c_str());
  std::printf("server VmHWM after the views:  %.1f MiB\n", bench::StatusMiB(server.pid(), "VmHWM"));
  server.Stop(SIGTERM);
  std::filesystem::remove_all(work);
  return absl::OkStatus();
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  motiondb::Flags flags;
  CLI::App app("What the web page's clip and hit views cost on a long take");
  app.add_option("--repetitions", flags.repetitions, "calls of each kind")->capture_default_str();
  app.add_option("--minutes", flags.minutes, "the take's length")->capture_default_str();
  app.add_option("--fps", flags.fps, "the take's frame rate")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  const absl::Status status = motiondb::Run(flags);
  if (!status.ok()) {
    std::fprintf(stderr, "clip_view_bench: %s\n", status.ToString().c_str());
    return 1;
  }
  return 0;
}
