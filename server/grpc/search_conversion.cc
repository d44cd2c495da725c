#include "server/grpc/search_conversion.h"

#include "server/grpc/clip_conversion.h"
#include "server/grpc/internal/field_conversion.h"
#include "util/name_text.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

absl::StatusOr<NeutralPose> FromProto(v1::NeutralPose neutral) {
  switch (neutral) {
    case v1::NEUTRAL_POSE_UNSPECIFIED:
    case v1::NEUTRAL_POSE_QUERY_MEAN:
      return NeutralPose::kQueryMean;
    case v1::NEUTRAL_POSE_BOUNDARY_MEAN:
      return NeutralPose::kBoundaryMean;
    case v1::NEUTRAL_POSE_ORIGIN:
      return NeutralPose::kOrigin;
    default:
      return UnknownValue("neutral", neutral);
  }
}

absl::StatusOr<SeedSelection> FromProto(v1::SeedSelection selection) {
  switch (selection) {
    case v1::SEED_SELECTION_UNSPECIFIED:
    case v1::SEED_SELECTION_NEAREST_FRAMES:
      return SeedSelection::kNearestFrames;
    case v1::SEED_SELECTION_DISTINCT_PLACES:
      return SeedSelection::kDistinctPlaces;
    case v1::SEED_SELECTION_NEAREST_WINDOWS:
      return SeedSelection::kNearestWindows;
    case v1::SEED_SELECTION_SHAPE_WINDOWS:
      return SeedSelection::kShapeWindows;
    default:
      return UnknownValue("seed_selection", selection);
  }
}

// Only what the request sets replaces SearchParams' defaults.
absl::StatusOr<SearchParams> ParamsFromProto(const v1::SearchRequest& request) {
  SearchParams params;
  MOTIONDB_ASSIGN_OR_RETURN(params.seed_selection, FromProto(request.seed_selection()));
  if (request.has_places()) params.places = request.places();
  if (request.has_neighbours()) params.neighbours = request.neighbours();
  if (request.has_shape_windows()) params.shape_windows = request.shape_windows();
  if (request.has_shape_clips()) params.shape_clips = request.shape_clips();
  if (request.has_shape_lengths_either_side()) {
    params.shape_lengths_either_side = request.shape_lengths_either_side();
  }
  if (request.has_exact_threads()) params.exact_threads = request.exact_threads();
  if (request.has_epsilon()) params.epsilon = request.epsilon();
  if (request.has_slope_limit()) params.slope_limit = request.slope_limit();
  if (request.has_max_results()) params.max_results = request.max_results();
  MOTIONDB_ASSIGN_OR_RETURN(params.neutral, FromProto(request.neutral()));
  if (request.has_cluster_gap_s()) params.cluster_gap_s = request.cluster_gap_s();
  if (request.has_max_overlap()) params.max_overlap = request.max_overlap();
  params.return_path = request.return_path();
  if (request.has_refine()) params.refine = request.refine();
  if (request.has_characteristic_points()) {
    params.characteristic_points = request.characteristic_points();
  }
  if (request.has_max_point_gap_s()) params.max_point_gap_s = request.max_point_gap_s();
  if (request.has_second_anchor_scatter()) {
    params.second_anchor_scatter = request.second_anchor_scatter();
  }
  params.clip_ids.assign(request.clip_ids().begin(), request.clip_ids().end());
  params.tags.assign(request.tags().begin(), request.tags().end());
  return params;
}

}  // namespace

absl::StatusOr<SearchRequest> FromProto(const v1::SearchRequest& request) {
  SearchRequest out;
  out.space = request.space();
  switch (request.query_case()) {
    case v1::SearchRequest::kClip:
      out.query = FromProto(request.clip());
      break;
    case v1::SearchRequest::kBvh: {
      const v1::BvhQuery& bvh = request.bvh();
      out.query = UploadedQuery{bvh.bvh(), Optional(bvh.has_first_frame(), bvh.first_frame()),
                                Optional(bvh.has_last_frame(), bvh.last_frame())};
      break;
    }
    default:
      break;  // the runner names the missing query
  }
  MOTIONDB_ASSIGN_OR_RETURN(out.params, ParamsFromProto(request));
  out.ann_dims = Optional(request.has_ann_dims(), request.ann_dims());
  out.dtw_dims = Optional(request.has_dtw_dims(), request.dtw_dims());
  // -1 asks for the automatic choice, as unset does.
  if (request.has_characteristic_frame() && request.characteristic_frame() != -1) {
    out.characteristic_frame = request.characteristic_frame();
  }
  out.characteristic_frames.assign(request.characteristic_frames().begin(),
                                   request.characteristic_frames().end());
  // 0 asks for the automatic choice, as unset does.
  if (request.has_threads() && request.threads() != 0) out.threads = request.threads();
  out.exact = request.exact();
  out.exclude_query = Optional(request.has_exclude_query(), request.exclude_query());
  out.explain = request.explain();
  out.mirror = request.mirror();
  return out;
}

void ToProto(const SearchExplanation& explanation, v1::SearchExplanation* out) {
  for (const JointShare& joint : explanation.joints) {
    v1::JointShare* share = out->add_joints();
    share->set_name(ValidUtf8(joint.name));
    share->set_share(joint.share);
    share->set_score(joint.score);
  }
  out->set_full_score(explanation.full_score);
  out->set_mean_speed(explanation.mean_speed);
  out->set_max_speed(explanation.max_speed);
}

void ToProto(const SearchOutcome& outcome, v1::SearchResponse* response) {
  for (const SearchHit& hit : outcome.hits) {
    v1::SearchResult* out = response->add_results();
    out->set_clip_id(hit.clip_id);
    out->set_clip_name(hit.clip_name);
    out->set_start_s(hit.start_s);
    out->set_end_s(hit.end_s);
    out->set_start_frame(hit.start_frame);
    out->set_end_frame(hit.end_frame);
    out->set_score(hit.score);
    out->set_seed_frame(hit.seed_frame);
    out->set_mirrored(hit.mirrored);
    for (const int frame : hit.path) out->add_path(frame);
    if (hit.explanation) ToProto(*hit.explanation, out->mutable_explanation());
  }
  response->set_characteristic_frame(outcome.characteristic_frame);
  for (const int frame : outcome.characteristic_frames) response->add_characteristic_frames(frame);
  response->set_second_anchor_frame(outcome.second_anchor_frame);
  const SearchStats& stats = outcome.stats;
  v1::SearchTimings* timings = response->mutable_timings();
  timings->set_characteristic_ms(stats.characteristic_ms);
  timings->set_seeds_ms(stats.seeds_ms);
  timings->set_clusters_ms(stats.clusters_ms);
  timings->set_warps_ms(stats.warps_ms);
  timings->set_refine_ms(stats.refine_ms);
  timings->set_ranking_ms(stats.ranking_ms);
  timings->set_total_ms(stats.total_ms);
  timings->set_request_ms(outcome.request_ms);
  v1::SearchCounts* counts = response->mutable_counts();
  counts->set_query_frames(outcome.query_frames);
  counts->set_library_frames(outcome.library_frames);
  counts->set_seeds(stats.seeds);
  counts->set_clusters(stats.clusters);
  counts->set_warps(stats.warps);
  counts->set_cells(stats.cells);
  counts->set_pruned_blocks(stats.pruned_blocks);
  counts->set_threads(stats.threads);
}

}  // namespace motiondb::server
