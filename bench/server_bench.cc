// The server's throughput and footprint (issue 5), measured on the real motiondb-server binary
// on a loopback port with a temporary database:
//  1. ingest over gRPC (IngestClip, one client, every file of a labelled folder; default
//     ../shared/mocap/bandai2-normal): frames/s for the first half, before any space exists,
//     and for the second half, into a skeleton with a space (each clip projected in the same
//     transaction and the resident index rebuilt aside and swapped);
//  2. searches per second and client-side p50/p99 latency with 1, 4 and 16 concurrent clients,
//     each on its own connection, every stored clip in turn as the query, default parameters;
//  3. the baseline: the same searches in process (server::RunSearch on the same database and
//     resident indices, no gRPC) with 1 and 2 threads;
//  4. the server's resident memory (VmRSS and its peak, VmHWM);
//  5. start to serving with hours of cached projections (synthetic clips at 30 Hz, stored
//     through the server's own library code): from exec to the first SERVING health answer,
//     and the server's resident memory then.
//
// usage: server_bench [--folder DIR] [--seconds S] [--hours H]
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "bench/measure.h"
#include "client/command_line.h"
#include "core/file_io.h"
#include "core/status_macros.h"
#include "core/synthetic_library.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "server/clip_facts.h"
#include "server/index_registry.h"
#include "server/library.h"
#include "server/search_request.h"
#include "storage/database.h"
#include "tests/server_process.h"

namespace motiondb {
namespace {

using bench::Clock;
using bench::Percentile;
using bench::SecondsSince;

// A field of /proc/PID/status in MiB (VmRSS, VmHWM).
double StatusMiB(pid_t pid, const std::string& field) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::atof(line.c_str() + field.size() + 1) / 1024;
  }
  return 0;
}

absl::Status FromGrpc(const grpc::Status& status, const std::string& what) {
  if (status.ok()) return absl::OkStatus();
  return absl::InternalError(absl::StrCat(what, ": ", status.error_message()));
}

// Its own connection, as a separate client process would have.
std::shared_ptr<grpc::Channel> OwnConnection(const std::string& address) {
  grpc::ChannelArguments arguments;
  arguments.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
  arguments.SetMaxReceiveMessageSize(-1);
  return grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), arguments);
}

struct Throughput {
  double qps = 0;
  std::vector<double> latencies_ms;
};

// `threads` workers call `search(worker, k)` for their k-th query until `seconds` have passed
// (after a warm-up of a quarter second that is not counted).
template <typename SearchFn>
absl::StatusOr<Throughput> Measure(int threads, double seconds, SearchFn search) {
  std::atomic<bool> failed{false};
  std::string failure;
  std::vector<std::vector<double>> latencies(threads);
  std::vector<int64_t> counted(threads, 0);
  const Clock::time_point warm = Clock::now() + std::chrono::milliseconds(250);
  const Clock::time_point end =
      warm + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  std::vector<std::thread> workers;
  for (int t = 0; t < threads; ++t) {
    workers.emplace_back([&, t] {
      for (int64_t k = 0; !failed; ++k) {
        const Clock::time_point start = Clock::now();
        if (start >= end) break;
        const absl::Status status = search(t, k);
        if (!status.ok()) {
          if (!failed.exchange(true)) failure = status.ToString();
          break;
        }
        if (start >= warm) {
          latencies[t].push_back(
              std::chrono::duration<double, std::milli>(Clock::now() - start).count());
          ++counted[t];
        }
      }
    });
  }
  for (std::thread& worker : workers) worker.join();
  if (failed) return absl::InternalError(failure);
  Throughput result;
  int64_t total = 0;
  for (int t = 0; t < threads; ++t) {
    total += counted[t];
    result.latencies_ms.insert(result.latencies_ms.end(), latencies[t].begin(), latencies[t].end());
  }
  result.qps = static_cast<double>(total) / seconds;
  return result;
}

