#include "server/search_runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "absl/cleanup/cleanup.h"
#include "absl/strings/str_cat.h"
#include "core/index/coarse_rate.h"
#include "core/motion/resample.h"
#include "core/search/exact_search.h"
#include "core/search/motion_search.h"
#include "core/search/warp/time_warp.h"
#include "core/space/search_coordinates.h"
#include "server/query_mirror.h"
#include "server/skeleton_map.h"
#include "server/space_lookup.h"
#include "util/parallel_for.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// The query: rows at the space rate, and how they map to the query clip's own frames.
struct Query {
  std::optional<RowMatrixXf> uploaded;  // an uploaded file's projection
  CoordinateView stored;                // a stored clip's projection, in the snapshot's index
  FrameConversion frames{1, 1, 1, 1};
  FrameRange range;  // at the clip's rate
  // The query clip's frame that is frame 0 of the rows' clip: a stored range read alone (to be
  // mirrored) starts at its first frame.
  int frame_offset = 0;
  int64_t first_row = 0;  // of the range, at the space rate
  int64_t row_count = 0;

  // Derived on demand rather than stored: a view into `uploaded` would not survive a copy.
  CoordinateView rows() const {
    return (uploaded ? CoordinateView::Of(*uploaded) : stored).middle_rows(first_row, row_count);
  }
};

void SetRows(Query* query) {
  const auto [first, last] = query->frames.ToSpace(FrameRange{
      query->range.first - query->frame_offset, query->range.last - query->frame_offset});
  query->first_row = first;
  query->row_count = last - first + 1;
}

// INVALID_ARGUMENT naming `field`, the limit and its flag when `rows`, a query's frames at the
// space's rate (`what` says them at the query's own), exceed `max_rows`.
absl::Status CheckQueryLength(absl::string_view field, int64_t rows, double rate,
                              absl::string_view what, int max_rows) {
  if (rows <= max_rows) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat(field, ": the query spans ", rows, " frames at the space's ", rate, " fps (",
                   what, "); this server searches queries of at most ", max_rows,
                   " frames (--max-query-frames): search a shorter stretch"));
}

// The rows of the anchored warps a search of `rows` query frames runs: at the coarse rate
// (core/index/coarse_rate.h) with refinement, else every frame; 0 for the exact search without
// paths, which runs none (its scan keeps a few columns).
int64_t AnchoredWarpRows(int64_t rows, const SearchParams& params, bool exact, double rate) {
  if (exact) return params.return_path ? rows : 0;
  if (!params.refine) return rows;
  return (rows - 1) / CoarseFactor(rate) + 1;
}

// INVALID_ARGUMENT naming slope_limit when the query's warps would fill a larger table than a
// query of `max_rows` frames warped at every frame at the default slope limit: the table grows
// with the square of the rows and of the slope limit (AnchoredWarpTableBytes), so that at slope
// limit 8 a query of --max-query-frames frames would take 21 times as much.
absl::Status CheckWarpMemory(int64_t rows, const SearchParams& params, bool exact, double rate,
                             int max_rows) {
  const int64_t budget = AnchoredWarpTableBytes(max_rows, kDefaultSlopeLimit);
  const int64_t warp_rows = AnchoredWarpRows(rows, params, exact, rate);
  const int64_t bytes = AnchoredWarpTableBytes(warp_rows, params.slope_limit);
  if (bytes <= budget) return absl::OkStatus();
  int64_t fits = rows;  // the longest query whose warps fit; it exists: one frame takes no table
  while (AnchoredWarpTableBytes(AnchoredWarpRows(fits, params, exact, rate), params.slope_limit) >
         budget) {
    fits = fits * 15 / 16;
  }
  constexpr double kMiB = 1 << 20;
  return absl::InvalidArgumentError(absl::StrCat(
      "slope_limit = ", params.slope_limit, ": the warps of this ", rows,
      "-frame query would take ", std::lround(bytes / kMiB), " MiB, more than the ",
      std::lround(budget / kMiB), " MiB of a ", max_rows, "-frame query at slope limit ",
      kDefaultSlopeLimit, " (--max-query-frames); lower slope_limit, or search about ", fits,
      " frames at most"));
}

