// The server's metrics, as GET /metrics shows them: calls per method and status code on each
// face with their latencies, HTTP exchanges per route, search stage times, frames ingested,
// and, read when scraped, each space index's clips and frames, jobs per state, the uploads in
// progress and the bytes they hold, and the process's resident memory. Fed where calls are already
// timed (server/grpc/request_logger.h, the search and clip services, the HTTP face); it knows no
// proto.
//
// Thread-safe.
#ifndef MOTIONDB_SERVER_METRICS_SERVER_METRICS_H_
#define MOTIONDB_SERVER_METRICS_SERVER_METRICS_H_

#include <functional>
#include <map>
#include <mutex>
#include <string>

#include "absl/strings/string_view.h"
#include "server/clip_ingest.h"
#include "server/index_registry.h"
#include "server/metrics/metrics_registry.h"
#include "server/search_runner.h"
#include "server/upload/upload_budget.h"
#include "storage/database.h"

namespace motiondb::server {

class ServerMetrics {
 public:
  // `indices`, `database` and `uploads` are read at each Render() and must outlive this.
  ServerMetrics(const IndexRegistry& indices, storage::Database& database,
                const UploadBudget& uploads);
  ServerMetrics(const ServerMetrics&) = delete;
  ServerMetrics& operator=(const ServerMetrics&) = delete;

  // A call of `method` ("/motiondb.v1.SearchService/Search") that ended with `code` ("OK") after
  // `seconds`, arriving on `face` ("grpc", or "http" for the HTTP face's transcoded calls).
  void CountCall(absl::string_view face, absl::string_view method, absl::string_view code,
                 double seconds);
  // An HTTP exchange: `route` as the route table names it ("GET /v1/clips/{id}"), the status
  // sent and the seconds it took, JSON conversion included.
  void CountHttp(absl::string_view route, int status, double seconds);
  // A search's stage times (the stages it ran; an exact search has only warps).
  void CountSearch(const SearchOutcome& outcome);
  // Frames stored by an ingest (none when it was skipped).
  void CountIngest(const IngestOutcome& outcome);

  // Where the connections open on `face` ("grpc", "http") are counted, read at each scrape
  // (motiondb_connections); `open` must stay callable until this is destroyed or replaced.
  void SetConnectionSource(absl::string_view face, std::function<int()> open);

  // Every metric in Prometheus' text format 0.0.4.
  std::string Render() const;

 private:
  MetricsRegistry registry_;
  MetricsRegistry::Counter& calls_;
  MetricsRegistry::Histogram& call_seconds_;
  MetricsRegistry::Counter& http_exchanges_;
  MetricsRegistry::Histogram& http_seconds_;
  MetricsRegistry::Histogram& search_stage_seconds_;
  MetricsRegistry::Counter& ingested_frames_;
  mutable std::mutex connection_sources_mutex_;
  std::map<std::string, std::function<int()>> connection_sources_;  // guarded by the mutex
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_METRICS_SERVER_METRICS_H_
