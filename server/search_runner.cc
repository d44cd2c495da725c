#include "server/search_runner.h"

#include <algorithm>
#include <chrono>
#include <optional>

#include "absl/strings/str_cat.h"
#include "core/bvh/bvh_reader.h"
#include "core/search/exact_search.h"
#include "core/search/motion_search.h"
#include "core/space/search_coordinates.h"
#include "server/frame_conversion.h"
#include "server/space_lookup.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// Seed and warp dimensions when the request leaves them unset: the thesis's 10 and 5, or all of
// a smaller space's.
constexpr int kDefaultAnnDims = 10;
constexpr int kDefaultDtwDims = 5;

// The query: rows at the space rate, and how they map to the query clip's own frames.
struct Query {
  std::optional<RowMatrixXf> uploaded;  // an uploaded file's projection
  CoordinateView stored;                // a stored clip's projection, in the snapshot's index
  FrameConversion frames{1, 1, 1, 1};
  FrameRange range;       // at the clip's rate
  int64_t first_row = 0;  // of the range, at the space rate
  int64_t row_count = 0;

  // Derived on demand rather than stored: a view into `uploaded` would not survive a copy.
  CoordinateView rows() const {
    return (uploaded ? CoordinateView::Of(*uploaded) : stored).middle_rows(first_row, row_count);
  }
};

void SetRows(Query* query) {
  const auto [first, last] = query->frames.ToSpace(query->range);
  query->first_row = first;
  query->row_count = last - first + 1;
}

absl::StatusOr<Query> StoredQuery(const v1::ClipRange& range, const SpaceSnapshot& snapshot,
                                  storage::Database& database) {
  MOTIONDB_RETURN_IF_ERROR(CheckClipInSpace(database, snapshot, range.clip_id()));
  Query query;
  query.stored = snapshot.index->clip_coordinates(snapshot.index->FindClip(range.clip_id()));
  query.frames = snapshot.Conversion(range.clip_id());
  MOTIONDB_ASSIGN_OR_RETURN(
      query.range,
      ResolveFrameRange(range, snapshot.clips.at(range.clip_id()).frame_count, "clip"));
  SetRows(&query);
  return query;
}

absl::StatusOr<Query> UploadedQuery(const v1::BvhQuery& bvh, const SpaceSnapshot& snapshot,
                                    const SearchLimits& limits) {
  if (static_cast<int64_t>(bvh.bvh().size()) > limits.max_bvh_bytes) {
    return absl::ResourceExhaustedError(absl::StrCat("bvh: the query file is ", bvh.bvh().size(),
                                                     " bytes; this server accepts at most ",
                                                     limits.max_bvh_bytes, " (--max-bvh-mb)"));
  }
  BvhReadOptions options;
  options.max_bytes = limits.max_bvh_bytes;
  absl::StatusOr<BvhReadResult> read = ReadBvh(bvh.bvh(), options);
  if (!read.ok()) {
    return absl::Status(read.status().code(), absl::StrCat("bvh: ", read.status().message()));
  }
  const Clip& clip = read->clip;
  if (!clip.skeleton().SameTopology(snapshot.space->skeleton())) {
    return absl::FailedPreconditionError(absl::StrCat(
        "bvh: the query's skeleton (", clip.skeleton().joint_count(), " joints, root '",
        clip.skeleton().joint(0).name, "') is not the skeleton of space '", snapshot.record.name,
        "' (", snapshot.space->skeleton().joint_count(), " joints, root '",
        snapshot.space->skeleton().joint(0).name, "')"));
  }
  Query query;
  MOTIONDB_ASSIGN_OR_RETURN(query.range, ResolveFrameRange(bvh, clip.frame_count(), "bvh"));
  // The whole file is projected, as a stored clip is, so that a range of an uploaded file gives
  // the same query as the same range of the file once stored.
  MOTIONDB_ASSIGN_OR_RETURN(query.uploaded, SearchCoordinates(*snapshot.space, clip));
  query.frames = FrameConversion(clip.fps(), clip.frame_count(), snapshot.space->sample_rate(),
                                 query.uploaded->rows());
  SetRows(&query);
  return query;
}

absl::StatusOr<NeutralPose> ToNeutralPose(v1::NeutralPose neutral) {
  switch (neutral) {
    case v1::NEUTRAL_POSE_UNSPECIFIED:
    case v1::NEUTRAL_POSE_QUERY_MEAN:
      return NeutralPose::kQueryMean;
    case v1::NEUTRAL_POSE_BOUNDARY_MEAN:
      return NeutralPose::kBoundaryMean;
    case v1::NEUTRAL_POSE_ORIGIN:
      return NeutralPose::kOrigin;
    default:
      return absl::InvalidArgumentError(absl::StrCat("neutral: unknown value ", neutral));
  }
}