absl::StatusOr<Query> StoredQuery(const ClipSelection& range, const SpaceSnapshot& snapshot,
                                  storage::Database& database, int max_rows) {
  // Also covers a space without clips, hence without an index.
  MOTIONDB_RETURN_IF_ERROR(CheckClipInSpace(database, snapshot, range.clip_id));
  Query query;
  query.stored = snapshot.index->clip_coordinates(snapshot.index->FindClip(range.clip_id));
  query.frames = snapshot.Conversion(range.clip_id);
  MOTIONDB_ASSIGN_OR_RETURN(
      query.range, ResolveFrameRange(range, snapshot.clips.at(range.clip_id).frame_count, "clip"));
  SetRows(&query);
  MOTIONDB_RETURN_IF_ERROR(CheckQueryLength(
      "clip", query.row_count, snapshot.space->sample_rate(),
      absl::StrCat("frames ", query.range.first, "..", query.range.last, " of the clip at its ",
                   snapshot.clips.at(range.clip_id).fps, " fps"),
      max_rows));
  return query;
}

// `coordinates`, `clip`'s search coordinates whole, as the query of the frames `range` (numbered
// from `frame_offset`, the query clip's frame that is `clip`'s first).
Query CoordinatesQuery(RowMatrixXf coordinates, const Clip& clip, FrameRange range,
                       int frame_offset, const SpaceSnapshot& snapshot) {
  Query query;
  query.frames = FrameConversion(clip.fps(), clip.frame_count(), snapshot.space->sample_rate(),
                                 coordinates.rows());
  query.uploaded = std::move(coordinates);
  query.range = range;
  query.frame_offset = frame_offset;
  SetRows(&query);
  return query;
}

// `clip` projected whole, as a stored clip is, as the query of the frames `range` (as above).
absl::StatusOr<Query> ProjectedQuery(const Clip& clip, FrameRange range, int frame_offset,
                                     const SpaceSnapshot& snapshot,
                                     const HumanoidMap* map = nullptr) {
  MOTIONDB_ASSIGN_OR_RETURN(RowMatrixXf coordinates,
                            SearchCoordinates(*snapshot.space, clip, -1, map));
  return CoordinatesQuery(std::move(coordinates), clip, range, frame_offset, snapshot);
}

