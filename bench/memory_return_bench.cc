// Whether the server gives memory back after its library grows (issue 15, finding 3): N
// clients ingest synthetic clips for S seconds into a space (each ingest projects the clip and
// swaps in a rebuilt index), then the server's resident memory once it has settled, beside a
// server started fresh on the same database (the same library, loaded from its cached
// projections). The ratio is what the growth left behind.
//
// usage: [MALLOC_...=V] memory_return_bench [--seconds S] [--clients N]
//   The servers inherit the environment, so glibc's malloc tunables set for the bench
//   (MALLOC_ARENA_MAX, MALLOC_MMAP_THRESHOLD_, ...) are theirs too; the report names them.
#include <signal.h>
#include <stdlib.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "absl/strings/str_cat.h"
#include "bench/measure.h"
#include "core/bvh/bvh_writer.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "testing/server_process.h"
#include "testing/synthetic_corpus.h"
#include "util/cli_conventions.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using bench::Clock;
using bench::SecondsSince;
using bench::StatusMiB;
using testing::GenerateSyntheticCorpus;
using testing::SyntheticCorpus;
using testing::SyntheticCorpusOptions;

struct Flags {
  double seconds = 75;
  int clients = 16;
};

// The MALLOC_* variables of the environment, "VAR=V VAR=V", or "none".
std::string MallocEnvironment() {
  std::string found;
  for (char** variable = environ; *variable != nullptr; ++variable) {
    if (std::string(*variable).starts_with("MALLOC_")) absl::StrAppend(&found, " ", *variable);
  }
  return found.empty() ? " none" : found;
}

absl::Status Ingest(v1::ClipService::Stub& stub, const std::string& name, const std::string& bvh) {
  v1::IngestClipRequest request;
  request.set_file_name(name + ".bvh");
  request.set_bvh(bvh);
  v1::IngestClipResponse response;
  grpc::ClientContext context;
  const grpc::Status status = stub.IngestClip(&context, request, &response);
  if (status.ok()) return absl::OkStatus();
  return absl::InternalError(absl::StrCat(name, ": ", status.error_message()));
}

absl::StatusOr<testing::ServerProcess*> Serve(testing::ServerProcess& server,
                                              const std::string& db) {
  std::string error;
  if (!server.Start({"--db", db, "--quiet"}, &error, std::chrono::seconds(600))) {
    return absl::InternalError(error);
  }
  if (!testing::WaitUntilServing(testing::InsecureChannel(server.address()), "",
                                 std::chrono::seconds(600))) {
    return absl::InternalError("the server did not start serving");
  }
  return &server;
}

absl::Status Run(const Flags& flags) {
  const std::filesystem::path work = std::filesystem::temp_directory_path() /
                                     ("motiondb_memory_bench_" + std::to_string(::getpid()));
  std::filesystem::create_directories(work);
  const std::string db = (work / "library.sqlite").string();

  // Clips of 10 to 40 s at 30 Hz, written as BVH once; each client cycles through them under
  // names of its own.
  SyntheticCorpusOptions options;
  options.fps = 30;
  options.target_duration_s = 1800;
  options.max_clip_duration_s = 40;
  options.threads = 2;
  MOTIONDB_ASSIGN_OR_RETURN(const SyntheticCorpus corpus, GenerateSyntheticCorpus(options));
  std::vector<std::string> texts;
  for (const Clip& clip : corpus.clips) {
    MOTIONDB_ASSIGN_OR_RETURN(texts.emplace_back(), WriteBvh(clip));
  }

  testing::ServerProcess grown;
  MOTIONDB_RETURN_IF_ERROR(Serve(grown, db).status());
  const auto channel = testing::InsecureChannel(grown.address());
  auto clips = v1::ClipService::NewStub(channel);
  MOTIONDB_RETURN_IF_ERROR(Ingest(*clips, "first", texts[0]));
  {
    v1::CreateSpaceRequest request;
    request.set_name("body");
    v1::Space space;
    grpc::ClientContext context;
    const grpc::Status status =
        v1::SpaceService::NewStub(channel)->CreateSpace(&context, request, &space);
    if (!status.ok()) return absl::InternalError(status.error_message());
  }
  const double rss_start = StatusMiB(grown.pid(), "VmRSS");

  std::atomic<int64_t> ingested = 0;
  std::vector<absl::Status> failures(flags.clients);
  std::vector<std::thread> threads;
  const Clock::time_point start = Clock::now();
  for (int c = 0; c < flags.clients; ++c) {
    threads.emplace_back([&, c] {
      // Its own connection, as a separate client would have.
      grpc::ChannelArguments arguments;
      arguments.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
      auto stub = v1::ClipService::NewStub(grpc::CreateCustomChannel(
          grown.address(), grpc::InsecureChannelCredentials(), arguments));
      for (size_t i = c; SecondsSince(start) < flags.seconds && failures[c].ok();
           i += flags.clients) {
        failures[c] = Ingest(*stub, absl::StrCat("c", c, "_", i), texts[i % texts.size()]);
        if (failures[c].ok()) ++ingested;
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  for (const absl::Status& failure : failures) MOTIONDB_RETURN_IF_ERROR(failure);
  std::this_thread::sleep_for(std::chrono::seconds(3));
  const double rss_grown = StatusMiB(grown.pid(), "VmRSS");
  const double hwm_grown = StatusMiB(grown.pid(), "VmHWM");
  grown.Stop(SIGTERM);

  testing::ServerProcess fresh;
  MOTIONDB_RETURN_IF_ERROR(Serve(fresh, db).status());
  std::this_thread::sleep_for(std::chrono::seconds(3));
  const double rss_fresh = StatusMiB(fresh.pid(), "VmRSS");
  fresh.Stop(SIGTERM);
  const double db_mib = std::filesystem::file_size(db) / 1048576.0;
  std::filesystem::remove_all(work);

  std::printf(
      "%d clients ingested %lld clips for %.0f s (malloc environment:%s); database %.0f MiB\n"
      "server VmRSS: %.0f MiB with the space and one clip, %.0f MiB after the growth (peak %.0f), "
      "%.0f MiB started fresh on the same database: %.2fx\n",
      flags.clients, static_cast<long long>(ingested.load()), flags.seconds,
      MallocEnvironment().c_str(), db_mib, rss_start, rss_grown, hwm_grown, rss_fresh,
      rss_grown / rss_fresh);
  return absl::OkStatus();
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  CLI::App app("Server memory after a growth of the library, beside a fresh start.",
               "memory_return_bench");
  motiondb::Flags flags;
  app.add_option("--seconds", flags.seconds, "how long the clients ingest")
      ->capture_default_str()
      ->check(motiondb::cli::NumberAbove(0));
  app.add_option("--clients", flags.clients, "concurrent ingesting clients")
      ->capture_default_str()
      ->check(CLI::Range(1, 256));
  if (const std::optional<int> exit_code = motiondb::cli::ParseCommandLine(app, argc, argv)) {
    return *exit_code;
  }
  const absl::Status status = motiondb::Run(flags);
  if (!status.ok()) {
    std::fprintf(stderr, "memory_return_bench: %s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
