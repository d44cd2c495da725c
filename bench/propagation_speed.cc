// Markup propagation speed (issue 13, item 7), through the real motiondb-server on a loopback
// port, on hours of synthetic capture at 30 Hz stored as server_bench stores its library
// (bench/synthetic_library.h):
//  1. one propagation job of N manual labels (ranges of 1 to 3 s spread evenly over the library,
//     five descriptors, value 1): from the StartPropagation call to the job's end as WatchJob
//     reports it, its writes included; beside the baseline, the same N searches (each label's
//     range the query, its own range excluded, the job's max_results) issued one by one by a
//     client, as a batch script without jobs would; the job once per --job-threads value, each
//     on a server started with it (the propagated labels of the previous one deleted first);
//  2. interactive search latency (2.8 s ranges spread over the library, default parameters, one
//     client, one search at a time) while that job runs again (on the last server), beside the
//     same searches with the server idle just before and just after;
//  3. FindLabels over M more labels (AddLabels batches of 10,000; D descriptors, values uniform
//     in [0, 1], ranges of 1 to 3 s): a first page and a deep page (min_value 0.7, page size 50),
//     beside a health check's round trip, the floor of any call.
// The library is made in a temporary folder, or kept at --library and reused by later runs
// (the labels of earlier runs are deleted first).
//
// usage: propagation_speed [--hours H] [--labels N] [--find-labels M] [--descriptors D]
//                          [--job-threads N...] [--library FILE]
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "bench/measure.h"
#include "bench/synthetic_library.h"
#include "bench/throughput.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "motiondb/v1/job_service.grpc.pb.h"
#include "motiondb/v1/label_service.grpc.pb.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "server/jobs/propagation.h"
#include "testing/server_process.h"
#include "util/cli_conventions.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

namespace fs = std::filesystem;
using bench::Clock;
using bench::FromGrpc;
using bench::OwnConnection;
using bench::Percentile;
using bench::SecondsSince;

constexpr char kSpace[] = "synthetic";
constexpr int kFps = 30;
constexpr int kFindPageSize = 50;
constexpr double kFindMinValue = 0.7;
constexpr int kDeepPage = 20;  // the deep page: 20th of 50 labels, after the 950 strongest

struct Flags {
  double hours = 10;
  int labels = 1000;
  int find_labels = 1000000;
  int descriptors = 200;
  std::vector<int> job_threads = {1, 0};  // the servers' --job-threads, one job each
  std::string library;                    // empty: a temporary one
};

// A range of a stored clip, at its rate (inclusive).
struct Range {
  int64_t clip_id = 0;
  int first = 0, last = 0;
};

// The clips of the library as the server lists them.
struct ClipFrames {
  std::vector<int64_t> ids;
  std::vector<int> frames;
  int64_t total = 0;
};

// `count` ranges evenly spread over the library, the i-th `length(i)` frames long (cut at its
// clip's end).
template <typename Length>
std::vector<Range> SpreadRanges(const ClipFrames& clips, int count, const Length& length) {
  std::vector<Range> ranges;
  for (int i = 0; i < count; ++i) {
    int64_t at = clips.total * i / count;
    size_t c = 0;
    while (at >= clips.frames[c]) at -= clips.frames[c++];
    const int first = static_cast<int>(at);
    ranges.push_back({clips.ids[c], first, std::min(clips.frames[c] - 1, first + length(i) - 1)});
  }
  return ranges;
}

v1::SearchRequest RangeQuery(const Range& range) {
  v1::SearchRequest request;
  request.set_space(kSpace);
  request.mutable_clip()->set_clip_id(range.clip_id);
  request.mutable_clip()->set_first_frame(range.first);
  request.mutable_clip()->set_last_frame(range.last);
  return request;
}

class Api {
 public:
  explicit Api(const std::string& address)
      : address_(address),
        channel_(OwnConnection(address)),
        clips_(v1::ClipService::NewStub(channel_)),
        labels_(v1::LabelService::NewStub(channel_)),
        jobs_(v1::JobService::NewStub(channel_)),
        health_(grpc::health::v1::Health::NewStub(channel_)) {}

  absl::StatusOr<ClipFrames> Clips() {
    ClipFrames clips;
    v1::ListClipsRequest list;
    list.set_page_size(1000);
    do {
      v1::ListClipsResponse page;
      grpc::ClientContext context;
      MOTIONDB_RETURN_IF_ERROR(FromGrpc(clips_->ListClips(&context, list, &page), "ListClips"));
      for (const v1::Clip& clip : page.clips()) {
        clips.ids.push_back(clip.clip_id());
        clips.frames.push_back(clip.frame_count());
        clips.total += clip.frame_count();
      }
      list.set_page_token(page.next_page_token());
    } while (!list.page_token().empty());
    return clips;
  }