// `clip`, an uploaded file's, as the query of its frames `upload` asks for.
absl::StatusOr<Query> QueryOfUpload(const UploadedQuery& upload, const Clip& clip,
                                    const SpaceSnapshot& snapshot, storage::Database& database,
                                    int max_rows) {
  std::optional<HumanoidMap> map;
  if (snapshot.space->canonical()) {
    MOTIONDB_ASSIGN_OR_RETURN(map, CanonicalMapOfClip(database, clip));
  } else if (!clip.skeleton().SameTopology(snapshot.space->skeleton())) {
    return absl::FailedPreconditionError(absl::StrCat(
        "bvh: the query's skeleton (", clip.skeleton().joint_count(), " joints, root '",
        clip.skeleton().joint(0).name, "') is not the skeleton of space '", snapshot.record.name,
        "' (", snapshot.space->skeleton().joint_count(), " joints, root '",
        snapshot.space->skeleton().joint(0).name, "')"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      const FrameRange range,
      ResolveFrameRange(upload.first_frame, upload.last_frame, clip.frame_count(), "bvh"));
  // The whole file is projected, as a stored clip is, so that a range of an uploaded file gives
  // the same query as the same range of the file once stored: its whole length counts.
  MOTIONDB_RETURN_IF_ERROR(CheckQueryLength(
      "bvh",
      ResampledFrameCount(clip.frame_count(), clip.frame_time(), snapshot.space->sample_rate()),
      snapshot.space->sample_rate(),
      absl::StrCat("the file's ", clip.frame_count(), " frames at its ", clip.fps(),
                   " fps; a range of it is searched after the whole file is projected"),
      max_rows));
  return ProjectedQuery(clip, range, /*frame_offset=*/0, snapshot, map ? &*map : nullptr);
}

// The mirror of `query` (of `uploaded`, an uploaded file's clip, or else of a stored clip's
// range, read alone), projected on the spot.
absl::StatusOr<Query> MirroredQuery(const Query& query, const std::optional<Clip>& uploaded,
                                    const SearchRequest& request, const SpaceSnapshot& snapshot,
                                    storage::Database& database) {
  std::optional<Clip> stored;
  if (!uploaded) {
    MOTIONDB_ASSIGN_OR_RETURN(
        storage::StoredClip range,
        database.GetClip(std::get<ClipSelection>(request.query).clip_id, query.range));
    stored = std::move(range.clip);
  }
  const Clip& clip = uploaded ? *uploaded : *stored;
  MOTIONDB_ASSIGN_OR_RETURN(RowMatrixXf coordinates, MirroredCoordinates(database, snapshot, clip));
  return CoordinatesQuery(std::move(coordinates), clip, query.range,
                          uploaded ? 0 : query.range.first, snapshot);
}

// A query frame (at its clip's rate, in its numbering) as a row of the query at the space rate.
absl::StatusOr<int> QueryRow(const Query& query, int frame, absl::string_view field) {
  if (frame < query.range.first || frame > query.range.last) {
    return absl::InvalidArgumentError(absl::StrCat(field, ": ", frame,
                                                   " is outside the query's frames ",
                                                   query.range.first, "..", query.range.last));
  }
  return static_cast<int>(std::clamp<int64_t>(
      query.frames.ToSpace(frame - query.frame_offset) - query.first_row, 0, query.row_count - 1));
}

absl::StatusOr<SearchParams> ResolveParams(const SearchRequest& request, const Query& query,
                                           int dims, int searches_running) {
  SearchParams params = WithSearchDims(request, dims);
  const bool automatic = !request.threads || *request.threads == 0;
  params.threads = automatic ? (searches_running == 1 ? ThreadsFor(0) : 1) : *request.threads;
  params.characteristic_frame = -1;
  if (request.characteristic_frame) {
    MOTIONDB_ASSIGN_OR_RETURN(
        params.characteristic_frame,
        QueryRow(query, *request.characteristic_frame, "characteristic_frame (or -1: automatic)"));
  }
  params.characteristic_frames.clear();
  for (size_t i = 0; i < request.characteristic_frames.size(); ++i) {
    const int frame = request.characteristic_frames[i];
    MOTIONDB_ASSIGN_OR_RETURN(
        const int row, QueryRow(query, frame, absl::StrCat("characteristic_frames[", i, "]")));
    if (i > 0 && frame <= request.characteristic_frames[i - 1]) {
      return absl::InvalidArgumentError(absl::StrCat("characteristic_frames[", i, "]: ", frame,
                                                     " does not follow the frame before it, ",
                                                     request.characteristic_frames[i - 1]));
    }
    if (i > 0 && row <= params.characteristic_frames.back()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "characteristic_frames[", i, "]: ", frame, " and ", request.characteristic_frames[i - 1],
          " fall on one frame at the space's rate; give frames further apart"));
    }
    params.characteristic_frames.push_back(row);
  }
  // Checked before the answer and the warps' memory are sized from them (a bad max_results is
  // INVALID_ARGUMENT, not a refused answer); the engine checks them again with the same function
  // at its entry (core/search/search_query.cc), its contract with every caller.
  MOTIONDB_RETURN_IF_ERROR(ValidateSearchParams(params, dims));
  // Threads past the cores would only spin beside each other.
  params.threads = std::min(params.threads, ThreadsFor(0));
  return params;
}

SearchHit HitOf(const SearchResult& result, const SpaceSnapshot& snapshot) {
  const FrameConversion frames = snapshot.Conversion(result.clip_id);
  SearchHit hit;
  hit.clip_id = result.clip_id;
  hit.clip_name = result.clip_name;
  hit.start_s = result.start_s;
  hit.end_s = result.end_s;
  hit.start_frame = frames.ToOriginal(result.first_frame);
  hit.end_frame = frames.ToOriginal(result.last_frame);
  hit.score = result.score;
  hit.seed_frame = result.seed_frame >= 0 ? frames.ToOriginal(result.seed_frame) : -1;
  hit.path.reserve(result.path.size());
  for (const int64_t frame : result.path) hit.path.push_back(frames.ToOriginal(frame));
  return hit;
}

// What Hits needs beyond the query: how to search and what to add to each hit.
struct HitOptions {
  bool exact = false;
  bool explain = false;
  bool keep_paths = false;  // the caller asked for the paths
};

