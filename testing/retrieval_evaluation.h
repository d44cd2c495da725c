// Retrieval quality of a labelled library: every clip is a query against all the other clips
// (leave-one-out) or against the clips of other groups (leave-group-out: a style against every
// other style, one dataset against another). Measures precision@k of the label for the fast and
// (on a subset) the exact search, and the fast search's recall against the exact one.
#ifndef MOTIONDB_TESTING_RETRIEVAL_EVALUATION_H_
#define MOTIONDB_TESTING_RETRIEVAL_EVALUATION_H_

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/index/library_index.h"
#include "core/search/search_params.h"
#include "core/search/search_result.h"

namespace motiondb::testing {

struct RetrievalOptions {
  // Search parameters of every query (filters are set by the evaluation).
  SearchParams params;
  // Precision is measured over the first this many results, and over the first
  // `wide_precision_at` (with the same queries: those with `precision_at` findable clips).
  int precision_at = 5;
  int wide_precision_at = 10;
  // Recall of the fast search against the exact search's first this many results.
  int recall_at = 10;
  // Every n-th query also runs the exact search (0: never).
  int exact_every = 10;
  // Per clip, its group: a query searches the clips of other groups only. Empty: every other
  // clip (leave-one-out).
  std::vector<std::string> groups;
  // Per clip, whether it is a query. Empty: every clip. A query is left out (and counted in
  // `skipped_queries`) when fewer than `precision_at` clips it may find share its label, as its
  // precision could not reach 1.
  std::vector<bool> queries;
  // Another search run on every query beside the fast one, scored and timed the same way (e.g.
  // bench/'s window-vector baseline): its results for `query` among `params.clip_ids` (library
  // indices, equal to the ids here), at most `params.max_results`, best first. Empty: none.
  std::function<std::vector<SearchResult>(CoordinateView query, const SearchParams& params)>
      baseline;
};

// RetrievalOptions::baseline's figures, on the same queries.
struct BaselineFigures {
  int queries = 0;
  double precision = 0;       // at precision_at, mean over queries
  double wide_precision = 0;  // at wide_precision_at
  double recall = 0;          // exact results it finds, on the exact search's queries
  double latency_p50_ms = 0;
  double latency_p90_ms = 0;
  double latency_p99_ms = 0;
  std::map<std::string, double> precision_by_label;
  std::map<std::string, double> precision_by_group;  // with RetrievalOptions::groups
};

struct RetrievalReport {
  int queries = 0;
  int skipped_queries = 0;
  double precision = 0;       // fast search, mean over queries
  double wide_precision = 0;  // at wide_precision_at
  int exact_queries = 0;
  double exact_precision = 0;  // exact search, mean over its queries
  double exact_wide_precision = 0;
  double recall = 0;  // exact results found by the fast search (overlapping by half)
  double latency_p50_ms = 0;
  double latency_p90_ms = 0;
  double latency_p99_ms = 0;
  double exact_latency_p50_ms = 0;
  double exact_latency_p99_ms = 0;
  BaselineFigures baseline;
  std::map<std::string, double> precision_by_label;
  std::map<std::string, double> precision_by_group;  // with RetrievalOptions::groups
  // Per query label, the labels of the fast search's first `precision_at` results, counted.
  std::map<std::string, std::map<std::string, int>> confusion;
  std::map<std::string, double> mean_stage_ms;  // seeds, clusters, warps, refine, ranking
};

// `labels[c]` is clip c's label. Queries are the clips' own library coordinates.
absl::StatusOr<RetrievalReport> EvaluateRetrieval(const LibraryIndex& library,
                                                  const std::vector<std::string>& labels,
                                                  const RetrievalOptions& options);

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTING_RETRIEVAL_EVALUATION_H_