  // Deletes every label of `origin` (every manual label deletes every propagated one too).
  absl::Status DeleteLabels(v1::LabelOrigin origin) {
    v1::DeleteLabelsRequest remove;
    remove.set_origin(origin);
    v1::DeleteLabelsResponse removed;
    grpc::ClientContext context;
    return FromGrpc(labels_->DeleteLabels(&context, remove, &removed), "DeleteLabels");
  }

  absl::Status AddLabels(const v1::AddLabelsRequest& add) {
    v1::AddLabelsResponse added;
    grpc::ClientContext context;
    return FromGrpc(labels_->AddLabels(&context, add, &added), "AddLabels");
  }

  // Starts a propagation of every manual descriptor with the job's default parameters.
  absl::StatusOr<std::string> StartPropagation() {
    v1::StartPropagationRequest start;
    start.set_space(kSpace);
    v1::Job job;
    grpc::ClientContext context;
    MOTIONDB_RETURN_IF_ERROR(
        FromGrpc(jobs_->StartPropagation(&context, start, &job), "StartPropagation"));
    return job.job_id();
  }

  // Watches the job to its end; `searched` is set when every label was searched (before the
  // job's writes). The job as it ended.
  absl::StatusOr<v1::Job> WaitForJob(const std::string& job_id, Clock::time_point* searched) {
    v1::WatchJobRequest watch;
    watch.set_job_id(job_id);
    grpc::ClientContext context;
    auto reader = jobs_->WatchJob(&context, watch);
    v1::Job job;
    *searched = Clock::time_point{};
    while (reader->Read(&job)) {
      if (searched->time_since_epoch().count() == 0 && job.total() > 0 &&
          job.done() == job.total()) {
        *searched = Clock::now();
      }
    }
    MOTIONDB_RETURN_IF_ERROR(FromGrpc(reader->Finish(), "WatchJob"));
    if (job.state() != v1::JOB_STATE_SUCCEEDED) {
      return absl::InternalError(
          absl::StrCat(job_id, " ended ", v1::JobState_Name(job.state()), ": ", job.error()));
    }
    return job;
  }

  // FindLabels' latency in ms; `page` gets the answer.
  absl::StatusOr<double> FindLabels(const v1::FindLabelsRequest& find,
                                    v1::FindLabelsResponse* page) {
    grpc::ClientContext context;
    const Clock::time_point sent = Clock::now();
    MOTIONDB_RETURN_IF_ERROR(FromGrpc(labels_->FindLabels(&context, find, page), "FindLabels"));
    return 1000 * SecondsSince(sent);
  }

  // A health check's latency in ms: a call that reads nothing.
  absl::StatusOr<double> HealthCheck() {
    grpc::health::v1::HealthCheckResponse serving;
    grpc::ClientContext context;
    const Clock::time_point sent = Clock::now();
    MOTIONDB_RETURN_IF_ERROR(FromGrpc(
        health_->Check(&context, grpc::health::v1::HealthCheckRequest(), &serving), "Check"));
    return 1000 * SecondsSince(sent);
  }

  const std::string& address() const { return address_; }

 private:
  std::string address_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::ClipService::Stub> clips_;
  std::unique_ptr<v1::LabelService::Stub> labels_;
  std::unique_ptr<v1::JobService::Stub> jobs_;
  std::unique_ptr<grpc::health::v1::Health::Stub> health_;
};

// Searches `queries` in turn, one at a time, until `keep_going` says no (checked before each),
// and returns their latencies in ms.
template <typename KeepGoing>
absl::StatusOr<std::vector<double>> TimeSearches(v1::SearchService::Stub& search,
                                                 const std::vector<v1::SearchRequest>& queries,
                                                 const KeepGoing& keep_going) {
  std::vector<double> ms;
  for (size_t i = 0; keep_going(i); ++i) {
    v1::SearchResponse response;
    grpc::ClientContext context;
    const Clock::time_point sent = Clock::now();
    MOTIONDB_RETURN_IF_ERROR(
        FromGrpc(search.Search(&context, queries[i % queries.size()], &response), "Search"));
    ms.push_back(1000 * SecondsSince(sent));
  }
  return ms;
}

