// The server's throughput and footprint (issue 5), measured on the real motiondb-server binary
// on a loopback port with a temporary database:
//  1. ingest over gRPC (IngestClip, one client, every file of a labelled folder; default
//     ../shared/mocap/bandai2-normal): frames/s for the first half, before any space exists,
//     and for the second half, into a skeleton with a space (each clip projected in the same
//     transaction and the resident index rebuilt aside and swapped);
//  2. searches per second and client-side p50/p99 latency with 1, 2, 4 and 16 concurrent
//     clients, each on its own connection, every stored clip in turn as the query, default
//     parameters, and again with each search on one thread (SearchRequest.threads = 1);
//  3. the baseline: the same searches in process (server::SearchRunner on the same database and
//     indices loaded as the server loads them, no gRPC) with 1 and 2 threads, measured in turns
//     interleaved with the served ones;
//  4. the server's resident memory (VmRSS and its peak, VmHWM);
//  5. start to serving with hours of cached projections (synthetic clips at 30 Hz, stored
//     through the server's own library code): from exec to the first SERVING health answer,
//     and the server's resident memory then; then ingest over gRPC into that library, and a
//     backup of it while a client ingests (its rate, and the ingest latency during it beside
//     the latency just before).
//
// usage: server_bench [--folder DIR] [--seconds S] [--hours H]
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
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
#include "bench/synthetic_library.h"
#include "bench/throughput.h"
#include "core/bvh/bvh_writer.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "motiondb/v1/server_service.grpc.pb.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "server/catalog.h"
#include "server/index_registry.h"
#include "server/search_runner.h"
#include "storage/database.h"
#include "testing/server_process.h"
#include "testing/synthetic_corpus.h"
#include "util/cli_conventions.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using bench::Add;
using bench::Clock;
using bench::FromGrpc;
using bench::Measure;
using bench::MocapRoot;
using bench::OwnConnection;
using bench::Percentile;
using bench::SecondsSince;
using bench::StatusMiB;
using bench::Throughput;
using testing::GenerateSyntheticCorpus;
using testing::SyntheticCorpus;
using testing::SyntheticCorpusOptions;

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

v1::SearchRequest QueryOf(int64_t clip_id, const std::string& space = "bench") {
  v1::SearchRequest request;
  request.set_space(space);
  request.mutable_clip()->set_clip_id(clip_id);
  return request;
}

// Client-side latencies of searches by 2.8 s ranges of `clip_id` (one every 10 s of it) in
// `space`, one at a time, in ms.
absl::StatusOr<std::vector<double>> TimeSearches(const std::string& address,
                                                 const std::string& space, int64_t clip_id,
                                                 int count) {
  auto stub = v1::SearchService::NewStub(OwnConnection(address));
  std::vector<double> ms;
  for (int i = 0; i < count; ++i) {
    v1::SearchRequest request = QueryOf(clip_id, space);
    request.mutable_clip()->set_first_frame(300 * i);
    request.mutable_clip()->set_last_frame(300 * i + 83);
    v1::SearchResponse response;
    grpc::ClientContext context;
    const Clock::time_point sent = Clock::now();
    MOTIONDB_RETURN_IF_ERROR(FromGrpc(stub->Search(&context, request, &response), "Search"));
    ms.push_back(1000 * SecondsSince(sent));
  }
  return ms;
}

