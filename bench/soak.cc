// A soak of the real server (issue 15, item 7): N clients, each on its own connection, run a mix
// of reads and writes for S seconds against a library that stays the same size (each client
// keeps at most a few clips of its own: it deletes its oldest when it ingests another). Beside
// them (issue 37, unless --no-hostile): HTTP clients calling the JSON API on new connections,
// slow HTTP clients, idle upload streams and floods of idle connections to both ports, with the
// server run under a low open-file limit (--max-open-files) and connection limits above what it
// holds, so that the floods run it out of descriptors. Reports the calls and their errors by
// method and status code, and the server's resident memory every few seconds; fails (exit 1) on
// any error of the mix (an HTTP refusal, 503, during a flood is none), when memory at the end
// exceeds 1.5x its highest level in the second fifth of the run (once warm), when a new gRPC
// connection is not served at the end, or on an unclean stop.
//
// usage: soak [--seconds 600] [--clients 16] [--sample-s 30] [--no-hostile]
//             [--max-open-files 1024]
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <map>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "absl/strings/str_cat.h"
#include "bench/call_context.h"
#include "bench/hostile_clients.h"
#include "bench/measure.h"
#include "core/bvh/bvh_writer.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "motiondb/v1/label_service.grpc.pb.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "testing/server_process.h"
#include "testing/synthetic_corpus.h"
#include "util/cli_conventions.h"
#include "util/status_macros.h"

// Last: httplib.h includes <resolv.h>, whose macro _res breaks Eigen's headers.
#include <httplib.h>

namespace motiondb {
namespace {

using bench::Clock;
using bench::SecondsSince;
using bench::StatusMiB;
using testing::GenerateSyntheticCorpus;
using testing::SyntheticCorpus;
using testing::SyntheticCorpusOptions;

struct Flags {
  double seconds = 600;
  int clients = 16;
  double sample_s = 30;
  bool hostile = true;
  int max_open_files = 1024;
};

// Clips of its own a client keeps; ingesting another deletes the oldest.
constexpr size_t kOwnClips = 3;

// Calls by method and status code, shared by the clients.
class CallTally {
 public:
  void Add(const std::string& method, grpc::StatusCode code, const std::string& message) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counts_[{method, code}];
    if (code != grpc::StatusCode::OK && first_errors_.size() < 10) {
      first_errors_.push_back(absl::StrCat(method, ": ", message));
    }
  }
  // Prints the table; returns the number of failed calls.
  int64_t Print() const {
    std::lock_guard<std::mutex> lock(mutex_);
    int64_t failed = 0;
    std::printf("%-14s %6s %10s\n", "method", "code", "calls");
    for (const auto& [key, count] : counts_) {
      std::printf("%-14s %6d %10lld\n", key.first.c_str(), static_cast<int>(key.second),
                  static_cast<long long>(count));
      if (key.second != grpc::StatusCode::OK) failed += count;
    }
    for (const std::string& error : first_errors_) std::printf("error: %s\n", error.c_str());
    return failed;
  }

