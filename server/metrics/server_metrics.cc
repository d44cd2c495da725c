#include "server/metrics/server_metrics.h"

#include <unistd.h>

#include <fstream>
#include <map>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"

namespace motiondb::server {
namespace {

using Samples = std::vector<std::pair<LabelValues, double>>;

// Calls from 0.5 ms to 16 s; search stages from 0.1 ms to 13 s, doubling.
std::vector<double> CallBounds() { return ExponentialBounds(0.0005, 2, 16); }
std::vector<double> StageBounds() { return ExponentialBounds(0.0001, 2, 18); }

// The resident set from /proc/self/statm (its second field, in pages); 0 where it is missing.
double ResidentBytes() {
  std::ifstream statm("/proc/self/statm");
  int64_t size_pages = 0, resident_pages = 0;
  if (!(statm >> size_pages >> resident_pages)) return 0;
  return static_cast<double>(resident_pages) * static_cast<double>(sysconf(_SC_PAGESIZE));
}

Samples SpaceSamples(const IndexRegistry& indices, bool frames) {
  Samples samples;
  for (const auto& snapshot : indices.All()) {
    const LibraryIndex* index = snapshot->index.get();
    const double value = index == nullptr ? 0
                         : frames         ? static_cast<double>(index->total_frames())
                                          : static_cast<double>(index->clip_count());
    samples.push_back({{snapshot->record.name}, value});
  }
  return samples;
}

// Every state, those without jobs at 0, so that a dashboard's series do not come and go.
Samples JobSamples(storage::Database& database) {
  const absl::StatusOr<std::map<storage::JobState, int64_t>> counts = database.CountJobs();
  Samples samples;
  if (!counts.ok()) return samples;  // a scrape shows what it can; the database logs nothing
  for (const storage::JobState state :
       {storage::JobState::kQueued, storage::JobState::kRunning, storage::JobState::kSucceeded,
        storage::JobState::kFailed, storage::JobState::kCancelled,
        storage::JobState::kInterrupted}) {
    const auto found = counts->find(state);
    samples.push_back({{storage::JobStateName(state)},
                       found == counts->end() ? 0.0 : static_cast<double>(found->second)});
  }
  return samples;
}

}  // namespace

ServerMetrics::ServerMetrics(const IndexRegistry& indices, storage::Database& database,
                             const UploadBudget& uploads)
    : calls_(registry_.AddCounter("motiondb_requests_total",
                                  "Calls of each API method, by face (grpc, http) and status code.",
                                  {"face", "method", "code"})),
      call_seconds_(registry_.AddHistogram("motiondb_request_duration_seconds",
                                           "Time the services took per call, by face and method.",
                                           {"face", "method"}, CallBounds())),
      http_exchanges_(registry_.AddCounter(
          "motiondb_http_requests_total",
          "HTTP requests by route (method and path pattern) and status.", {"route", "status"})),
      http_seconds_(registry_.AddHistogram(
          "motiondb_http_request_duration_seconds",
          "Time from an HTTP request to its response, JSON conversion included, by route.",
          {"route"}, CallBounds())),
      search_stage_seconds_(registry_.AddHistogram(
          "motiondb_search_stage_duration_seconds",
          "Time of each search stage (total: the search proper; request: all of the request).",
          {"stage"}, StageBounds())),
      ingested_frames_(registry_.AddCounter("motiondb_ingested_frames_total",
                                            "Frames of the clips stored by ingests.", {})) {
  registry_.AddGauge("motiondb_index_clips", "Clips in each space's resident index.", {"space"},
                     [&indices] { return SpaceSamples(indices, /*frames=*/false); });
  registry_.AddGauge("motiondb_index_frames",
                     "Frames (at the space's rate) in each space's resident index.", {"space"},
                     [&indices] { return SpaceSamples(indices, /*frames=*/true); });
  registry_.AddGauge("motiondb_jobs", "Background jobs in each state.", {"state"},
                     [&database] { return JobSamples(database); });
  registry_.AddGauge(
      "motiondb_uploads_in_progress",
      "Uploads in progress: ingests, and HTTP bodies arriving (at most --max-uploads).", {},
      [&uploads] {
        return Samples{{{}, static_cast<double>(uploads.uploads())}};
      });
  registry_.AddGauge(
      "motiondb_upload_buffered_bytes",
      "Bytes the ingests in progress hold together (at most --max-upload-buffer-mb).", {},
      [&uploads] {
        return Samples{{{}, static_cast<double>(uploads.buffered_bytes())}};
      });
  registry_.AddGauge("process_resident_memory_bytes", "Resident memory size in bytes.", {}, [] {
    return Samples{{{}, ResidentBytes()}};
  });
  registry_.AddGauge("motiondb_connections",
                     "Connections open on each port (at most --max-connections, "
                     "--http-max-connections).",
                     {"face"}, [this] {
                       std::lock_guard<std::mutex> lock(connection_sources_mutex_);
                       Samples samples;
                       for (const auto& [face, open] : connection_sources_) {
                         samples.push_back({{face}, static_cast<double>(open())});
                       }
                       return samples;
                     });
}

void ServerMetrics::SetConnectionSource(absl::string_view face, std::function<int()> open) {
  std::lock_guard<std::mutex> lock(connection_sources_mutex_);
  if (open) {
    connection_sources_[std::string(face)] = std::move(open);
  } else {
    connection_sources_.erase(std::string(face));
  }
}

void ServerMetrics::CountCall(absl::string_view face, absl::string_view method,
                              absl::string_view code, double seconds) {
  calls_.Add({std::string(face), std::string(method), std::string(code)});
  call_seconds_.Observe({std::string(face), std::string(method)}, seconds);
}

void ServerMetrics::CountHttp(absl::string_view route, int status, double seconds) {
  http_exchanges_.Add({std::string(route), absl::StrCat(status)});
  http_seconds_.Observe({std::string(route)}, seconds);
}

void ServerMetrics::CountSearch(const SearchOutcome& outcome) {
  const SearchStats& stats = outcome.stats;
  const std::pair<const char*, double> stages[] = {{"characteristic", stats.characteristic_ms},
                                                   {"seeds", stats.seeds_ms},
                                                   {"clusters", stats.clusters_ms},
                                                   {"warps", stats.warps_ms},
                                                   {"refine", stats.refine_ms},
                                                   {"ranking", stats.ranking_ms},
                                                   {"total", stats.total_ms},
                                                   {"request", outcome.request_ms}};
  for (const auto& [stage, ms] : stages) {
    // A stage at exactly 0 did not run (the exact search's, a refinement turned off).
    if (ms > 0) search_stage_seconds_.Observe({stage}, ms / 1000);
  }
}

void ServerMetrics::CountIngest(const IngestOutcome& outcome) {
  if (outcome.result == IngestResult::kSkipped) return;
  ingested_frames_.Add({}, outcome.clip.frame_count);
}

std::string ServerMetrics::Render() const { return registry_.Render(); }

}  // namespace motiondb::server