std::string Latencies(const std::vector<double>& ms) {
  return absl::StrFormat("p50 %.2f ms, p90 %.2f ms, p99 %.2f ms, max %.2f ms (%d searches)",
                         Percentile(ms, 0.5), Percentile(ms, 0.9), Percentile(ms, 0.99),
                         *std::max_element(ms.begin(), ms.end()), ms.size());
}

// 1, the baseline: the job's searches one by one from a client.
absl::Status ClientBaseline(v1::SearchService::Stub& search, const std::vector<Range>& labelled) {
  std::vector<v1::SearchRequest> queries;
  for (const Range& range : labelled) {
    queries.push_back(RangeQuery(range));
    queries.back().set_max_results(server::kPropagationMaxResults);  // the job's default
  }
  const Clock::time_point start = Clock::now();
  MOTIONDB_ASSIGN_OR_RETURN(
      const std::vector<double> one_by_one,
      TimeSearches(search, queries, [&](size_t i) { return i < queries.size(); }));
  const double client_s = SecondsSince(start);
  std::printf("| the same searches one by one from a client | %.2f | %.0f | client searches %s |\n",
              client_s, queries.size() / client_s, Latencies(one_by_one).c_str());
  return absl::OkStatus();
}

// 1: one job on a server started with --job-threads `threads`.
absl::Status TimeJob(Api& api, int threads) {
  const Clock::time_point start = Clock::now();
  MOTIONDB_ASSIGN_OR_RETURN(const std::string job_id, api.StartPropagation());
  Clock::time_point searched;
  MOTIONDB_ASSIGN_OR_RETURN(const v1::Job job, api.WaitForJob(job_id, &searched));
  const Clock::time_point end = Clock::now();
  const double job_s = std::chrono::duration<double>(end - start).count();
  std::printf(
      "| one job, `--job-threads %d`, call to end (writes included) | **%.2f** | %.0f | %s: %lld "
      "queries (%lld skipped), %lld labels written; searches done after %.2f s, the end (the "
      "space's scale, keeping the strongest, the writes) %.2f s after that |\n",
      threads, job_s, job.queries() / job_s, job_id.c_str(), static_cast<long long>(job.queries()),
      static_cast<long long>(job.queries_skipped()), static_cast<long long>(job.labels_written()),
      std::chrono::duration<double>(searched - start).count(),
      std::chrono::duration<double>(end - searched).count());
  return absl::OkStatus();
}

// 2: interactive searches while a job runs, beside idle before and after.
absl::Status SearchDuringJob(Api& api, v1::SearchService::Stub& search, const ClipFrames& clips) {
  std::vector<v1::SearchRequest> queries;
  for (const Range& range : SpreadRanges(clips, 97, [](int) { return 84; })) {
    queries.push_back(RangeQuery(range));
  }
  const auto passes = [&](size_t i) { return i < 4 * queries.size(); };
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<double> before,
                            TimeSearches(search, queries, passes));

  MOTIONDB_ASSIGN_OR_RETURN(const std::string job_id, api.StartPropagation());
  std::atomic<bool> running = true;
  absl::StatusOr<v1::Job> job;
  std::thread watcher([&] {
    Clock::time_point searched;
    job = api.WaitForJob(job_id, &searched);
    running = false;
  });
  const absl::StatusOr<std::vector<double>> during =
      TimeSearches(search, queries, [&](size_t) { return running.load(); });
  watcher.join();
  MOTIONDB_RETURN_IF_ERROR(during.status());
  MOTIONDB_RETURN_IF_ERROR(job.status());
  // The search that was running when the job ended is counted: it ran mostly beside the job.
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<double> after, TimeSearches(search, queries, passes));
  std::vector<double> idle = before;
  idle.insert(idle.end(), after.begin(), after.end());
  std::printf("## 2. Interactive search (%zu 2.8 s ranges in turn, defaults, one client)\n\n",
              queries.size());
  std::printf("| server | latency |\n|---|---|\n");
  std::printf("| idle, before the job | %s |\n", Latencies(before).c_str());
  std::printf("| while job %s runs | %s |\n", job_id.c_str(), Latencies(*during).c_str());
  std::printf("| idle, after the job | %s |\n\n", Latencies(after).c_str());
  std::printf("during / idle (before and after) p99: **%.2fx**, p50: %.2fx\n\n",
              Percentile(*during, 0.99) / Percentile(idle, 0.99),
              Percentile(*during, 0.5) / Percentile(idle, 0.5));
  return absl::OkStatus();
}

