#include "core/search/exact_search.h"

#include <chrono>
#include <vector>

#include "core/search/internal/clip_scan.h"
#include "core/search/internal/search_query.h"
#include "util/parallel_for.h"
#include "util/status_macros.h"

namespace motiondb {

absl::StatusOr<SearchResponse> ExactSearch(const LibraryIndex& library, CoordinateView query,
                                           const SearchParams& params) {
  const auto start = std::chrono::steady_clock::now();
  MOTIONDB_ASSIGN_OR_RETURN(const SearchFilter filter, PrepareQuery(library, query, params));
  SearchResponse response;
  const auto warps = std::chrono::steady_clock::now();
  FinishedClips finished(params.max_results, query.rows);
  std::vector<SearchStats> stats(ThreadsFor(params.exact_threads));
  std::vector<ClipScanWorkspace> workspaces(stats.size());
  MOTIONDB_RETURN_IF_ERROR(ParallelFor(
      library.clip_count(), static_cast<int>(stats.size()),
      [&](int64_t index, int thread) -> absl::Status {
        const int c = static_cast<int>(index);
        if (!filter.allowed.empty() && !filter.allowed[c]) return absl::OkStatus();
        // Each thread polls on its own; every one of them stops within a poll's work.
        StopPoll stop = SearchStop(params);
        if (stop.Done(query.rows)) return SearchStopped();
        StreamingTopResults top(params.max_results, params.max_overlap, query.rows);
        MOTIONDB_RETURN_IF_ERROR(ScanClip(
            query, library.clip_coordinates(c), 0, 1, c, library.clip(c).clip_id, params, filter,
            stop, [&] { return finished.bound(); }, workspaces[thread], top, stats[thread]));
        // Most clips hold nothing under the bound: adding nothing would only take the
        // lock.
        std::vector<SearchResult> results = top.Take();
        if (!results.empty()) finished.Add(std::move(results));
        return absl::OkStatus();
      }));
  for (const SearchStats& thread_stats : stats) {
    response.stats.cells += thread_stats.cells;
    response.stats.pruned_blocks += thread_stats.pruned_blocks;
  }
  response.stats.warps_ms = MillisecondsSince(warps);
  std::vector<SearchResult> best = finished.Take();
  if (params.return_path) MOTIONDB_RETURN_IF_ERROR(AddPaths(library, query, params, 1, best));
  response.results = FinishResults(library, filter, std::move(best), params);
  response.stats.total_ms = MillisecondsSince(start);
  return response;
}

}  // namespace motiondb