// `result` as a hit, explained when asked.
absl::StatusOr<SearchHit> FullHit(const SpaceSnapshot& snapshot, const Query& query,
                                  const SearchResult& result, const HitOptions& options) {
  SearchHit hit = HitOf(result, snapshot);
  if (options.explain) {
    MOTIONDB_ASSIGN_OR_RETURN(
        hit.explanation,
        ExplainHit(*snapshot.space, query.rows(),
                   snapshot.index->clip_coordinates(result.clip_index), result.path));
  }
  if (!options.keep_paths) hit.path.clear();
  return hit;
}

// A stored query's own range (at its clip's rate) as the search leaves it out: the space frames
// of the hits that would overlap it, which are exactly those whose own frames would
// (FrameConversion::SpaceFramesWithin).
std::optional<ExcludedRange> OwnRange(const SpaceSnapshot& snapshot, int64_t clip_id,
                                      FrameRange frames) {
  if (!snapshot.index || snapshot.index->FindClip(clip_id) < 0) return std::nullopt;
  const auto [first, last] = snapshot.Conversion(clip_id).SpaceFramesWithin(frames);
  return ExcludedRange{clip_id, first, last};
}

// One search of a request: the query or its mirror, with its own parameters (their rows).
struct Half {
  const Query* query = nullptr;
  SearchParams params;
  bool mirrored = false;
};

// Runs the search of each half and makes their results hits: one half's as they come, two
// halves' ranked together (RankedIndices) under the first's max_results and max_overlap. The
// stats are the first half's, with the second's work added.
absl::StatusOr<std::vector<SearchHit>> Hits(const SpaceSnapshot& snapshot,
                                            const std::vector<Half>& halves,
                                            const HitOptions& options, SearchStats* stats) {
  std::vector<SearchResult> candidates;
  std::vector<size_t> half_of;  // by candidate
  for (size_t h = 0; h < halves.size(); ++h) {
    SearchParams params = halves[h].params;
    params.return_path = params.return_path || options.explain;
    const CoordinateView rows = halves[h].query->rows();
    MOTIONDB_ASSIGN_OR_RETURN(SearchResponse found, options.exact
                                                        ? ExactSearch(*snapshot.index, rows, params)
                                                        : Search(*snapshot.index, rows, params));
    if (h == 0) {
      *stats = found.stats;
    } else {
      AddStageStats(found.stats, *stats);
      stats->total_ms += found.stats.total_ms;
    }
    for (SearchResult& result : found.results) {
      candidates.push_back(std::move(result));
      half_of.push_back(h);
    }
  }
  std::vector<size_t> kept(candidates.size());
  for (size_t i = 0; i < kept.size(); ++i) kept[i] = i;
  if (halves.size() > 1) {
    kept = RankedIndices(candidates, halves[0].params.max_overlap, halves[0].params.max_results);
  }
  std::vector<SearchHit> hits;
  hits.reserve(kept.size());
  for (const size_t i : kept) {
    const Half& half = halves[half_of[i]];
    MOTIONDB_ASSIGN_OR_RETURN(hits.emplace_back(),
                              FullHit(snapshot, *half.query, candidates[i], options));
    hits.back().mirrored = half.mirrored;
  }
  return hits;
}

// The answer's size at most (SearchAnswerBytes) for queries of up to `query_rows` rows, checked
// with what the batch's earlier answers took against request.answers.
absl::StatusOr<int64_t> CheckAnswer(const SearchRequest& request, const SearchParams& params,
                                    int64_t query_rows, const Skeleton& skeleton) {
  const int64_t path_rows = request.params.return_path ? query_rows : 0;
  const int64_t bytes = SearchAnswerBytes(params.max_results, path_rows, request.explain, skeleton);
  MOTIONDB_RETURN_IF_ERROR(request.answers->Check(
      request.answers_used + bytes + kAnswerFixedBytes,
      absl::StrCat(request.answers_used > 0 ? "with the batch's earlier answers, " : "",
                   "the answer of up to ", params.max_results, " results",
                   path_rows > 0 ? absl::StrCat(" with paths of ", path_rows, " frames") : "",
                   request.explain ? " explained" : ""),
      request.answers_used > 0
          ? "send the rest of the batch in another call, or ask for fewer max_results"
          : "ask for fewer max_results, or without return_path and explain"));
  return bytes;
}

}  // namespace