// 3: FindLabels over `count` more labels.
absl::Status FindOverMany(Api& api, const ClipFrames& clips, const Flags& flags) {
  std::mt19937_64 random(13);
  std::uniform_int_distribution<int64_t> frame(0, clips.total - 1);
  std::uniform_int_distribution<int> length(kFps, 3 * kFps), descriptor(0, flags.descriptors - 1);
  std::uniform_real_distribution<double> value(0, 1);
  const auto name = [](int d) { return absl::StrFormat("find-%03d", d); };
  Clock::time_point start = Clock::now();
  for (int done = 0; done < flags.find_labels;) {
    v1::AddLabelsRequest add;
    for (; done < flags.find_labels && add.labels_size() < 10000; ++done) {
      int64_t at = frame(random);
      size_t c = 0;
      while (at >= clips.frames[c]) at -= clips.frames[c++];
      v1::NewLabel* label = add.add_labels();
      label->set_clip_id(clips.ids[c]);
      label->set_first_frame(static_cast<int>(at));
      label->set_last_frame(std::min<int>(clips.frames[c] - 1, at + length(random) - 1));
      label->set_descriptor_name(name(descriptor(random)));
      label->set_value(value(random));
    }
    MOTIONDB_RETURN_IF_ERROR(api.AddLabels(add));
  }
  const double insert_s = SecondsSince(start);

  std::vector<double> first_ms, deep_ms, call_ms;
  int64_t pages_short = 0;
  for (int d = 0; d < flags.descriptors; ++d) {
    v1::FindLabelsRequest find;
    find.set_descriptor_name(name(d));
    find.set_min_value(kFindMinValue);
    find.set_page_size(kFindPageSize);
    for (int page = 1; page <= kDeepPage; ++page) {
      v1::FindLabelsResponse answer;
      MOTIONDB_ASSIGN_OR_RETURN(const double ms, api.FindLabels(find, &answer));
      if (page == 1) first_ms.push_back(ms);
      if (page == kDeepPage) deep_ms.push_back(ms);
      if (answer.next_page_token().empty()) {
        ++pages_short;
        break;
      }
      find.set_page_token(answer.next_page_token());
    }
    MOTIONDB_ASSIGN_OR_RETURN(call_ms.emplace_back(), api.HealthCheck());
  }
  std::printf("## 3. FindLabels over %d more labels (%d descriptors, values uniform in [0, 1])\n\n",
              flags.find_labels, flags.descriptors);
  std::printf("AddLabels in batches of 10,000: %.1f s, %.0f labels/s\n\n", insert_s,
              flags.find_labels / insert_s);
  std::printf("| request (min_value %.1f, page size %d) | p50 ms | p99 ms | requests |\n",
              kFindMinValue, kFindPageSize);
  std::printf("|---|---:|---:|---:|\n");
  const auto row = [](const std::string& what, const std::vector<double>& ms) {
    std::printf("| %s | %.2f | %.2f | %zu |\n", what.c_str(), Percentile(ms, 0.5),
                Percentile(ms, 0.99), ms.size());
  };
  row("first page", first_ms);
  row(absl::StrCat("page ", kDeepPage, " (after ", (kDeepPage - 1) * kFindPageSize, " labels)"),
      deep_ms);
  row("health check (the floor of a call)", call_ms);
  if (pages_short > 0) {
    std::printf("\n%lld descriptors had fewer than %d pages\n", static_cast<long long>(pages_short),
                kDeepPage);
  }
  std::printf("\n");
  return absl::OkStatus();
}

// The manual labels of the jobs, replacing every earlier label.
absl::StatusOr<std::vector<Range>> AddManualLabels(Api& api, const ClipFrames& clips,
                                                   const Flags& flags) {
  MOTIONDB_RETURN_IF_ERROR(api.DeleteLabels(v1::LABEL_ORIGIN_MANUAL));
  const std::vector<Range> labelled =
      SpreadRanges(clips, flags.labels, [](int i) { return kFps + (i * 7919) % (2 * kFps + 1); });
  static const char* const kDescriptors[] = {"step", "raise", "shrug", "slouch", "turn"};
  v1::AddLabelsRequest add;
  for (size_t i = 0; i < labelled.size(); ++i) {
    v1::NewLabel* label = add.add_labels();
    label->set_clip_id(labelled[i].clip_id);
    label->set_first_frame(labelled[i].first);
    label->set_last_frame(labelled[i].last);
    label->set_descriptor_name(kDescriptors[i % std::size(kDescriptors)]);
  }
  MOTIONDB_RETURN_IF_ERROR(api.AddLabels(add));
  return labelled;
}