// Searches from `clients` clients, each on its own connection to `address`, every clip of `ids`
// in turn as the query, each search on `search_threads` threads (0: the server's choice).
absl::StatusOr<Throughput> MeasureServed(const std::string& address, int clients, double seconds,
                                         const std::vector<int64_t>& ids, int search_threads = 0) {
  std::vector<std::unique_ptr<v1::SearchService::Stub>> stubs;
  for (int c = 0; c < clients; ++c) {
    stubs.push_back(v1::SearchService::NewStub(OwnConnection(address)));
  }
  return Measure(clients, seconds, [&](int worker, int64_t k) {
    v1::SearchRequest request = QueryOf(ids[(worker * 7919 + k) % ids.size()]);
    if (search_threads > 0) request.set_threads(search_threads);
    v1::SearchResponse response;
    grpc::ClientContext context;
    return FromGrpc(stubs[worker]->Search(&context, request, &response), "Search");
  });
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

  // The server that did the ingests, before any restart: its index holds the recent clips in a
  // second kd-tree (core/library_index.h).
  MOTIONDB_ASSIGN_OR_RETURN(const Throughput after_ingest,
                            MeasureServed(server.address(), 4, 1.0, ids));
  const double ingest_rss = StatusMiB(server.pid(), "VmRSS");
  if (server.Stop(SIGTERM) != 0) return absl::InternalError("the server did not stop cleanly");

  // The baseline: the server's own search code on the same database and indices loaded as the
  // server loads them, without gRPC.
  MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<storage::Database> database,
                            storage::Database::Open(db));
  server::IndexRegistry registry;
  server::Catalog catalog(*database, registry);
  MOTIONDB_RETURN_IF_ERROR(catalog.LoadIndices());
  const server::SearchRunner runner(registry, *database, {});

  // Served and in-process searching take turns of a second or so (the server started afresh for
  // each turn, and stopped while the baseline runs), so that a change in the speed of the
  // machine, which is shared, weighs on both alike.
  struct Way {
    std::string label;
    int threads = 1;
    bool served = false;
    int search_threads = 0;  // served: each search's threads (0: the server's choice)
    Throughput total;
    std::vector<double> server_ms;  // as the server logged them
  };
  std::vector<Way> ways;
  // Each search on every core while it runs alone, one beside others (the server's choice), and
  // on one thread always, as before SearchParams::threads.
  for (int clients : {1, 2, 4, 16}) {
    for (int search_threads : {0, 1}) {
      ways.push_back({absl::StrCat("gRPC, ", clients, clients == 1 ? " client" : " clients",
                                   search_threads == 1 ? ", one thread a search" : ""),
                      clients,
                      true,
                      search_threads,
                      {},
                      {}});
    }
  }
  for (int threads : {1, 2}) {
    ways.push_back({absl::StrCat("in process, ", threads, threads == 1 ? " thread" : " threads"),
                    threads,
                    false,
                    0,
                    {},
                    {}});
  }
  const int turns = std::max(1, static_cast<int>(seconds));
  double rss = 0, hwm = 0;
  int64_t logged_searches = 0;
  for (int turn = 0; turn < turns; ++turn) {
    testing::ServerProcess turn_server;
    if (!turn_server.Start({"--db", db}, &error)) return absl::InternalError(error);
    if (!testing::WaitUntilServing(OwnConnection(turn_server.address()), "")) {
      return absl::InternalError("the server did not start serving");
    }
    for (Way& way : ways) {
      if (way.served != true) continue;
      const size_t log_before = turn_server.Log().size();
      MOTIONDB_ASSIGN_OR_RETURN(const Throughput part,
                                MeasureServed(turn_server.address(), way.threads, seconds / turns,
                                              ids, way.search_threads));
      Add(part, turns, way.total);
      const std::vector<double> logged = LoggedSearchMs(turn_server.Log(), log_before);
      way.server_ms.insert(way.server_ms.end(), logged.begin(), logged.end());
    }
    rss = StatusMiB(turn_server.pid(), "VmRSS");
    hwm = StatusMiB(turn_server.pid(), "VmHWM");
    logged_searches += static_cast<int64_t>(LoggedSearchMs(turn_server.Log(), 0).size());
    if (turn_server.Stop(SIGTERM) != 0) {
      return absl::InternalError("the server did not stop cleanly");
    }
    for (Way& way : ways) {
      if (way.served) continue;
      MOTIONDB_ASSIGN_OR_RETURN(const Throughput part,
                                Measure(way.threads, seconds / turns, [&](int worker, int64_t k) {
                                  server::SearchRequest request;
                                  request.space = "bench";
                                  server::ClipSelection query;
                                  query.clip_id = ids[(worker * 7919 + k) % ids.size()];
                                  request.query = query;
                                  return runner.Run(request, [] { return false; }).status();
                                }));
      Add(part, turns, way.total);
    }
  }
  std::printf("\n## Search, every clip in turn as the query, default parameters\n\n");
  std::printf(
      "| client | searches/s | p50 ms | p99 ms | server-side p50 ms |\n"
      "|---|---:|---:|---:|---:|\n");
  double best_served = 0, best_in_process = 0;
  for (const Way& way : ways) {
    PrintThroughput(way.label, way.total, way.server_ms);
    double& best = way.served ? best_served : best_in_process;
    best = std::max(best, way.total.qps);
  }
  std::printf("\nserved / in-process throughput (best of each): %.2f\n",
              best_served / best_in_process);
  std::printf(
      "the server that did the ingests, before a restart, 4 clients for 1 s: %.0f/s, "
      "p50 %.2f ms\n",
      after_ingest.qps, Percentile(after_ingest.latencies_ms, 0.5));
  std::printf("server resident memory after the ingests: VmRSS %.0f MiB\n", ingest_rss);
  std::printf(
      "server resident memory after a turn of searches (restarted): VmRSS %.0f MiB, peak "
      "VmHWM %.0f MiB\n",
      rss, hwm);
  std::printf("searches the server logged in the turns: %lld\n\n",
              static_cast<long long>(logged_searches));
  return absl::OkStatus();
}

