// One search, from request to ranked hits: the query's coordinates (rows of a stored clip's
// cached projection, or an uploaded BVH projected on the spot), the parameters with the
// thesis's defaults for what is unset, and the hits with frame numbers converted back to each
// clip's own rate.
#ifndef MOTIONDB_SERVER_SEARCH_RUNNER_H_
#define MOTIONDB_SERVER_SEARCH_RUNNER_H_

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "absl/status/statusor.h"
#include "core/search/search_params.h"
#include "core/search/search_result.h"
#include "server/answer_limit.h"
#include "server/frame_conversion.h"
#include "server/index_registry.h"
#include "server/search_explanation.h"
#include "server/upload/upload.h"
#include "storage/database.h"

namespace motiondb::server {

// A query sent as a BVH file, whole or a range of its frames (at its own rate).
struct UploadedQuery {
  std::string bvh;
  std::optional<int> first_frame;
  std::optional<int> last_frame;
};

struct SearchRequest {
  std::string space;
  // A stored clip's frames or an uploaded file's; monostate is INVALID_ARGUMENT.
  std::variant<std::monostate, ClipSelection, UploadedQuery> query;
  // Every parameter but the three below, which the request states in its own terms.
  SearchParams params;
  // Unset: SearchParams' defaults, or all of a smaller space's dimensions.
  std::optional<int> ann_dims;
  std::optional<int> dtw_dims;
  // A query frame at the query clip's own rate, inside its range; unset: found automatically.
  std::optional<int> characteristic_frame;
  // Several characteristic points, as characteristic_frame, increasing (SearchParams'
  // characteristic_frames); empty: none given.
  std::vector<int> characteristic_frames;
  // Threads of a fast search (SearchParams::threads), at most the cores; unset or 0: every core
  // when the search starts while the runner runs no other, else one, so that a quiet server
  // answers one client sooner and a busy one gives each search a core as before.
  std::optional<int> threads;
  // The exhaustive search instead of the seeded one.
  bool exact = false;
  // A stored-clip query: drop hits in its clip overlapping its range (unset: true), filling
  // params.max_results with others. Ignored for an uploaded query.
  std::optional<bool> exclude_query;
  // Also search the query's left/right mirror (core/motion/clip_mirror.h, by the skeleton's
  // humanoid map): its rows projected on the spot, searched with the same parameters and
  // excluded range, its results ranked with the query's own under the one max_results and
  // overlap suppression, each marked SearchHit::mirrored. FAILED_PRECONDITION when the
  // skeleton's map cannot mirror.
  bool mirror = false;
  // Each hit with its SearchExplanation (the path is computed for it, and returned only when
  // params.return_path asks).
  bool explain = false;
  // The answer's limit, for a search whose hits are sent (not a job's): RESOURCE_EXHAUSTED
  // before the search when `answers_used` (what a batch's earlier answers took) and this answer
  // (SearchAnswerBytes of max_results, the query's rows when paths are returned) could exceed
  // it. Null: no limit.
  const AnswerLimit* answers = nullptr;
  int64_t answers_used = 0;
};

// The request's params with its ann_dims and dtw_dims, or where unset SearchParams' defaults
// capped at a space of `dims` dimensions: the one place the default dimensions are chosen.
SearchParams WithSearchDims(const SearchRequest& request, int dims);

// A ranked time range, in the clip's own frames (inclusive).
struct SearchHit {
  int64_t clip_id = 0;
  std::string clip_name;
  double start_s = 0;
  double end_s = 0;
  int start_frame = 0;
  int end_frame = 0;
  double score = 0;       // mean pose distance along the warp; lower is better
  int seed_frame = -1;    // the frame matched to the characteristic query frame; -1 in exact mode
  bool mirrored = false;  // found by the query's mirror (SearchRequest::mirror)
  std::vector<int> path;  // per query sample at the space rate (of the mirror's when mirrored)
  std::optional<SearchExplanation> explanation;  // when requested
};

struct SearchOutcome {
  std::vector<SearchHit> hits;
  SearchStats stats;                       // zero when the space holds no clips
  int characteristic_frame = -1;           // at the query clip's rate; -1 when none was used
  std::vector<int> characteristic_frames;  // every one used, as characteristic_frame
  int second_anchor_frame = -1;            // as characteristic_frame; -1 when none was used
  int64_t query_frames = 0;                // at the space rate
  int64_t answer_bytes = 0;  // with SearchRequest::answers: the answer's size, at most
  int64_t library_frames = 0;
  double request_ms = 0;  // the whole request, query projection included
};

// The longest query searched, in frames at the space's rate, unless the server is told
// otherwise (--max-query-frames). A query is an example of a motion: an action takes seconds,
// and a query of several (characteristic_points) a minute at most; 4000 frames are 2 min 13 s at
// the default 30 Hz, 33 s at 120 Hz. A search's memory grows with the square of its warps' rows
// (docs/server-limits.md, "Deadlines and query length"; bench/notes/2026-12-06-deadlines.md).
inline constexpr int kDefaultMaxQueryFrames = 4000;

// Thread-safe: searches run concurrently on immutable snapshots.
class SearchRunner {
 public:
  // Queries longer than `max_query_frames` at the space's rate are refused with
  // INVALID_ARGUMENT before they are projected or searched.
  SearchRunner(const IndexRegistry& registry, storage::Database& database,
               const UploadLimits& limits, int max_query_frames = kDefaultMaxQueryFrames)
      : registry_(registry),
        database_(database),
        limits_(limits),
        max_query_frames_(max_query_frames) {}

  // Runs `request` against the space it names. `should_stop` ends the search with CANCELLED.
  absl::StatusOr<SearchOutcome> Run(const SearchRequest& request,
                                    const std::function<bool()>& should_stop) const;

 private:
  const IndexRegistry& registry_;
  storage::Database& database_;
  UploadLimits limits_;
  int max_query_frames_;
  mutable std::atomic<int> running_{0};  // searches in Run now
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_SEARCH_RUNNER_H_