// What is measured on the server started with the `round`-th --job-threads value.
absl::Status Measure(const std::string& address, const Flags& flags, size_t round) {
  Api api(address);
  auto search = v1::SearchService::NewStub(OwnConnection(address));
  MOTIONDB_ASSIGN_OR_RETURN(const ClipFrames clips, api.Clips());
  if (round == 0) {
    MOTIONDB_ASSIGN_OR_RETURN(const std::vector<Range> labelled,
                              AddManualLabels(api, clips, flags));
    std::printf("library: %zu clips, %lld frames at %d Hz (%.1f h)\n\n", clips.ids.size(),
                static_cast<long long>(clips.total), kFps, clips.total / (3600.0 * kFps));
    std::printf("## 1. %zu manual labels propagated (max_results %d a query)\n\n", labelled.size(),
                server::kPropagationMaxResults);
    std::printf("| way | seconds | searches/s | detail |\n|---|---:|---:|---|\n");
    MOTIONDB_RETURN_IF_ERROR(ClientBaseline(*search, labelled));
  } else {
    MOTIONDB_RETURN_IF_ERROR(api.DeleteLabels(v1::LABEL_ORIGIN_PROPAGATED));
  }
  MOTIONDB_RETURN_IF_ERROR(TimeJob(api, flags.job_threads[round]));
  if (round + 1 < flags.job_threads.size()) return absl::OkStatus();
  std::printf("\n");
  MOTIONDB_RETURN_IF_ERROR(SearchDuringJob(api, *search, clips));
  if (flags.find_labels > 0) MOTIONDB_RETURN_IF_ERROR(FindOverMany(api, clips, flags));
  return absl::OkStatus();
}

absl::Status Run(const Flags& flags) {
  const fs::path work =
      fs::temp_directory_path() / ("motiondb_propagation_speed_" + std::to_string(::getpid()));
  fs::create_directories(work);
  const std::string db = flags.library.empty() ? (work / "library.sqlite").string() : flags.library;
  if (!fs::exists(db)) {
    const Clock::time_point start = Clock::now();
    MOTIONDB_RETURN_IF_ERROR(bench::StoreSyntheticLibrary(db, flags.hours, kFps, kSpace).status());
    std::printf("stored %.1f h of synthetic capture and space '%s' in %.1f s\n", flags.hours,
                kSpace, SecondsSince(start));
  }
  absl::Status measured;
  for (size_t round = 0; round < flags.job_threads.size() && measured.ok(); ++round) {
    testing::ServerProcess server;
    std::string error;
    if (!server.Start(
            {"--db", db, "--quiet", "--job-threads", std::to_string(flags.job_threads[round])},
            &error, std::chrono::seconds(600))) {
      return absl::InternalError(error);
    }
    if (!testing::WaitUntilServing(OwnConnection(server.address()), "",
                                   std::chrono::seconds(600))) {
      return absl::InternalError("the server did not start serving");
    }
    measured = Measure(server.address(), flags, round);
    server.Stop(SIGTERM);
  }
  fs::remove_all(work);
  return measured;
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  CLI::App app("Markup propagation speed on hours of synthetic capture, through the real server.",
               "propagation_speed");
  motiondb::Flags flags;
  app.add_option("--hours", flags.hours, "hours of capture at 30 Hz in a new library")
      ->capture_default_str()
      ->check(motiondb::cli::NumberAbove(0));
  app.add_option("--labels", flags.labels, "manual labels the job propagates")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  app.add_option("--find-labels", flags.find_labels, "labels FindLabels searches (0: skip)")
      ->capture_default_str()
      ->check(CLI::Range(0, 100000000));
  app.add_option("--descriptors", flags.descriptors, "descriptors of those labels")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  app.add_option("--job-threads", flags.job_threads,
                 "one job on a server started with each of these --job-threads (0: one per core)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  app.add_option("--library", flags.library,
                 "keep the library in this database file, and reuse it when it exists")
      ->type_name("FILE");
  if (const std::optional<int> exit_code = motiondb::cli::ParseCommandLine(app, argc, argv)) {
    return *exit_code;
  }
  const absl::Status status = motiondb::Run(flags);
  if (!status.ok()) {
    std::fprintf(stderr, "propagation_speed: %s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
