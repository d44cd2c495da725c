#include "testing/retrieval_evaluation.h"

#include <algorithm>

#include "core/search/exact_search.h"
#include "core/search/motion_search.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

double Percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, static_cast<size_t>(p * values.size()))];
}

double Precision(const std::vector<SearchResult>& results, const std::vector<std::string>& labels,
                 const std::string& want, int k) {
  int hits = 0;
  for (int i = 0; i < k && i < static_cast<int>(results.size()); ++i) {
    hits += labels[results[i].clip_index] == want;
  }
  return static_cast<double>(hits) / k;
}

}  // namespace

absl::StatusOr<RetrievalReport> EvaluateLeaveOneOut(const LibraryIndex& library,
                                                    const std::vector<std::string>& labels,
                                                    const RetrievalOptions& options) {
  if (static_cast<int>(labels.size()) != library.clip_count()) {
    return absl::InvalidArgumentError("one label per library clip is needed");
  }
  RetrievalReport report;
  std::map<std::string, int> label_queries;
  std::vector<double> latencies, exact_latencies;
  int recall_hits = 0, recall_total = 0;
  for (int q = 0; q < library.clip_count(); ++q) {
    SearchParams params = options.params;
    params.max_results = std::max(options.precision_at, options.recall_at);
    params.clip_ids.clear();
    params.tags.clear();
    for (int c = 0; c < library.clip_count(); ++c) {
      if (c != q) params.clip_ids.push_back(library.clip(c).clip_id);
    }
    const CoordinateView query = library.clip_coordinates(q);
    MOTIONDB_ASSIGN_OR_RETURN(const SearchResponse fast, Search(library, query, params));
    latencies.push_back(fast.stats.total_ms);
    report.mean_stage_ms["seeds"] += fast.stats.seeds_ms;
    report.mean_stage_ms["clusters"] += fast.stats.clusters_ms;
    report.mean_stage_ms["warps"] += fast.stats.warps_ms;
    report.mean_stage_ms["refine"] += fast.stats.refine_ms;
    report.mean_stage_ms["ranking"] += fast.stats.ranking_ms;
    const double precision = Precision(fast.results, labels, labels[q], options.precision_at);
    report.precision += precision;
    report.precision_by_label[labels[q]] += precision;
    ++label_queries[labels[q]];
    if (options.exact_every > 0 && q % options.exact_every == 0) {
      MOTIONDB_ASSIGN_OR_RETURN(const SearchResponse exact, ExactSearch(library, query, params));
      exact_latencies.push_back(exact.stats.total_ms);
      report.exact_precision += Precision(exact.results, labels, labels[q], options.precision_at);
      ++report.exact_queries;
      for (int i = 0; i < options.recall_at && i < static_cast<int>(exact.results.size()); ++i) {
        const SearchResult& e = exact.results[i];
        ++recall_total;
        recall_hits += std::any_of(
            fast.results.begin(), fast.results.end(),
            [&](const SearchResult& f) { return Overlaps(e, f, 0.5) || Overlaps(f, e, 0.5); });
      }
    }
  }
  report.queries = library.clip_count();
  report.precision /= report.queries;
  for (auto& [label, sum] : report.precision_by_label) sum /= label_queries[label];
  for (auto& [stage, sum] : report.mean_stage_ms) sum /= report.queries;
  if (report.exact_queries > 0) report.exact_precision /= report.exact_queries;
  report.recall = recall_total > 0 ? static_cast<double>(recall_hits) / recall_total : 0.0;
  report.latency_p50_ms = Percentile(latencies, 0.5);
  report.latency_p99_ms = Percentile(latencies, 0.99);
  report.exact_latency_p50_ms = Percentile(exact_latencies, 0.5);
  return report;
}

}  // namespace motiondb