 private:
  mutable std::mutex mutex_;
  std::map<std::pair<std::string, grpc::StatusCode>, int64_t> counts_;
  std::vector<std::string> first_errors_;
};

// The library every client reads: clip ids and frame counts.
struct Library {
  std::vector<int64_t> ids;
  std::vector<int> frames;
  std::vector<std::string> texts;  // BVH of the corpus's clips, ingested again under new names
};

std::unique_ptr<grpc::ClientContext> Context() {
  return bench::ContextWithin(std::chrono::seconds(60));
}

// One client: its own connection and clips, a mix of calls until `stop_at`.
void RunClient(const std::string& address, int index, const Library& library,
               Clock::time_point stop_at, CallTally& tally) {
  grpc::ChannelArguments arguments;
  arguments.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
  arguments.SetMaxReceiveMessageSize(-1);
  const auto channel =
      grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), arguments);
  auto clips = v1::ClipService::NewStub(channel);
  auto spaces = v1::SpaceService::NewStub(channel);
  auto search = v1::SearchService::NewStub(channel);
  auto labels = v1::LabelService::NewStub(channel);
  std::mt19937 random(index);
  std::deque<int64_t> own;
  for (int call = 0; Clock::now() < stop_at; ++call) {
    const size_t clip = random() % library.ids.size();
    const int length = 60 + static_cast<int>(random() % 60);
    const int first = static_cast<int>(random() % (library.frames[clip] - length));
    v1::ClipRange range;
    range.set_clip_id(library.ids[clip]);
    range.set_first_frame(first);
    range.set_last_frame(first + length - 1);
    const int kind = static_cast<int>(random() % 20);
    grpc::Status status;
    std::string method;
    if (kind < 10) {
      method = "Search";
      v1::SearchRequest request;
      request.set_space("body");
      *request.mutable_clip() = range;
      v1::SearchResponse response;
      status = search->Search(Context().get(), request, &response);
    } else if (kind < 12) {
      method = "IngestClip";
      v1::IngestClipRequest request;
      request.set_file_name(absl::StrCat("soak_", index, "_", call, ".bvh"));
      request.set_bvh(library.texts[clip]);
      v1::IngestClipResponse response;
      status = clips->IngestClip(Context().get(), request, &response);
      if (status.ok()) own.push_back(response.clip().clip_id());
      if (status.ok() && own.size() > kOwnClips) {
        tally.Add(method, status.error_code(), status.error_message());
        method = "DeleteClip";
        v1::DeleteClipRequest remove;
        remove.set_clip_id(own.front());
        own.pop_front();
        v1::DeleteClipResponse removed;
        status = clips->DeleteClip(Context().get(), remove, &removed);
      }
    } else if (kind < 14) {
      method = "ListClips";
      v1::ListClipsRequest request;
      request.set_page_size(50);
      v1::ListClipsResponse response;
      status = clips->ListClips(Context().get(), request, &response);
    } else if (kind < 16) {
      method = "GetCurve";
      v1::GetCurveRequest request;
      request.set_space("body");
      *request.mutable_clip() = range;
      v1::GetCurveResponse response;
      status = spaces->GetCurve(Context().get(), request, &response);
    } else if (kind < 17) {
      method = "ExportClip";
      v1::ExportClipRequest request;
      request.mutable_clip()->set_clip_id(library.ids[clip]);
      v1::ExportClipResponse response;
      status = clips->ExportClip(Context().get(), request, &response);
    } else if (kind < 19) {
      method = "AddLabels";
      v1::AddLabelsRequest request;
      v1::NewLabel* label = request.add_labels();
      label->set_clip_id(range.clip_id());
      label->set_first_frame(range.first_frame());
      label->set_last_frame(range.last_frame());
      label->set_descriptor_name(absl::StrCat("soak-", random() % 8));
      label->set_value(static_cast<double>(random() % 101) / 100);
      v1::AddLabelsResponse response;
      status = labels->AddLabels(Context().get(), request, &response);
    } else {
      method = "FindLabels";
      v1::FindLabelsRequest request;
      request.set_descriptor_name(absl::StrCat("soak-", random() % 8));
      request.set_min_value(0.5);
      request.set_page_size(50);
      v1::FindLabelsResponse response;
      status = labels->FindLabels(Context().get(), request, &response);
    }
    tally.Add(method, status.error_code(), status.error_message());
  }
}