absl::StatusOr<SearchParams> ToParams(const v1::SearchRequest& request, const Query& query,
                                      int dims) {
  SearchParams params;
  params.ann_dims = request.has_ann_dims() ? request.ann_dims() : std::min(kDefaultAnnDims, dims);
  if (request.has_neighbours()) params.neighbours = request.neighbours();
  if (request.has_epsilon()) params.epsilon = request.epsilon();
  params.dtw_dims = request.has_dtw_dims() ? request.dtw_dims() : std::min(kDefaultDtwDims, dims);
  if (request.has_slope_limit()) params.slope_limit = request.slope_limit();
  if (request.has_max_results()) params.max_results = request.max_results();
  if (request.has_characteristic_frame() && request.characteristic_frame() != -1) {
    const int frame = request.characteristic_frame();
    if (frame < query.range.first || frame > query.range.last) {
      return absl::InvalidArgumentError(
          absl::StrCat("characteristic_frame: ", frame, " is outside the query's frames ",
                       query.range.first, "..", query.range.last, " (or -1 for automatic)"));
    }
    params.characteristic_frame = static_cast<int>(
        std::clamp<int64_t>(query.frames.ToSpace(frame) - query.first_row, 0, query.row_count - 1));
  }
  MOTIONDB_ASSIGN_OR_RETURN(params.neutral, ToNeutralPose(request.neutral()));
  if (request.has_cluster_gap_s()) params.cluster_gap_s = request.cluster_gap_s();
  if (request.has_max_overlap()) params.max_overlap = request.max_overlap();
  params.return_path = request.return_path();
  if (request.has_refine()) params.refine = request.refine();
  params.clip_ids.assign(request.clip_ids().begin(), request.clip_ids().end());
  params.tags.assign(request.tags().begin(), request.tags().end());
  MOTIONDB_RETURN_IF_ERROR(ValidateSearchParams(params, dims));
  return params;
}

void FillResult(const SearchResult& result, const SpaceSnapshot& snapshot, v1::SearchResult* out) {
  const FrameConversion frames = snapshot.Conversion(result.clip_id);
  out->set_clip_id(result.clip_id);
  out->set_clip_name(result.clip_name);
  out->set_start_s(result.start_s);
  out->set_end_s(result.end_s);
  out->set_start_frame(frames.ToOriginal(result.first_frame));
  out->set_end_frame(frames.ToOriginal(result.last_frame));
  out->set_score(result.score);
  out->set_seed_frame(result.seed_frame >= 0 ? frames.ToOriginal(result.seed_frame) : -1);
  for (const int64_t frame : result.path) out->add_path(frames.ToOriginal(frame));
}

void FillStats(const SearchStats& stats, v1::SearchResponse* response) {
  v1::SearchTimings* timings = response->mutable_timings();
  timings->set_characteristic_ms(stats.characteristic_ms);
  timings->set_seeds_ms(stats.seeds_ms);
  timings->set_clusters_ms(stats.clusters_ms);
  timings->set_warps_ms(stats.warps_ms);
  timings->set_refine_ms(stats.refine_ms);
  timings->set_ranking_ms(stats.ranking_ms);
  timings->set_total_ms(stats.total_ms);
  v1::SearchCounts* counts = response->mutable_counts();
  counts->set_seeds(stats.seeds);
  counts->set_clusters(stats.clusters);
  counts->set_warps(stats.warps);
  counts->set_cells(stats.cells);
  counts->set_pruned_blocks(stats.pruned_blocks);
}

}  // namespace

absl::StatusOr<v1::SearchResponse> RunSearch(const v1::SearchRequest& request,
                                             const IndexRegistry& registry,
                                             storage::Database& database,
                                             const SearchLimits& limits,
                                             const std::function<bool()>& should_stop) {
  const auto start = std::chrono::steady_clock::now();
  // The snapshot is held to the end: the query's rows and the results point into it.
  MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> snapshot,
                            FindSpace(registry, request.space()));
  const int dims = snapshot->space->dims();
  Query query;
  switch (request.query_case()) {
    case v1::SearchRequest::kClip: {
      // CheckClipInSpace (in StoredQuery) also covers a space without clips, hence without an
      // index.
      MOTIONDB_ASSIGN_OR_RETURN(query, StoredQuery(request.clip(), *snapshot, database));
      break;
    }
    case v1::SearchRequest::kBvh: {
      MOTIONDB_ASSIGN_OR_RETURN(query, UploadedQuery(request.bvh(), *snapshot, limits));
      break;
    }
    default:
      return absl::InvalidArgumentError("query: give a stored clip (clip) or a BVH file (bvh)");
  }
  MOTIONDB_ASSIGN_OR_RETURN(SearchParams params, ToParams(request, query, dims));
  params.should_stop = should_stop;

  v1::SearchResponse response;
  response.set_characteristic_frame(-1);
  v1::SearchCounts* counts = response.mutable_counts();
  counts->set_query_frames(query.row_count);
  if (snapshot->index) {
    counts->set_library_frames(snapshot->index->total_frames());
    MOTIONDB_ASSIGN_OR_RETURN(const SearchResponse found,
                              request.exact() ? ExactSearch(*snapshot->index, query.rows(), params)
                                              : Search(*snapshot->index, query.rows(), params));
    for (const SearchResult& result : found.results) {
      FillResult(result, *snapshot, response.add_results());
    }
    FillStats(found.stats, &response);
    if (found.stats.characteristic_frame >= 0) {
      response.set_characteristic_frame(
          query.frames.ToOriginal(query.first_row + found.stats.characteristic_frame));
    }
  }
  response.mutable_timings()->set_request_ms(
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  return response;
}

}  // namespace motiondb::server