// Stores `hours` of synthetic clips at 30 Hz and a space over them through the server's own
// library code, then times the server from exec to serving.
struct BackupRun {
  double mib = 0;
  double seconds = 0;
  std::vector<double> alone_ms;   // of each of 32 clips ingested just before, without a backup
  std::vector<double> ingest_ms;  // of each clip ingested while the backup ran
};

// A backup streamed to a file under `work` while another thread ingests `texts` again and
// again through `ingest` (returning each call's latency), beside as many ingests just before
// without a backup: what the backup costs writers.
template <typename Ingest>
absl::StatusOr<BackupRun> BackupDuringIngest(const std::string& address,
                                             const std::filesystem::path& work,
                                             const std::vector<std::string>& texts,
                                             const Ingest& ingest) {
  BackupRun run;
  for (size_t i = 0; i < 32; ++i) {
    MOTIONDB_ASSIGN_OR_RETURN(run.alone_ms.emplace_back(),
                              ingest(absl::StrCat("before_", i), texts[i % texts.size()]));
  }
  std::atomic<bool> done = false;
  absl::Status ingest_status;
  std::thread writer([&] {
    // At least one clip lands inside the backup, however short it is.
    for (size_t i = 0; ingest_status.ok() && (i == 0 || !done); ++i) {
      absl::StatusOr<double> ms = ingest(absl::StrCat("during_", i), texts[i % texts.size()]);
      if (ms.ok()) {
        run.ingest_ms.push_back(*ms);
      } else {
        ingest_status = ms.status();
      }
    }
  });
  const std::filesystem::path copy = work / "backup.sqlite";
  auto stub = v1::ServerService::NewStub(OwnConnection(address));
  grpc::ClientContext context;
  const Clock::time_point start = Clock::now();
  auto reader = stub->CreateBackup(&context, v1::CreateBackupRequest());
  {
    std::ofstream file(copy, std::ios::binary);
    v1::BackupChunk chunk;
    while (reader->Read(&chunk)) file << chunk.data();
  }
  const grpc::Status status = reader->Finish();
  run.seconds = SecondsSince(start);
  done = true;
  writer.join();
  MOTIONDB_RETURN_IF_ERROR(FromGrpc(status, "CreateBackup"));
  MOTIONDB_RETURN_IF_ERROR(ingest_status);
  run.mib = std::filesystem::file_size(copy) / 1048576.0;
  std::filesystem::remove(copy);
  return run;
}