// The JSON API on a new connection each call, as a script would: a refusal (503) while a flood
// holds every place is counted apart, any other failure as an error.
void RunHttpClient(int port, Clock::time_point stop_at, CallTally& tally) {
  for (int call = 0; Clock::now() < stop_at; ++call) {
    httplib::Client http("127.0.0.1", port);
    http.set_connection_timeout(10);
    http.set_read_timeout(60);
    const httplib::Result result =
        call % 2 == 0 ? http.Get("/v1/clips?page_size=20") : http.Get("/v1/spaces/body");
    const std::string method = call % 2 == 0 ? "HTTP clips" : "HTTP space";
    if (result && result->status == 200) {
      tally.Add(method, grpc::StatusCode::OK, "");
    } else if (!result || result->status == 503) {
      tally.Add(method + " refused", grpc::StatusCode::OK, "");
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    } else {
      tally.Add(method, grpc::StatusCode::UNKNOWN,
                absl::StrCat("HTTP ", result->status, ": ", result->body));
    }
  }
}

absl::Status Run(const Flags& flags) {
  const std::filesystem::path work =
      std::filesystem::temp_directory_path() / ("motiondb_soak_" + std::to_string(::getpid()));
  std::filesystem::create_directories(work);
  const std::string db = (work / "library.sqlite").string();

  // About 10 minutes of the synthetic humanoid at 30 Hz in clips of up to 40 s.
  SyntheticCorpusOptions options;
  options.fps = 30;
  options.target_duration_s = 600;
  options.max_clip_duration_s = 40;
  options.threads = 2;
  MOTIONDB_ASSIGN_OR_RETURN(const SyntheticCorpus corpus, GenerateSyntheticCorpus(options));
  Library library;
  for (const Clip& clip : corpus.clips) {
    MOTIONDB_ASSIGN_OR_RETURN(library.texts.emplace_back(), WriteBvh(clip));
    library.frames.push_back(clip.frame_count());
  }

  testing::ServerProcess server;
  std::vector<std::string> args = {"--db", db, "--quiet"};
  if (flags.hostile) {
    server.LimitOpenFiles(flags.max_open_files);
    args.insert(args.end(), {"--max-connections", "4096", "--http-max-connections", "4096"});
  }
  std::string error;
  if (!server.Start(args, &error, std::chrono::seconds(600)) ||
      !testing::WaitUntilServing(testing::InsecureChannel(server.address()), "")) {
    return absl::InternalError(absl::StrCat("the server did not start: ", error));
  }
  const auto channel = testing::InsecureChannel(server.address());
  auto clips = v1::ClipService::NewStub(channel);
  for (size_t i = 0; i < library.texts.size(); ++i) {
    v1::IngestClipRequest request;
    request.set_file_name(absl::StrCat("library_", i, ".bvh"));
    request.set_bvh(library.texts[i]);
    v1::IngestClipResponse response;
    const grpc::Status status = clips->IngestClip(Context().get(), request, &response);
    if (!status.ok()) return absl::InternalError(status.error_message());
    library.ids.push_back(response.clip().clip_id());
  }
  v1::CreateSpaceRequest create;
  create.set_name("body");
  v1::Space space;
  const grpc::Status created =
      v1::SpaceService::NewStub(channel)->CreateSpace(Context().get(), create, &space);
  if (!created.ok()) return absl::InternalError(created.error_message());

  std::printf("soak: %d clients for %.0f s on %zu clips (%.0f s of capture at 30 Hz)\n",
              flags.clients, flags.seconds, library.ids.size(), options.target_duration_s);
  CallTally tally;
  const Clock::time_point start = Clock::now();
  const Clock::time_point stop_at = start + std::chrono::duration_cast<Clock::duration>(
                                                std::chrono::duration<double>(flags.seconds));
  std::vector<std::thread> clients;
  for (int c = 0; c < flags.clients; ++c) {
    clients.emplace_back(RunClient, server.address(), c, std::cref(library), stop_at,
                         std::ref(tally));
  }
  std::unique_ptr<bench::HostileClients> hostile;
  if (flags.hostile) {
    for (int c = 0; c < 2; ++c) {
      clients.emplace_back(RunHttpClient, server.http_port(), stop_at, std::ref(tally));
    }
    hostile = std::make_unique<bench::HostileClients>(
        bench::HostileOptions{.grpc_port = server.port(), .http_port = server.http_port()});
  }
  std::vector<std::pair<double, double>> samples;  // (seconds, VmRSS MiB)
  for (double next = 0; Clock::now() < stop_at; next += flags.sample_s) {
    std::this_thread::sleep_until(
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(next)));
    samples.emplace_back(SecondsSince(start), StatusMiB(server.pid(), "VmRSS"));
    std::printf("  %6.0f s  VmRSS %7.1f MiB\n", samples.back().first, samples.back().second);
    std::fflush(stdout);
  }
  for (std::thread& client : clients) client.join();
  if (hostile) {
    hostile->Stop();
    std::printf("%s\n", hostile->Report().c_str());
  }
  // The gRPC port takes a new connection after it all.
  v1::ListClipsResponse listed;
  const grpc::Status accepting =
      v1::ClipService::NewStub(testing::InsecureChannel(server.address()))
          ->ListClips(Context().get(), v1::ListClipsRequest(), &listed);
  samples.emplace_back(SecondsSince(start), StatusMiB(server.pid(), "VmRSS"));
  const double peak = StatusMiB(server.pid(), "VmHWM");
  std::string log_tail = server.Log();
  log_tail = log_tail.substr(log_tail.size() > 4000 ? log_tail.size() - 4000 : 0);
  const int stopped = server.Stop(SIGTERM);
  std::filesystem::remove_all(work);

  const int64_t failed = tally.Print();
  // The level once warm: the highest sample of the second fifth of the run (index rebuilds make
  // the resident memory swing), against the last.
  double settled = 0;
  for (const auto& [seconds, rss] : samples) {
    if (seconds > flags.seconds / 5 && (seconds <= 2 * flags.seconds / 5 || settled == 0)) {
      settled = std::max(settled, rss);
    }
  }
  const double growth = samples.back().second / settled;
  std::printf(
      "VmRSS %.1f MiB at most in the second fifth, %.1f MiB at the end (%.2fx), peak %.1f MiB;"
      " %lld failed calls; a new gRPC connection at the end: %s; server exit code %d\n",
      settled, samples.back().second, growth, peak, static_cast<long long>(failed),
      accepting.ok() ? "served" : accepting.error_message().c_str(), stopped);
  if (failed > 0 || growth > 1.5 || stopped != 0 || !accepting.ok()) {
    std::printf("the server's log, its end:\n%s\n", log_tail.c_str());
    return absl::InternalError(
        "the soak failed: errors, growing memory, a port not accepting or an unclean stop");
  }
  return absl::OkStatus();
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  CLI::App app("Soak: concurrent clients mixing reads and writes against the real server.", "soak");
  motiondb::Flags flags;
  app.add_option("--seconds", flags.seconds, "how long the clients run")
      ->capture_default_str()
      ->check(motiondb::cli::NumberAbove(0));
  app.add_option("--clients", flags.clients, "concurrent clients, each on its own connection")
      ->capture_default_str()
      ->check(CLI::Range(1, 256));
  app.add_option("--sample-s", flags.sample_s, "seconds between memory samples")
      ->capture_default_str()
      ->check(motiondb::cli::NumberAbove(0));
  app.add_flag("!--no-hostile", flags.hostile,
               "no HTTP clients, slow clients, idle streams or connection floods");
  app.add_option("--max-open-files", flags.max_open_files,
                 "the server's open-file limit with the hostile clients")
      ->capture_default_str()
      ->check(CLI::Range(128, 1 << 20));
  if (const std::optional<int> exit_code = motiondb::cli::ParseCommandLine(app, argc, argv)) {
    return *exit_code;
  }
  const absl::Status status = motiondb::Run(flags);
  if (!status.ok()) {
    std::fprintf(stderr, "soak: %s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
