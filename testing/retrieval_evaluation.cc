#include "testing/retrieval_evaluation.h"

#include <algorithm>
#include <chrono>

#include "core/search/exact_search.h"
#include "core/search/motion_search.h"
#include "util/status_macros.h"

namespace motiondb::testing {
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

// The clips query `q` may find: every other one, or those of other groups.
std::vector<int64_t> FindableClips(const LibraryIndex& library, const RetrievalOptions& options,
                                   int q) {
  std::vector<int64_t> clip_ids;
  for (int c = 0; c < library.clip_count(); ++c) {
    const bool findable = options.groups.empty() ? c != q : options.groups[c] != options.groups[q];
    if (findable) clip_ids.push_back(library.clip(c).clip_id);
  }
  return clip_ids;
}

// How many of `clip_ids` (library clip ids, equal to their indices here) carry `label`.
int CountLabel(const std::vector<int64_t>& clip_ids, const std::vector<std::string>& labels,
               const std::string& label) {
  return static_cast<int>(std::count_if(clip_ids.begin(), clip_ids.end(),
                                        [&](int64_t c) { return labels[c] == label; }));
}

// Of the exact search's first `recall_at` results, those `found` holds (overlapping by half):
// adds them to `hits`, and the exact results to `total`.
void CountRecall(const std::vector<SearchResult>& exact, const std::vector<SearchResult>& found,
                 int recall_at, int* hits, int* total) {
  for (int i = 0; i < recall_at && i < static_cast<int>(exact.size()); ++i) {
    const SearchResult& e = exact[i];
    ++*total;
    *hits += std::any_of(found.begin(), found.end(), [&](const SearchResult& f) {
      return Overlaps(e, f, 0.5) || Overlaps(f, e, 0.5);
    });
  }
}

absl::Status CheckOptions(const LibraryIndex& library, const std::vector<std::string>& labels,
                          const RetrievalOptions& options) {
  const size_t clips = library.clip_count();
  for (int c = 0; c < library.clip_count(); ++c) {
    if (library.clip(c).clip_id != c) {
      return absl::InvalidArgumentError("library clip ids must be their indices");
    }
  }
  if (labels.size() != clips) return absl::InvalidArgumentError("one label per library clip");
  if (!options.groups.empty() && options.groups.size() != clips) {
    return absl::InvalidArgumentError("groups: one per library clip, or none");
  }
  if (!options.queries.empty() && options.queries.size() != clips) {
    return absl::InvalidArgumentError("queries: one per library clip, or none");
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<RetrievalReport> EvaluateRetrieval(const LibraryIndex& library,
                                                  const std::vector<std::string>& labels,
                                                  const RetrievalOptions& options) {
  MOTIONDB_RETURN_IF_ERROR(CheckOptions(library, labels, options));
  RetrievalReport report;
  std::map<std::string, int> label_queries, group_queries;
  std::vector<double> latencies, exact_latencies, baseline_latencies;
  int recall_hits = 0, recall_total = 0, baseline_hits = 0, baseline_total = 0;
  BaselineFigures& baseline = report.baseline;
  for (int q = 0; q < library.clip_count(); ++q) {
    if (!options.queries.empty() && !options.queries[q]) continue;
    SearchParams params = options.params;
    params.max_results =
        std::max({options.precision_at, options.wide_precision_at, options.recall_at});
    params.clip_ids = FindableClips(library, options, q);
    params.tags.clear();
    if (CountLabel(params.clip_ids, labels, labels[q]) < options.precision_at) {
      ++report.skipped_queries;
      continue;
    }
    const int query_number = report.queries++;
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
    report.wide_precision += Precision(fast.results, labels, labels[q], options.wide_precision_at);
    report.precision_by_label[labels[q]] += precision;
    for (int i = 0; i < options.precision_at && i < static_cast<int>(fast.results.size()); ++i) {
      ++report.confusion[labels[q]][labels[fast.results[i].clip_index]];
    }
    ++label_queries[labels[q]];
    if (!options.groups.empty()) {
      report.precision_by_group[options.groups[q]] += precision;
      ++group_queries[options.groups[q]];
    }
    std::vector<SearchResult> baseline_results;
    if (options.baseline) {
      const auto start = std::chrono::steady_clock::now();
      baseline_results = options.baseline(query, params);
      baseline_latencies.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count());
      ++baseline.queries;
      const double p = Precision(baseline_results, labels, labels[q], options.precision_at);
      baseline.precision += p;
      baseline.wide_precision +=
          Precision(baseline_results, labels, labels[q], options.wide_precision_at);
      baseline.precision_by_label[labels[q]] += p;
      if (!options.groups.empty()) baseline.precision_by_group[options.groups[q]] += p;
    }
    if (options.exact_every > 0 && query_number % options.exact_every == 0) {
      MOTIONDB_ASSIGN_OR_RETURN(const SearchResponse exact, ExactSearch(library, query, params));
      exact_latencies.push_back(exact.stats.total_ms);
      report.exact_precision += Precision(exact.results, labels, labels[q], options.precision_at);
      report.exact_wide_precision +=
          Precision(exact.results, labels, labels[q], options.wide_precision_at);
      ++report.exact_queries;
      CountRecall(exact.results, fast.results, options.recall_at, &recall_hits, &recall_total);
      if (options.baseline) {
        CountRecall(exact.results, baseline_results, options.recall_at, &baseline_hits,
                    &baseline_total);
      }
    }
  }
  if (report.queries == 0) return absl::InvalidArgumentError("no query has enough relevant clips");
  report.precision /= report.queries;
  report.wide_precision /= report.queries;
  for (auto& [label, sum] : report.precision_by_label) sum /= label_queries[label];
  for (auto& [group, sum] : report.precision_by_group) sum /= group_queries[group];
  for (auto& [stage, sum] : report.mean_stage_ms) sum /= report.queries;
  if (report.exact_queries > 0) {
    report.exact_precision /= report.exact_queries;
    report.exact_wide_precision /= report.exact_queries;
  }
  report.recall = recall_total > 0 ? static_cast<double>(recall_hits) / recall_total : 0.0;
  report.latency_p50_ms = Percentile(latencies, 0.5);
  report.latency_p90_ms = Percentile(latencies, 0.9);
  report.latency_p99_ms = Percentile(latencies, 0.99);
  report.exact_latency_p50_ms = Percentile(exact_latencies, 0.5);
  report.exact_latency_p99_ms = Percentile(exact_latencies, 0.99);
  if (baseline.queries > 0) {
    baseline.precision /= baseline.queries;
    baseline.wide_precision /= baseline.queries;
    for (auto& [label, sum] : baseline.precision_by_label) sum /= label_queries[label];
    for (auto& [group, sum] : baseline.precision_by_group) sum /= group_queries[group];
    baseline.recall =
        baseline_total > 0 ? static_cast<double>(baseline_hits) / baseline_total : 0.0;
    baseline.latency_p50_ms = Percentile(baseline_latencies, 0.5);
    baseline.latency_p90_ms = Percentile(baseline_latencies, 0.9);
    baseline.latency_p99_ms = Percentile(baseline_latencies, 0.99);
  }
  return report;
}

}  // namespace motiondb::testing