SearchParams WithSearchDims(const SearchRequest& request, int dims) {
  SearchParams params = request.params;
  const SearchParams defaults;
  params.ann_dims = request.ann_dims.value_or(std::min(defaults.ann_dims, dims));
  params.dtw_dims = request.dtw_dims.value_or(std::min(defaults.dtw_dims, dims));
  return params;
}

absl::StatusOr<SearchOutcome> SearchRunner::Run(const SearchRequest& request,
                                                const std::function<bool()>& should_stop) const {
  const auto start = std::chrono::steady_clock::now();
  const int searches_running = ++running_;
  const absl::Cleanup done = [this] { --running_; };
  // The snapshot is held to the end: the query's rows and the results point into it.
  MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> snapshot,
                            FindSpace(registry_, request.space));
  const int dims = snapshot->space->dims();
  Query query;
  std::optional<Clip> uploaded;  // an uploaded query's clip, kept to be mirrored
  const HitOptions options{request.exact, request.explain, request.params.return_path};
  std::optional<ExcludedRange> own;
  if (const auto* stored = std::get_if<ClipSelection>(&request.query)) {
    MOTIONDB_ASSIGN_OR_RETURN(query, StoredQuery(*stored, *snapshot, database_, max_query_frames_));
    if (request.exclude_query.value_or(true))
      own = OwnRange(*snapshot, stored->clip_id, query.range);
  } else if (const auto* upload = std::get_if<UploadedQuery>(&request.query)) {
    MOTIONDB_ASSIGN_OR_RETURN(UploadedFile read,
                              ReadUpload(upload->bvh, "bvh", limits_, should_stop));
    if (read.takes.size() != 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("bvh: the file holds ", read.takes.size(),
                       " takes; a query is one (ingest the file and query a take by its clip)"));
    }
    uploaded = std::move(read.takes[0].clip);
    MOTIONDB_ASSIGN_OR_RETURN(
        query, QueryOfUpload(*upload, *uploaded, *snapshot, database_, max_query_frames_));
  } else {
    return absl::InvalidArgumentError("query: give a stored clip (clip) or a BVH file (bvh)");
  }
  std::optional<Query> mirrored;
  if (request.mirror) {
    MOTIONDB_ASSIGN_OR_RETURN(mirrored,
                              MirroredQuery(query, uploaded, request, *snapshot, database_));
  }
  std::vector<Half> halves;
  for (const Query* half : {&query, mirrored ? &*mirrored : nullptr}) {
    if (half == nullptr) continue;
    MOTIONDB_ASSIGN_OR_RETURN(SearchParams params,
                              ResolveParams(request, *half, dims, searches_running));
    params.excluded = own;
    SearchParams searched = params;
    searched.return_path = params.return_path || request.explain;  // as Hits asks
    MOTIONDB_RETURN_IF_ERROR(CheckWarpMemory(half->row_count, searched, request.exact,
                                             snapshot->space->sample_rate(), max_query_frames_));
    params.should_stop = should_stop;
    halves.push_back({half, std::move(params), half != &query});
  }

  SearchOutcome outcome;
  if (request.answers != nullptr) {
    const int64_t rows = std::max(query.row_count, mirrored ? mirrored->row_count : 0);
    MOTIONDB_ASSIGN_OR_RETURN(outcome.answer_bytes, CheckAnswer(request, halves[0].params, rows,
                                                                snapshot->space->skeleton()));
  }
  outcome.query_frames = query.row_count;
  if (snapshot->index) {
    outcome.library_frames = snapshot->index->total_frames();
    MOTIONDB_ASSIGN_OR_RETURN(outcome.hits, Hits(*snapshot, halves, options, &outcome.stats));
    if (outcome.stats.characteristic_frame >= 0) {
      outcome.characteristic_frame =
          query.frames.ToOriginal(query.first_row + outcome.stats.characteristic_frame);
    }
    for (const int row : outcome.stats.characteristic_frames) {
      outcome.characteristic_frames.push_back(query.frames.ToOriginal(query.first_row + row));
    }
    if (outcome.stats.second_anchor >= 0) {
      outcome.second_anchor_frame =
          query.frames.ToOriginal(query.first_row + outcome.stats.second_anchor);
    }
  }
  outcome.request_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return outcome;
}

}  // namespace motiondb::server