// `server_ms`: the latencies the server logged for the same calls (empty in process).
void PrintThroughput(const std::string& label, const Throughput& t,
                     const std::vector<double>& server_ms = {}) {
  std::printf("| %s | %.0f | %.2f | %.2f | %s |\n", label.c_str(), t.qps,
              Percentile(t.latencies_ms, 0.5), Percentile(t.latencies_ms, 0.99),
              server_ms.empty() ? "" : absl::StrFormat("%.2f", Percentile(server_ms, 0.5)).c_str());
}

// The latencies of the searches the server logged after the first `from` bytes of its log.
std::vector<double> LoggedSearchMs(const std::string& log, size_t from) {
  static const std::regex line("SearchService/Search OK ([0-9.]+)ms");
  std::vector<double> ms;
  for (auto it = std::sregex_iterator(log.begin() + from, log.end(), line);
       it != std::sregex_iterator(); ++it) {
    ms.push_back(std::stod((*it)[1]));
  }
  return ms;
}

v1::SearchRequest QueryOf(int64_t clip_id) {
  v1::SearchRequest request;
  request.set_space("bench");
  request.mutable_clip()->set_clip_id(clip_id);
  return request;
}

absl::StatusOr<std::vector<std::filesystem::path>> BvhFiles(const std::filesystem::path& folder) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() == ".bvh") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  if (files.size() < 4)
    return absl::NotFoundError(absl::StrCat(folder.string(), ": too few BVH files"));
  return files;
}

// Ingests `files` one by one; returns the frames stored.
absl::StatusOr<int64_t> Ingest(v1::ClipService::Stub& clips,
                               const std::vector<std::filesystem::path>& files,
                               std::vector<int64_t>& ids) {
  int64_t frames = 0;
  for (const std::filesystem::path& file : files) {
    v1::IngestClipRequest request;
    request.set_file_name(file.filename().string());
    MOTIONDB_ASSIGN_OR_RETURN(*request.mutable_bvh(),
                              ReadFileBytes(file.string(), int64_t{1} << 30));
    v1::IngestClipResponse response;
    grpc::ClientContext context;
    MOTIONDB_RETURN_IF_ERROR(
        FromGrpc(clips.IngestClip(&context, request, &response), "IngestClip " + file.string()));
    ids.push_back(response.clip().clip_id());
    frames += response.clip().frame_count();
  }
  return frames;
}