absl::Status StartToServing(double hours, const std::filesystem::path& work) {
  const std::string db = (work / "synthetic.sqlite").string();
  Clock::time_point start = Clock::now();
  MOTIONDB_ASSIGN_OR_RETURN(const bench::StoredLibrary library,
                            bench::StoreSyntheticLibrary(db, hours, 30, "synthetic"));
  const int64_t frames = library.frames, first_id = library.clip_ids.front();
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
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<double> search_ms,
                            TimeSearches(server.address(), "synthetic", first_id, 20));

  // Ingest into the large library: 10 clips of a minute, projected and indexed on arrival.
  SyntheticCorpusOptions extra;
  extra.seed = 2;
  extra.fps = 30;
  extra.target_duration_s = 600;
  extra.max_clip_duration_s = 60;
  MOTIONDB_ASSIGN_OR_RETURN(const SyntheticCorpus more, GenerateSyntheticCorpus(extra));
  std::vector<std::string> texts;
  int64_t more_frames = 0;
  for (const Clip& clip : more.clips) {
    MOTIONDB_ASSIGN_OR_RETURN(texts.emplace_back(), WriteBvh(clip));
    more_frames += clip.frame_count();
  }
  auto clips = v1::ClipService::NewStub(OwnConnection(server.address()));
  // One clip ingested as `name`; its latency in ms.
  const auto ingest = [&clips](const std::string& name,
                               const std::string& text) -> absl::StatusOr<double> {
    v1::IngestClipRequest request;
    request.set_file_name(name + ".bvh");
    request.set_bvh(text);
    v1::IngestClipResponse response;
    grpc::ClientContext context;
    const Clock::time_point sent = Clock::now();
    MOTIONDB_RETURN_IF_ERROR(
        FromGrpc(clips->IngestClip(&context, request, &response), "IngestClip"));
    return 1000 * SecondsSince(sent);
  };
  start = Clock::now();
  for (size_t c = 0; c < texts.size(); ++c) {
    MOTIONDB_RETURN_IF_ERROR(ingest(absl::StrCat("extra_", c), texts[c]).status());
  }
  const double ingest_s = SecondsSince(start);
  MOTIONDB_ASSIGN_OR_RETURN(const BackupRun backup,
                            BackupDuringIngest(server.address(), work, texts, ingest));
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
  std::printf(
      "searches over gRPC, one at a time (2.8 s ranges of the first clip, defaults): p50 %.2f "
      "ms, p99 %.2f ms (%zu)\n",
      Percentile(search_ms, 0.5), Percentile(search_ms, 0.99), search_ms.size());
  std::printf(
      "ingest into it over gRPC (each clip projected and indexed): %zu clips, %lld frames in "
      "%.2f s = %.0f frames/s, %.0f ms per clip\n",
      texts.size(), static_cast<long long>(more_frames), ingest_s, more_frames / ingest_s,
      1000 * ingest_s / texts.size());
  const auto latencies = [](const std::vector<double>& ms) {
    return absl::StrFormat("p50 %.1f ms, p90 %.1f ms, max %.1f ms (%d clips)", Percentile(ms, 0.5),
                           Percentile(ms, 0.9), *std::max_element(ms.begin(), ms.end()), ms.size());
  };
  std::printf(
      "backup (CreateBackup to a file) while one client ingests: %.0f MiB in %.2f s = %.0f "
      "MiB/s; ingest latency during it %s; just before, without a backup, %s\n",
      backup.mib, backup.seconds, backup.mib / backup.seconds, latencies(backup.ingest_ms).c_str(),
      latencies(backup.alone_ms).c_str());
  return absl::OkStatus();
}

struct BenchFlags {
  std::string folder = (MocapRoot() / "bandai2-normal").string();
  double seconds = 5.0;  // of each served-search measurement
  double hours = 10.0;   // of the start-up library (0: skip)
};

absl::Status Run(const BenchFlags& flags) {
  const std::filesystem::path folder = flags.folder;
  const std::filesystem::path work = std::filesystem::temp_directory_path() /
                                     ("motiondb_server_bench_" + std::to_string(getpid()));
  std::filesystem::create_directories(work);
  absl::Status status = absl::OkStatus();
  if (std::filesystem::is_directory(folder)) {
    status = ServedSearches(folder, flags.seconds, work);
  } else {
    std::printf("%s is absent; the ingest and search measurements are skipped\n", folder.c_str());
  }
  if (status.ok() && flags.hours > 0) status = StartToServing(flags.hours, work);
  std::filesystem::remove_all(work);
  return status;
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  CLI::App app("The server's throughput, ingest rate, start-up time and memory.", "server_bench");
  motiondb::BenchFlags flags;
  app.add_option("--folder", flags.folder, "labelled BVH folder to ingest and search")
      ->type_name("DIR")
      ->capture_default_str();
  app.add_option("--seconds", flags.seconds, "length of each served-search measurement")
      ->type_name("S")
      ->capture_default_str()
      ->check(motiondb::cli::NumberAbove(0));
  app.add_option("--hours", flags.hours, "hours of capture in the start-up library (0: skip)")
      ->type_name("H")
      ->capture_default_str()
      ->check(motiondb::cli::NumberAtLeast(0));
  if (const std::optional<int> exit_code = motiondb::cli::ParseCommandLine(app, argc, argv)) {
    return *exit_code;
  }
  const absl::Status status = motiondb::Run(flags);
  if (!status.ok()) {
    std::fprintf(stderr, "server_bench: %s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
