// The HTTP face beside gRPC (issue 14), on one real motiondb-server over loopback with the demo
// library as scripts/start.sh --demo loads it (Debian's assimp-testmodels BVH files with the
// space "demo", and ../shared/mocap/bandai2-normal with the space "bandai" when it is there):
//  1. searches per second and client-side p50/p99 latency over gRPC and over HTTP (POST
//     /v1/search, JSON both ways, parsed into the response message as a client would), with 1
//     and 4 clients each on its own connection, every clip of the larger space in turn as the
//     query (its first 2 s); the two faces measured in alternating turns, so that both see the
//     same machine;
//  2. the time of a GET /metrics scrape, one connection, one scrape after another.
//
// usage: http_bench [--seconds S] [--turns N] [--scrapes N]
#include <signal.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <google/protobuf/util/json_util.h>
#include <grpcpp/grpcpp.h>

#include <CLI/CLI.hpp>

#include "absl/strings/str_cat.h"
#include "bench/measure.h"
#include "bench/throughput.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "testing/server_process.h"
#include "util/cli_conventions.h"
#include "util/file_io.h"
#include "util/status_macros.h"

// Last: httplib.h includes <resolv.h>, whose _res macro breaks the Eigen headers above.
#include <httplib.h>

namespace motiondb {
namespace {

using bench::Clock;
using bench::FromGrpc;
using bench::OwnConnection;
using bench::Percentile;
using bench::Throughput;

constexpr char kDemoFolder[] = "/usr/share/assimp/models/BVH";
constexpr char kBandaiFolder[] = "bandai2-normal";  // in the shared mocap folder, when there
constexpr double kQuerySeconds = 2;

// Ingests every BVH file of `folder` and builds the space `name` on the first one's skeleton, as
// scripts/start.sh --demo does; returns a query per clip of that skeleton (its first
// kQuerySeconds).
absl::StatusOr<std::vector<v1::SearchRequest>> LoadSpace(
    const std::shared_ptr<grpc::Channel>& channel, const std::filesystem::path& folder,
    const std::string& name) {
  auto clips = v1::ClipService::NewStub(channel);
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() == ".bvh") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  int64_t skeleton = 0;
  for (const std::filesystem::path& file : files) {
    v1::IngestClipRequest request;
    request.set_file_name(file.filename().string());
    MOTIONDB_ASSIGN_OR_RETURN(*request.mutable_bvh(),
                              ReadFileBytes(file.string(), int64_t{1} << 30));
    v1::IngestClipResponse response;
    grpc::ClientContext context;
    // Files the reader refuses are left out, as start.sh's ingest leaves them.
    if (clips->IngestClip(&context, request, &response).ok() && skeleton == 0) {
      skeleton = response.clip().skeleton_id();
    }
  }
  if (skeleton == 0) return absl::NotFoundError(absl::StrCat(folder.string(), ": no BVH files"));
  v1::CreateSpaceRequest space;
  space.set_name(name);
  space.set_skeleton_id(skeleton);
  v1::Space created;
  grpc::ClientContext space_context;
  MOTIONDB_RETURN_IF_ERROR(
      FromGrpc(v1::SpaceService::NewStub(channel)->CreateSpace(&space_context, space, &created),
               "CreateSpace"));
  v1::ListClipsRequest list;
  list.set_skeleton_id(skeleton);
  list.set_page_size(1000);
  v1::ListClipsResponse listed;
  grpc::ClientContext list_context;
  MOTIONDB_RETURN_IF_ERROR(FromGrpc(clips->ListClips(&list_context, list, &listed), "ListClips"));
  std::vector<v1::SearchRequest> queries;
  for (const v1::Clip& clip : listed.clips()) {
    v1::SearchRequest& query = queries.emplace_back();
    query.set_space(name);
    query.mutable_clip()->set_clip_id(clip.clip_id());
    query.mutable_clip()->set_first_frame(0);
    query.mutable_clip()->set_last_frame(
        std::min(clip.frame_count() - 1, static_cast<int>(kQuerySeconds * clip.fps())));
  }
  std::printf("space %s: %zu files of %s, %d clips, %lld frames indexed at %.0f Hz\n", name.c_str(),
              files.size(), folder.string().c_str(), listed.clips_size(),
              static_cast<long long>(created.index().frames()), created.report().sample_rate());
  return queries;
}

absl::StatusOr<Throughput> MeasureGrpc(const std::string& address, int clients, double seconds,
                                       const std::vector<v1::SearchRequest>& queries) {
  std::vector<std::unique_ptr<v1::SearchService::Stub>> stubs;
  for (int c = 0; c < clients; ++c)
    stubs.push_back(v1::SearchService::NewStub(OwnConnection(address)));
  return bench::Measure(clients, seconds, [&](int worker, int64_t k) {
    const v1::SearchRequest& request = queries[(worker * 7919 + k) % queries.size()];
    v1::SearchResponse response;
    grpc::ClientContext context;
    return FromGrpc(stubs[worker]->Search(&context, request, &response), "Search");
  });
}

absl::StatusOr<Throughput> MeasureHttp(int port, int clients, double seconds,
                                       const std::vector<std::string>& bodies) {
  std::vector<std::unique_ptr<httplib::Client>> connections;
  for (int c = 0; c < clients; ++c) {
    connections.push_back(std::make_unique<httplib::Client>("127.0.0.1", port));
    connections.back()->set_keep_alive(true);
    connections.back()->set_tcp_nodelay(true);  // as browsers do
  }
  return bench::Measure(clients, seconds, [&](int worker, int64_t k) -> absl::Status {
    const std::string& body = bodies[(worker * 7919 + k) % bodies.size()];
    const httplib::Result result =
        connections[worker]->Post("/v1/search", body, "application/json");
    if (!result) return absl::UnavailableError(httplib::to_string(result.error()));
    if (result->status != 200) return absl::InternalError(result->body);
    v1::SearchResponse response;
    const auto parsed = google::protobuf::util::JsonStringToMessage(result->body, &response);
    return parsed.ok() ? absl::OkStatus() : absl::InternalError(parsed.ToString());
  });
}

void PrintRow(const std::string& label, const Throughput& t) {
  std::printf("| %s | %.0f | %.2f | %.2f |\n", label.c_str(), t.qps,
              Percentile(t.latencies_ms, 0.5), Percentile(t.latencies_ms, 0.99));
}

// One scrape after another on one connection: p50 and p99 ms, and the body's size.
absl::Status MeasureScrapes(int port, int scrapes) {
  httplib::Client client("127.0.0.1", port);
  client.set_keep_alive(true);
  client.set_tcp_nodelay(true);
  std::vector<double> ms;
  size_t bytes = 0;
  for (int i = 0; i < scrapes; ++i) {
    const Clock::time_point start = Clock::now();
    const httplib::Result result = client.Get("/metrics");
    if (!result || result->status != 200) return absl::InternalError("GET /metrics failed");
    ms.push_back(1000 * bench::SecondsSince(start));
    bytes = result->body.size();
  }
  std::printf(
      "\nGET /metrics, %d scrapes one after another: p50 %.3f ms, p99 %.3f ms, max %.3f ms "
      "(%zu bytes)\n",
      scrapes, Percentile(ms, 0.5), Percentile(ms, 0.99), Percentile(ms, 1.0), bytes);
  return absl::OkStatus();
}

absl::Status Run(double seconds, int turns, int scrapes) {
  const std::filesystem::path work =
      std::filesystem::temp_directory_path() / absl::StrCat("http_bench_", getpid());
  std::filesystem::create_directories(work);
  testing::ServerProcess server;
  std::string error;
  if (!server.Start({"--db", (work / "db.sqlite").string(), "--quiet"}, &error)) {
    return absl::InternalError(error);
  }
  // The demo library of scripts/start.sh --demo; searches in its larger space when it has two.
  const auto channel = testing::InsecureChannel(server.address());
  MOTIONDB_ASSIGN_OR_RETURN(std::vector<v1::SearchRequest> queries,
                            LoadSpace(channel, kDemoFolder, "demo"));
  if (std::filesystem::is_directory(bench::MocapRoot() / kBandaiFolder)) {
    MOTIONDB_ASSIGN_OR_RETURN(queries,
                              LoadSpace(channel, bench::MocapRoot() / kBandaiFolder, "bandai"));
  }
  std::vector<std::string> bodies;
  google::protobuf::util::JsonPrintOptions compact;
  for (const v1::SearchRequest& query : queries) {
    (void)google::protobuf::util::MessageToJsonString(query, &bodies.emplace_back(), compact);
  }
  std::printf("\n## Search in %s over gRPC and over HTTP, %d turns of %.1f s each way\n\n",
              queries.front().space().c_str(), turns, seconds / turns);
  std::printf("| face, clients | searches/s | p50 ms | p99 ms |\n|---|---:|---:|---:|\n");
  for (const int clients : {1, 4}) {
    Throughput grpc_total, http_total;
    for (int turn = 0; turn < turns; ++turn) {
      MOTIONDB_ASSIGN_OR_RETURN(const Throughput grpc_part,
                                MeasureGrpc(server.address(), clients, seconds / turns, queries));
      bench::Add(grpc_part, turns, grpc_total);
      MOTIONDB_ASSIGN_OR_RETURN(const Throughput http_part,
                                MeasureHttp(server.http_port(), clients, seconds / turns, bodies));
      bench::Add(http_part, turns, http_total);
    }
    PrintRow(absl::StrCat("gRPC, ", clients), grpc_total);
    PrintRow(absl::StrCat("HTTP/JSON, ", clients), http_total);
    std::printf("| HTTP / gRPC searches/s | %.2f | | |\n", http_total.qps / grpc_total.qps);
  }
  MOTIONDB_RETURN_IF_ERROR(MeasureScrapes(server.http_port(), scrapes));
  server.Stop(SIGTERM);
  std::filesystem::remove_all(work);
  return absl::OkStatus();
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  CLI::App app("http_bench: searches over HTTP beside gRPC on the demo library, and /metrics",
               "http_bench");
  double seconds = 20;
  int turns = 4;
  int scrapes = 500;
  app.add_option("--seconds", seconds, "measured seconds per face and client count")
      ->capture_default_str();
  app.add_option("--turns", turns, "alternating turns the seconds are split into")
      ->capture_default_str();
  app.add_option("--scrapes", scrapes, "GET /metrics calls timed")->capture_default_str();
  if (const std::optional<int> exit_code = motiondb::cli::ParseCommandLine(app, argc, argv)) {
    return *exit_code;
  }
  const absl::Status status = motiondb::Run(seconds, turns, scrapes);
  if (!status.ok()) {
    std::fprintf(stderr, "http_bench: %s\n", status.ToString().c_str());
    return 1;
  }
  return 0;
}
