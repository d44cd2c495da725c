// The server's memory for one large upload (issue 15, finding 2): a BVH file of about N MiB,
// made of a real clip's rows repeated, sent to a fresh motiondb-server by IngestClipStream in
// chunks (or whole by IngestClip with --unary); reported: the server's resident memory before,
// its peak (VmHWM) after the ingest, and the peak's growth over the file's size.
//
// usage: [MOTIONDB_SERVER_BIN=PATH] upload_memory_bench [--mb N] [--chunk-kb K] [--unary]
//          [--source FILE.bvh]
//   MOTIONDB_SERVER_BIN runs another build of the server (a baseline) with the same client.
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>

#include <grpcpp/grpcpp.h>

#include "absl/strings/str_cat.h"
#include "bench/measure.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "testing/corpus_paths.h"
#include "testing/server_process.h"
#include "util/cli_conventions.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using bench::Clock;
using bench::SecondsSince;
using bench::StatusMiB;

struct Flags {
  double mb = 500;
  int chunk_kb = 1024;
  bool unary = false;
  std::string source;  // empty: ../shared/mocap/cmu/01_01_3dsmax.bvh
};

// `source`'s header and rows, its rows repeated until the text reaches `bytes`, with the
// Frames: header telling the truth (as an exporter writes it).
absl::StatusOr<std::string> LargeBvh(const std::string& source, size_t bytes) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::string text, ReadFileBytes(source, int64_t{1} << 30));
  const size_t rows_at = text.find('\n', text.find("Frame Time:")) + 1;
  const size_t frames_at = text.find("Frames:");
  if (frames_at == std::string::npos || rows_at == 0) {
    return absl::InvalidArgumentError(absl::StrCat(source, ": no MOTION header"));
  }
  const std::string rows = text.substr(rows_at);
  const size_t row_count = std::count(rows.begin(), rows.end(), '\n');
  const size_t copies = std::max<size_t>(1, bytes / rows.size());
  std::string large = text.substr(0, frames_at);
  absl::StrAppend(&large, "Frames: ", copies * row_count, "\n",
                  text.substr(text.find("Frame Time:"), rows_at - text.find("Frame Time:")));
  large.reserve(large.size() + copies * rows.size());
  for (size_t i = 0; i < copies; ++i) large += rows;
  return large;
}

absl::Status Send(v1::ClipService::Stub& stub, const std::string& bvh, const Flags& flags) {
  v1::IngestClipResponse response;
  grpc::ClientContext context;
  grpc::Status status;
  if (flags.unary) {
    v1::IngestClipRequest request;
    request.set_file_name("large.bvh");
    request.set_bvh(bvh);
    status = stub.IngestClip(&context, request, &response);
  } else {
    const std::unique_ptr<grpc::ClientWriter<v1::IngestClipStreamRequest>> writer =
        stub.IngestClipStream(&context, &response);
    const size_t chunk = static_cast<size_t>(flags.chunk_kb) * 1024;
    for (size_t at = 0; at < bvh.size(); at += chunk) {
      v1::IngestClipStreamRequest message;
      if (at == 0) message.set_file_name("large.bvh");
      message.set_chunk(bvh.substr(at, chunk));
      if (!writer->Write(message)) break;
    }
    writer->WritesDone();
    status = writer->Finish();
  }
  if (!status.ok()) return absl::InternalError(status.error_message());
  return absl::OkStatus();
}

absl::Status Run(const Flags& flags) {
  std::string source = flags.source;
  if (source.empty()) {
    if (!testing::MocapDir())
      return absl::NotFoundError("../shared/mocap is absent: give --source");
    source = (*testing::MocapDir() / "cmu" / "01_01_3dsmax.bvh").string();
  }
  MOTIONDB_ASSIGN_OR_RETURN(const std::string bvh,
                            LargeBvh(source, static_cast<size_t>(flags.mb * 1048576)));
  const double bvh_mib = bvh.size() / 1048576.0;

  const std::filesystem::path work = std::filesystem::temp_directory_path() /
                                     ("motiondb_upload_bench_" + std::to_string(::getpid()));
  std::filesystem::create_directories(work);
  testing::ServerProcess server;
  std::string error;
  const std::string max_mb = std::to_string(static_cast<int>(bvh_mib) + 2);
  // The upload budget keeps its default (2 GiB), which also bounds the parsed clip: a budget of
  // the file's size would refuse the clip, 1.5x the text in double precision.
  if (!server.Start({"--db", (work / "library.sqlite").string(), "--quiet", "--max-bvh-mb", max_mb},
                    &error)) {
    return absl::InternalError(error);
  }
  const auto channel = testing::InsecureChannel(server.address());
  if (!testing::WaitUntilServing(channel, "")) return absl::InternalError("not serving");
  const double rss_before = StatusMiB(server.pid(), "VmRSS");
  const double hwm_before = StatusMiB(server.pid(), "VmHWM");

  const Clock::time_point start = Clock::now();
  const absl::Status sent = Send(*v1::ClipService::NewStub(channel), bvh, flags);
  const double seconds = SecondsSince(start);
  const double hwm = StatusMiB(server.pid(), "VmHWM");
  const double rss_after = StatusMiB(server.pid(), "VmRSS");
  server.Stop(SIGTERM);
  std::filesystem::remove_all(work);
  MOTIONDB_RETURN_IF_ERROR(sent);

  std::printf(
      "server %s\n%s of %.1f MiB (%s, %d KiB chunks) ingested in %.1f s\n"
      "server VmRSS before %.0f MiB (peak so far %.0f), peak after the ingest %.0f MiB, "
      "VmRSS after %.0f MiB\npeak growth %.0f MiB = %.2fx the file\n",
      testing::ServerPath().c_str(), flags.unary ? "IngestClip" : "IngestClipStream", bvh_mib,
      source.c_str(), flags.chunk_kb, seconds, rss_before, hwm_before, hwm, rss_after,
      hwm - rss_before, (hwm - rss_before) / bvh_mib);
  return absl::OkStatus();
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  CLI::App app("The server's peak memory for one large BVH upload.", "upload_memory_bench");
  motiondb::Flags flags;
  app.add_option("--mb", flags.mb, "the upload's size in MiB")
      ->capture_default_str()
      ->check(motiondb::cli::NumberAbove(0));
  app.add_option("--chunk-kb", flags.chunk_kb, "IngestClipStream's chunk size")
      ->capture_default_str()
      ->check(CLI::Range(1, 65536));
  app.add_flag("--unary", flags.unary, "send it whole with IngestClip");
  app.add_option("--source", flags.source, "the BVH file whose rows are repeated");
  if (const std::optional<int> exit_code = motiondb::cli::ParseCommandLine(app, argc, argv)) {
    return *exit_code;
  }
  const absl::Status status = motiondb::Run(flags);
  if (!status.ok()) {
    std::fprintf(stderr, "upload_memory_bench: %s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