absl::Status ServedSearches(const std::filesystem::path& folder, double seconds,
                            const std::filesystem::path& work) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<std::filesystem::path> files, BvhFiles(folder));
  const std::string db = (work / "bandai.sqlite").string();
  testing::ServerProcess server;
  std::string error;
  if (!server.Start({"--db", db}, &error)) return absl::InternalError(error);
  const std::shared_ptr<grpc::Channel> channel = OwnConnection(server.address());
  if (!testing::WaitUntilServing(channel, "")) return absl::InternalError("server not serving");
  auto clips = v1::ClipService::NewStub(channel);
  auto spaces = v1::SpaceService::NewStub(channel);

  const size_t half = files.size() / 2;
  std::vector<int64_t> ids;
  Clock::time_point start = Clock::now();
  MOTIONDB_ASSIGN_OR_RETURN(
      const int64_t first_frames,
      Ingest(*clips, std::vector<std::filesystem::path>(files.begin(), files.begin() + half), ids));
  const double first_s = SecondsSince(start);

  start = Clock::now();
  v1::CreateSpaceRequest create;
  create.set_name("bench");
  v1::Space created;
  {
    grpc::ClientContext context;
    MOTIONDB_RETURN_IF_ERROR(
        FromGrpc(spaces->CreateSpace(&context, create, &created), "CreateSpace"));
  }
  const double create_s = SecondsSince(start);

  start = Clock::now();
  MOTIONDB_ASSIGN_OR_RETURN(
      const int64_t second_frames,
      Ingest(*clips, std::vector<std::filesystem::path>(files.begin() + half, files.end()), ids));
  const double second_s = SecondsSince(start);

  std::printf("## Ingest over gRPC (IngestClip, one client), %s\n\n", folder.c_str());
  std::printf(
      "| phase | files | frames | seconds | frames/s | files/s "
      "|\n|---|---:|---:|---:|---:|---:|\n");
  std::printf("| no space yet | %zu | %lld | %.2f | %.0f | %.0f |\n", half,
              static_cast<long long>(first_frames), first_s, first_frames / first_s,
              half / first_s);
  std::printf(
      "| into a skeleton with a space (projection + index swap per clip) | %zu | %lld | "
      "%.2f | %.0f | %.0f |\n",
      files.size() - half, static_cast<long long>(second_frames), second_s,
      second_frames / second_s, (files.size() - half) / second_s);
  std::printf("\nCreateSpace over the first half (%zu clips): %.2f s\n", half, create_s);

  std::printf("\n## Search, every clip in turn as the query, default parameters\n\n");
  std::printf(
      "| client | searches/s | p50 ms | p99 ms | server-side p50 ms |\n"
      "|---|---:|---:|---:|---:|\n");
  double best_served = 0;
  for (int clients : {1, 4, 16}) {
    std::vector<std::unique_ptr<v1::SearchService::Stub>> stubs;
    for (int c = 0; c < clients; ++c) {
      stubs.push_back(v1::SearchService::NewStub(OwnConnection(server.address())));
    }
    const size_t log_before = server.Log().size();
    MOTIONDB_ASSIGN_OR_RETURN(
        const Throughput served, Measure(clients, seconds, [&](int worker, int64_t k) {
          const v1::SearchRequest request = QueryOf(ids[(worker * 7919 + k) % ids.size()]);
          v1::SearchResponse response;
          grpc::ClientContext context;
          return FromGrpc(stubs[worker]->Search(&context, request, &response), "Search");
        }));
    PrintThroughput(absl::StrCat("gRPC, ", clients, clients == 1 ? " client" : " clients"), served,
                    LoggedSearchMs(server.Log(), log_before));
    best_served = std::max(best_served, served.qps);
  }
  const double rss = StatusMiB(server.pid(), "VmRSS"), hwm = StatusMiB(server.pid(), "VmHWM");
  const std::string log = server.Log();
  if (server.Stop(SIGTERM) != 0) return absl::InternalError("the server did not stop cleanly");

  // The baseline: the server's own search code on the same database, without gRPC.
  MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<storage::Database> database,
                            storage::Database::Open(db));
  server::IndexRegistry registry;
  server::ClipFactsCache facts(*database);
  server::Library library(*database, registry, facts);
  MOTIONDB_RETURN_IF_ERROR(library.LoadIndices());
  double best_in_process = 0;
  for (int threads : {1, 2}) {
    MOTIONDB_ASSIGN_OR_RETURN(
        const Throughput local, Measure(threads, seconds, [&](int worker, int64_t k) {
          return server::RunSearch(QueryOf(ids[(worker * 7919 + k) % ids.size()]), registry,
                                   *database, {}, [] { return false; })
              .status();
        }));
    PrintThroughput(absl::StrCat("in process, ", threads, threads == 1 ? " thread" : " threads"),
                    local);
    best_in_process = std::max(best_in_process, local.qps);
  }
  std::printf("\nserved / in-process throughput (best of each): %.2f\n",
              best_served / best_in_process);
  std::printf("server resident memory after the searches: VmRSS %.0f MiB, peak VmHWM %.0f MiB\n",
              rss, hwm);
  std::printf("requests logged: %lld\n\n",
              static_cast<long long>(std::count(log.begin(), log.end(), '\n')));
  return absl::OkStatus();
}

// Stores `hours` of synthetic clips at 30 Hz and a space over them through the server's own
// library code, then times the server from exec to serving.
absl::Status StartToServing(double hours, const std::filesystem::path& work) {
  const std::string db = (work / "synthetic.sqlite").string();
  Clock::time_point start = Clock::now();
  int64_t frames = 0;
  {
    SyntheticLibraryOptions options;
    options.fps = 30;
    options.target_duration_s = hours * 3600;
    MOTIONDB_ASSIGN_OR_RETURN(SyntheticLibrary generated, GenerateSyntheticLibrary(options));
    MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<storage::Database> database,
                              storage::Database::Open(db));
    server::IndexRegistry registry;
    server::ClipFactsCache facts(*database);
    server::Library library(*database, registry, facts);
    int64_t first_id = 0;
    for (size_t c = 0; c < generated.clips.size(); ++c) {
      storage::ClipRecord record;
      record.name = absl::StrCat("synthetic_", c);
      record.source_file = record.name + ".bvh";
      MOTIONDB_ASSIGN_OR_RETURN(const server::IngestedClip ingested,
                                library.IngestClip(record, generated.clips[c]));
      if (c == 0) first_id = ingested.clip_id;
      frames += generated.clips[c].frame_count();
    }
    server::SpaceRequest space;
    space.name = "synthetic";
    space.training = {{first_id, std::nullopt, std::nullopt}};
    MOTIONDB_RETURN_IF_ERROR(library.CreateSpace(space, [] { return false; }).status());
  }
  const double prepare_s = SecondsSince(start);
  const double db_mib = std::filesystem::file_size(db) / 1048576.0;

  testing::ServerProcess server;
  std::string error;
  start = Clock::now();
  if (!server.Start({"--db", db}, &error, std::chrono::seconds(600))) {
    return absl::InternalError(error);
  }
  if (!testing::WaitUntilServing(OwnConnection(server.address()), "", std::chrono::seconds(600))) {
    return absl::InternalError("the server did not start serving");
  }
  const double serving_s = SecondsSince(start);
  const double rss = StatusMiB(server.pid(), "VmRSS"), hwm = StatusMiB(server.pid(), "VmHWM");
  const std::string log = server.Log();
  server.Stop(SIGTERM);
  std::smatch loaded;
  const std::string load_line =
      std::regex_search(log, loaded, std::regex("loaded [^\n]*")) ? loaded.str() : "(no line)";
  std::printf("## Start to serving with %.1f h of cached projections\n\n", hours);
  std::printf("%lld frames at 30 Hz in one space; database %.0f MiB, prepared in %.1f s\n",
              static_cast<long long>(frames), db_mib, prepare_s);
  std::printf("exec to first SERVING health answer: %.2f s (server log: %s)\n", serving_s,
              load_line.c_str());
  std::printf("server resident memory when serving: VmRSS %.0f MiB, peak VmHWM %.0f MiB\n", rss,
              hwm);
  return absl::OkStatus();
}

absl::Status Run(const cli::CommandLine& line) {
  const char* env = std::getenv("MOTIONDB_MOCAP_DIR");
  const std::filesystem::path mocap = env != nullptr ? env : MOTIONDB_MOCAP_DIR;
  const std::filesystem::path folder =
      line.value("folder").value_or((mocap / "bandai2-normal").string());
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<double> seconds, line.number("seconds"));
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<double> hours, line.number("hours"));
  const std::filesystem::path work = std::filesystem::temp_directory_path() /
                                     ("motiondb_server_bench_" + std::to_string(getpid()));
  std::filesystem::create_directories(work);
  absl::Status status = absl::OkStatus();
  if (std::filesystem::is_directory(folder)) {
    status = ServedSearches(folder, seconds.value_or(5.0), work);
  } else {
    std::printf("%s is absent; the ingest and search measurements are skipped\n", folder.c_str());
  }
  if (status.ok() && hours.value_or(10.0) > 0) status = StartToServing(hours.value_or(10.0), work);
  std::filesystem::remove_all(work);
  return status;
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  const absl::StatusOr<motiondb::cli::CommandLine> line = motiondb::cli::CommandLine::Parse(
      std::vector<std::string>(argv + 1, argv + argc), {"folder", "seconds", "hours"}, {});
  const absl::Status status = line.ok() ? motiondb::Run(*line) : line.status();
  if (!status.ok()) {
    std::fprintf(stderr, "server_bench: %s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
