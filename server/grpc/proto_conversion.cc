#include "server/grpc/proto_conversion.h"

#include <utility>

#include <google/protobuf/util/json_util.h>

#include "absl/strings/str_cat.h"
#include "core/space/joint_weights.h"
#include "server/listing.h"
#include "util/byte_coding.h"
#include "util/name_text.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

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
      return absl::InvalidArgumentError(absl::StrCat("neutral: unknown value ", neutral));
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
    default:
      return absl::InvalidArgumentError(absl::StrCat("seed_selection: unknown value ", selection));
  }
}

absl::StatusOr<WeightPreset> FromProto(v1::WeightPreset preset) {
  switch (preset) {
    case v1::WEIGHT_PRESET_UNSPECIFIED:
    case v1::WEIGHT_PRESET_MASS:
      return WeightPreset::kMass;
    case v1::WEIGHT_PRESET_UNIFORM:
      return WeightPreset::kUniform;
    default:
      return absl::InvalidArgumentError(absl::StrCat("weight_preset: unknown value ", preset));
  }
}

absl::StatusOr<SpaceMetric> FromProto(v1::SpaceMetric metric) {
  switch (metric) {
    case v1::SPACE_METRIC_UNSPECIFIED:
    case v1::SPACE_METRIC_UNIT:
      return SpaceMetric::kUnit;
    case v1::SPACE_METRIC_EIGENVALUE_SCALED:
      return SpaceMetric::kEigenvalueScaled;
    default:
      return absl::InvalidArgumentError(absl::StrCat("metric: unknown value ", metric));
  }
}

v1::SpaceMetric ToProto(SpaceMetric metric) {
  return metric == SpaceMetric::kUnit ? v1::SPACE_METRIC_UNIT : v1::SPACE_METRIC_EIGENVALUE_SCALED;
}

v1::WeightPreset ToProto(WeightPreset preset) {
  return preset == WeightPreset::kMass ? v1::WEIGHT_PRESET_MASS : v1::WEIGHT_PRESET_UNIFORM;
}

absl::StatusOr<OnConflict> FromProto(v1::OnConflict on_conflict) {
  switch (on_conflict) {
    case v1::ON_CONFLICT_UNSPECIFIED:
      return OnConflict::kSkipIdentical;
    case v1::ON_CONFLICT_ERROR:
      return OnConflict::kError;
    case v1::ON_CONFLICT_SKIP:
      return OnConflict::kSkip;
    case v1::ON_CONFLICT_REPLACE:
      return OnConflict::kReplace;
    default:
      return absl::InvalidArgumentError(absl::StrCat("on_conflict: unknown value ", on_conflict));
  }
}

v1::IngestResult ToProto(IngestResult result) {
  switch (result) {
    case IngestResult::kStored:
      return v1::INGEST_RESULT_STORED;
    case IngestResult::kSkipped:
      return v1::INGEST_RESULT_SKIPPED;
    case IngestResult::kReplaced:
      return v1::INGEST_RESULT_REPLACED;
  }
  return v1::INGEST_RESULT_UNSPECIFIED;
}

// A filter's origin: unspecified is any.
absl::StatusOr<std::optional<storage::LabelOrigin>> FromProto(v1::LabelOrigin origin) {
  switch (origin) {
    case v1::LABEL_ORIGIN_UNSPECIFIED:
      return std::nullopt;
    case v1::LABEL_ORIGIN_MANUAL:
      return storage::LabelOrigin::kManual;
    case v1::LABEL_ORIGIN_PROPAGATED:
      return storage::LabelOrigin::kPropagated;
    default:
      return absl::InvalidArgumentError(absl::StrCat("origin: unknown value ", origin));
  }
}

// ListLabelsResponse and FindLabelsResponse: a page of labels.
template <typename Response>
void PageToProto(const storage::LabelPage& page, Response* response) {
  // Qualified: this namespace's own ToProto overloads would hide the public ones.
  for (const storage::LabelRecord& record : page.labels) {
    server::ToProto(record, response->add_labels());
  }
  response->set_next_page_token(page.next_page_token);
}

// IngestClipRequest and the first IngestClipStreamRequest carry the same fields.
template <typename Message>
absl::StatusOr<IngestRequest> IngestRequestOf(const Message& message) {
  IngestRequest request;
  request.file_name = message.file_name();
  request.name = message.name();
  request.tags.assign(message.tags().begin(), message.tags().end());
  MOTIONDB_ASSIGN_OR_RETURN(request.on_conflict, FromProto(message.on_conflict()));
  return request;
}

template <typename T>
std::optional<T> Optional(bool has, T value) {
  return has ? std::optional<T>(value) : std::nullopt;
}

// Only what the request sets replaces SearchParams' defaults.
absl::StatusOr<SearchParams> ParamsFromProto(const v1::SearchRequest& request) {
  SearchParams params;
  MOTIONDB_ASSIGN_OR_RETURN(params.seed_selection, FromProto(request.seed_selection()));
  if (request.has_places()) params.places = request.places();
  if (request.has_neighbours()) params.neighbours = request.neighbours();
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

ClipSelection FromProto(const v1::ClipRange& range) {
  return {range.clip_id(), Optional(range.has_first_frame(), range.first_frame()),
          Optional(range.has_last_frame(), range.last_frame())};
}

absl::StatusOr<IngestRequest> FromProto(const v1::IngestClipRequest& request) {
  return IngestRequestOf(request);
}

absl::StatusOr<IngestRequest> FromProto(const v1::IngestClipStreamRequest& first) {
  return IngestRequestOf(first);
}

storage::ClipUpdate FromProto(const v1::UpdateClipRequest& request) {
  storage::ClipUpdate update;
  if (request.has_name()) update.name = request.name();
  update.add_tags.assign(request.add_tags().begin(), request.add_tags().end());
  update.remove_tags.assign(request.remove_tags().begin(), request.remove_tags().end());
  return update;
}

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
  out.exact = request.exact();
  out.exclude_query = Optional(request.has_exclude_query(), request.exclude_query());
  out.explain = request.explain();
  return out;
}

absl::StatusOr<PropagationRequest> FromProto(const v1::StartPropagationRequest& request) {
  const v1::SearchRequest& search = request.search();
  // The fields a job sets per query, or that it does not do (the application refuses the
  // others: server/propagation.cc).
  const std::pair<bool, const char*> refused[] = {
      {!search.space().empty(), "search.space: give the space as space"},
      {search.query_case() != v1::SearchRequest::QUERY_NOT_SET,
       "search.query: the job's queries are its manual labels"},
      {search.tags_size() > 0, "search.tags: give the tags as tags"},
      {search.explain(), "search.explain: a propagation keeps no explanations"},
      {search.has_exclude_query(), "search.exclude_query: a query's own range is always excluded"},
      {search.has_characteristic_frame(), "search.characteristic_frame: each query finds its own"},
      {search.characteristic_frames_size() > 0,
       "search.characteristic_frames: each query finds its own"}};
  for (const auto& [set, message] : refused) {
    if (set) return absl::InvalidArgumentError(message);
  }
  PropagationRequest out;
  out.space = request.space();
  out.descriptors.assign(request.descriptor_names().begin(), request.descriptor_names().end());
  MOTIONDB_ASSIGN_OR_RETURN(out.search, Prefixed("search", FromProto(search)));
  out.search.params.tags.assign(request.tags().begin(), request.tags().end());
  if (!search.has_max_results()) out.search.params.max_results = kPropagationMaxResults;
  return out;
}

absl::StatusOr<SpaceRequest> FromProto(const v1::CreateSpaceRequest& request) {
  SpaceRequest out;
  out.name = request.name();
  if (request.has_skeleton_id()) out.skeleton_id = request.skeleton_id();
  for (const v1::ClipRange& range : request.training()) out.training.push_back(FromProto(range));
  SpaceOptions& options = out.options;
  if (request.has_sample_rate()) options.sample_rate = request.sample_rate();
  MOTIONDB_ASSIGN_OR_RETURN(options.weights.preset, FromProto(request.weight_preset()));
  if (!request.weight_overrides().empty() && !request.weights_json().empty()) {
    return absl::InvalidArgumentError("give weight_overrides or weights_json, not both");
  }
  for (const auto& [joint, weight] : request.weight_overrides()) {
    options.weights.overrides[joint] = weight;
  }
  if (!request.weights_json().empty()) {
    absl::StatusOr<std::map<std::string, double>> overrides =
        Prefixed("weights_json", ParseWeightOverrides(request.weights_json()));
    if (!overrides.ok()) return absl::InvalidArgumentError(overrides.status().message());
    options.weights.overrides = *std::move(overrides);
  }
  options.pose.remove_heading = !request.keep_heading();
  if (request.has_yaw_rate_weight()) options.yaw_rate_weight = request.yaw_rate_weight();
  if (request.has_root_velocity_weight()) {
    options.pose.root_velocity = request.root_velocity_weight() != 0;
    if (options.pose.root_velocity) options.root_velocity_weight = request.root_velocity_weight();
  }
  MOTIONDB_ASSIGN_OR_RETURN(options.metric, FromProto(request.metric()));
  if (request.has_learned_metric()) {
    LearnedMetricOptions& learned = out.learned_metric.emplace();
    if (request.learned_metric().has_shrink()) learned.shrink = request.learned_metric().shrink();
    // "learned_metric.shrink: ...", the field's path, as the CLI names its flag by it.
    if (const absl::Status valid = ValidateLearnedMetricOptions(learned); !valid.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("learned_metric.", valid.message()));
    }
  }
  return out;
}

CurveRequest FromProto(const v1::GetCurveRequest& request) {
  return {request.space(), FromProto(request.clip()), Optional(request.has_dims(), request.dims())};
}

ClipListRequest FromProto(const v1::ListClipsRequest& request) {
  return {.page = {request.page_size(), request.page_token()},
          .tag = request.tag(),
          .name_contains = request.name_contains(),
          .sort = request.sort(),
          .skeleton_id = request.skeleton_id(),
          .descriptor = request.descriptor_name()};
}

PosesRequest FromProto(const v1::GetClipPosesRequest& request) {
  return {FromProto(request.clip()), Optional(request.has_max_rate(), request.max_rate())};
}

std::vector<NewLabel> FromProto(const v1::AddLabelsRequest& request) {
  std::vector<NewLabel> labels;
  labels.reserve(request.labels_size());
  for (const v1::NewLabel& label : request.labels()) {
    labels.push_back({.clip_id = label.clip_id(),
                      .clip_name = label.clip_name(),
                      .first_frame = Optional(label.has_first_frame(), label.first_frame()),
                      .last_frame = Optional(label.has_last_frame(), label.last_frame()),
                      .start_s = Optional(label.has_start_s(), label.start_s()),
                      .end_s = Optional(label.has_end_s(), label.end_s()),
                      .descriptor = label.descriptor_name(),
                      .value = Optional(label.has_value(), label.value())});
  }
  return labels;
}

absl::StatusOr<storage::LabelFilter> FromProto(const v1::ListLabelsRequest& request) {
  storage::LabelFilter filter{.clip_id = request.clip_id(),
                              .descriptor = request.descriptor_name()};
  MOTIONDB_ASSIGN_OR_RETURN(filter.origin, FromProto(request.origin()));
  filter.min_value = Optional(request.has_min_value(), request.min_value());
  return filter;
}

absl::StatusOr<LabelDeletion> FromProto(const v1::DeleteLabelsRequest& request) {
  LabelDeletion deletion;
  deletion.label_ids.assign(request.label_ids().begin(), request.label_ids().end());
  deletion.filter.clip_id = request.clip_id();
  deletion.filter.descriptor = request.descriptor_name();
  MOTIONDB_ASSIGN_OR_RETURN(deletion.filter.origin, FromProto(request.origin()));
  return deletion;
}

storage::LabelQuery FromProto(const v1::FindLabelsRequest& request) {
  return {request.descriptor_name(), request.min_value(),
          std::vector<std::string>(request.tags().begin(), request.tags().end())};
}

void ToProto(const storage::ClipRecord& record, v1::Clip* clip) {
  const double fps = record.frame_time > 0 ? 1.0 / record.frame_time : 0.0;
  clip->set_clip_id(record.clip_id);
  clip->set_name(record.name);
  clip->set_source_file(record.source_file);
  for (const std::string& tag : record.tags) clip->add_tags(tag);
  clip->set_skeleton_id(record.skeleton_id);
  clip->set_created_unix_ms(record.created_unix_ms);
  clip->set_frame_count(static_cast<int32_t>(record.frame_count));
  clip->set_fps(fps);
  clip->set_duration_s(fps > 0 ? record.frame_count / fps : 0.0);
  clip->set_joint_count(record.joint_count);
  clip->set_content_hash(record.content_hash);
  if (const std::optional<Provenance> provenance = ParseProvenance(record.provenance)) {
    v1::Provenance* out = clip->mutable_provenance();
    out->set_operator_(provenance->op);
    out->set_space(provenance->space);
    for (const SourceRange& source : provenance->sources) {
      v1::ClipRange* range = out->add_sources();
      range->set_clip_id(source.clip_id);
      range->set_first_frame(source.frames.first);
      range->set_last_frame(source.frames.last);
    }
    out->set_parameters_json(provenance->parameters_json);
  }
}

void ToProto(const storage::SkeletonSummary& summary, v1::Skeleton* skeleton) {
  skeleton->set_skeleton_id(summary.skeleton_id);
  skeleton->set_name(ValidUtf8(SkeletonName(summary)));
  skeleton->set_joint_count(summary.joint_count);
  skeleton->set_clip_count(summary.clip_count);
  skeleton->set_root_joint(ValidUtf8(summary.root_joint));
}

void ToProto(const storage::Counts& counts, v1::DatabaseCounts* out) {
  out->set_skeletons(counts.skeletons);
  out->set_clips(counts.clips);
  out->set_frames(counts.frames);
  out->set_spaces(counts.spaces);
  out->set_projections(counts.projections);
  out->set_labels(counts.labels);
}

void ToProto(const IngestOutcome& outcome, v1::IngestClipResponse* response) {
  ToProto(outcome.clip, response->mutable_clip());
  for (const std::string& warning : outcome.warnings) response->add_warnings(warning);
  for (const std::string& space : outcome.spaces) response->add_projected_spaces(space);
  response->set_result(ToProto(outcome.result));
  response->set_replaced_clip_id(outcome.replaced_clip_id);
  for (const storage::ClipRecord& duplicate : outcome.duplicates) {
    v1::ClipRef* same = response->add_duplicate_of();
    same->set_clip_id(duplicate.clip_id);
    same->set_name(duplicate.name);
  }
}

void ToProto(ExportedBvh&& exported, v1::ExportClipResponse* response) {
  response->set_bvh(std::move(exported.bvh));
  response->set_file_name(exported.file_name);
  response->set_first_frame(exported.frames.first);
  response->set_last_frame(exported.frames.last);
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
}

void ToProto(const SpaceReport& report, v1::SpaceBuildReport* out) {
  out->set_dims(report.dims);
  out->set_joint_count(report.joint_count);
  out->set_pelvis(report.pelvis);
  out->set_sample_rate(report.sample_rate);
  out->set_heading_removed(report.heading_removed);
  out->set_yaw_rate_weight(report.yaw_rate_weight);
  out->set_root_velocity_weight(report.root_velocity_weight);
  out->set_metric(ToProto(report.metric));
  out->set_weight_preset(ToProto(report.weight_preset));
  for (const JointWeightReport& weight : report.joint_weights) {
    v1::JointWeight* joint = out->add_joint_weights();
    joint->set_joint(ValidUtf8(weight.joint));
    joint->set_weight(weight.weight);
  }
  for (const TrainingReport& range : report.training) {
    v1::ClipRange* used = out->add_training();
    used->set_clip_id(range.clip_id);
    used->set_first_frame(range.frames.first);
    used->set_last_frame(range.frames.last);
  }
  out->set_training_frames(report.training_frames);
  for (const double value : report.explained_variance) out->add_explained_variance(value);
  for (const ReconstructionError& error : report.reconstruction_error) {
    v1::ReconstructionError* measured = out->add_reconstruction_error();
    measured->set_dims(error.dims);
    measured->set_mean_rad(error.mean_rad);
    measured->set_max_rad(error.max_rad);
  }
  out->set_projected_clips(report.projected_clips);
  if (report.learned_metric_examples > 0) {
    v1::LearnedMetricReport* learned = out->mutable_learned_metric();
    learned->set_shrink(report.learned_metric_shrink);
    learned->set_examples(report.learned_metric_examples);
    learned->set_descriptors(report.learned_metric_descriptors);
  }
  out->set_build_ms(report.build_ms);
}

void ToProto(const SpaceSnapshot& snapshot, v1::SpaceIndex* index) {
  index->set_dims(snapshot.space->dims());
  if (!snapshot.index) return;
  index->set_clips(snapshot.index->clip_count());
  index->set_frames(snapshot.index->total_frames());
  index->set_ann_dims(snapshot.index->ann_dims());
  index->set_coordinate_bytes(snapshot.coordinate_bytes());
  index->set_tree_bytes(snapshot.tree_bytes());
}

void ToProto(const SpaceSnapshot& snapshot, v1::Space* space) {
  const storage::SpaceRecord& record = snapshot.record;
  space->set_space_id(record.space_id);
  space->set_name(record.name);
  space->set_skeleton_id(record.skeleton_id);
  space->set_version(record.version);
  space->set_created_unix_ms(record.created_unix_ms);
  ToProto(ReportFromJson(record.build_report_json, *snapshot.space), space->mutable_report());
  ToProto(snapshot, space->mutable_index());
}

void ToProto(const Curve& curve, v1::GetCurveResponse* response) {
  response->set_dims(static_cast<int32_t>(curve.coordinates.cols()));
  response->set_frames(static_cast<int32_t>(curve.coordinates.rows()));
  response->set_sample_rate(curve.sample_rate);
  AppendFloat32s(curve.coordinates.data(), curve.coordinates.size(),
                 response->mutable_coordinates());
  response->set_first_frame(curve.frames.first);
  response->set_last_frame(curve.frames.last);
}

void ToProto(const storage::ClipPage& page, v1::ListClipsResponse* response) {
  for (const storage::ClipRecord& record : page.clips) ToProto(record, response->add_clips());
  response->set_next_page_token(page.next_page_token);
  response->set_total_size(page.total_size);
}

void ToProto(const ClipPoses& poses, v1::ClipPoses* response) {
  response->set_clip_id(poses.clip_id);
  for (const std::string& name : poses.joint_names) response->add_joint_names(ValidUtf8(name));
  for (const int parent : poses.parents) response->add_parents(parent);
  response->set_sample_rate(poses.sample_rate);
  response->set_frames(static_cast<int32_t>(poses.positions.rows()));
  response->set_first_frame(poses.frames.first);
  response->set_last_frame(poses.frames.last);
  AppendFloat32s(poses.positions.data(), poses.positions.size(), response->mutable_positions());
}

void ToProto(const storage::LabelRecord& record, v1::Label* label) {
  label->set_label_id(record.label_id);
  label->set_clip_id(record.clip_id);
  label->set_clip_name(record.clip_name);
  label->set_first_frame(static_cast<int32_t>(record.first_frame));
  label->set_last_frame(static_cast<int32_t>(record.last_frame));
  label->set_start_s(record.first_frame * record.frame_time);
  label->set_end_s(record.last_frame * record.frame_time);
  label->set_descriptor_name(record.descriptor);
  label->set_value(record.value);
  label->set_origin(record.origin == storage::LabelOrigin::kManual ? v1::LABEL_ORIGIN_MANUAL
                                                                   : v1::LABEL_ORIGIN_PROPAGATED);
  label->set_source_label_id(record.source_label_id);
  label->set_space(record.space_name);
  label->set_score(record.score);
  label->set_job_id(record.job_id);
  label->set_created_unix_ms(record.created_unix_ms);
}

void ToProto(const storage::LabelPage& page, v1::ListLabelsResponse* response) {
  PageToProto(page, response);
}

void ToProto(const storage::LabelPage& page, v1::FindLabelsResponse* response) {
  PageToProto(page, response);
}

void ToProto(const ClipTimeline& timeline, v1::GetClipLabelsResponse* response) {
  const storage::ClipRecord& clip = timeline.clip;
  response->set_clip_id(clip.clip_id);
  response->set_clip_name(clip.name);
  response->set_frame_count(static_cast<int32_t>(clip.frame_count));
  response->set_fps(clip.frame_time > 0 ? 1.0 / clip.frame_time : 0.0);
  for (const storage::LabelRecord& record : timeline.labels) {
    ToProto(record, response->add_labels());
  }
  response->set_next_page_token(timeline.next_page_token);
}

namespace {

v1::JobState ToProto(storage::JobState state) {
  switch (state) {
    case storage::JobState::kQueued:
      return v1::JOB_STATE_QUEUED;
    case storage::JobState::kRunning:
      return v1::JOB_STATE_RUNNING;
    case storage::JobState::kSucceeded:
      return v1::JOB_STATE_SUCCEEDED;
    case storage::JobState::kFailed:
      return v1::JOB_STATE_FAILED;
    case storage::JobState::kCancelled:
      return v1::JOB_STATE_CANCELLED;
    case storage::JobState::kInterrupted:
      return v1::JOB_STATE_INTERRUPTED;
  }
  return v1::JOB_STATE_UNSPECIFIED;
}

}  // namespace

void ToProto(const storage::JobRecord& record, v1::Job* job) {
  const PropagationTarget target = TargetOf(record);
  job->set_job_id(record.job_id);
  job->set_kind(record.kind);
  job->set_state(ToProto(record.state));
  job->set_space(target.space);
  for (const std::string& descriptor : target.descriptors) job->add_descriptor_names(descriptor);
  job->set_parameters(record.parameters_json);
  job->set_done(record.done);
  job->set_total(record.total);
  job->set_queries(record.queries);
  job->set_queries_skipped(record.queries_skipped);
  job->set_labels_written(record.labels_written);
  job->set_error(record.error);
  job->set_created_unix_ms(record.created_unix_ms);
  job->set_started_unix_ms(record.started_unix_ms);
  job->set_finished_unix_ms(record.finished_unix_ms);
}

void ToProto(const storage::JobPage& page, v1::ListJobsResponse* response) {
  for (const storage::JobRecord& record : page.jobs) ToProto(record, response->add_jobs());
  response->set_next_page_token(page.next_page_token);
}

// EditService.
namespace {

std::string JsonOf(const google::protobuf::Message& message) {
  std::string json;
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  if (!google::protobuf::util::MessageToJsonString(message, &json, options).ok()) return "{}";
  return json;
}

// The request as proto3 JSON without its `output`: what made a stored result.
template <typename Request>
std::string ParametersJson(const Request& request) {
  Request parameters = request;
  parameters.clear_output();
  return JsonOf(parameters);
}

// The parameters only for a result that is stored: a request's JSON is a copy of it (a blend's
// path of a million points takes seconds), made for nothing when the result is only answered.
template <typename Request>
EditOutput OutputOf(const Request& request) {
  const v1::EditOutput& output = request.output();
  return {output.store_name(),
          std::vector<std::string>(output.store_tags().begin(), output.store_tags().end()),
          output.store_name().empty() ? std::string() : ParametersJson(request)};
}

EditScope FromProto(const v1::EditScope& scope) {
  EditScope out;
  if (scope.has_gate()) {
    const v1::Gate& gate = scope.gate();
    out.gate = Gate{gate.start_s(), gate.end_s(), gate.lead_in_s(), gate.lead_out_s()};
  }
  out.dims.assign(scope.dims().begin(), scope.dims().end());
  return out;
}

JointConstraints FromProto(const v1::JointConstraints& constraints) {
  JointConstraints out;
  out.edit_weights.insert(constraints.edit_weights().begin(), constraints.edit_weights().end());
  out.max_angles.insert(constraints.max_angles().begin(), constraints.max_angles().end());
  out.source_margin = Optional(constraints.has_source_margin(), constraints.source_margin());
  return out;
}

template <typename Request>
CurveEdit CurveEditOf(const Request& request) {
  // Qualified: this namespace's own FromProto overloads would hide the public ones.
  return {request.space(), server::FromProto(request.clip()), FromProto(request.scope()),
          FromProto(request.constraints()), OutputOf(request)};
}

absl::StatusOr<CovarianceType> FromProto(v1::CovarianceType type) {
  switch (type) {
    case v1::COVARIANCE_TYPE_UNSPECIFIED:
    case v1::COVARIANCE_TYPE_FULL:
      return CovarianceType::kFull;
    case v1::COVARIANCE_TYPE_DIAGONAL:
      return CovarianceType::kDiagonal;
    case v1::COVARIANCE_TYPE_SPHERICAL:
      return CovarianceType::kSpherical;
    default:
      return absl::InvalidArgumentError(absl::StrCat("covariance: unknown value ", type));
  }
}

v1::CovarianceType ToProto(CovarianceType type) {
  switch (type) {
    case CovarianceType::kFull:
      return v1::COVARIANCE_TYPE_FULL;
    case CovarianceType::kDiagonal:
      return v1::COVARIANCE_TYPE_DIAGONAL;
    case CovarianceType::kSpherical:
      return v1::COVARIANCE_TYPE_SPHERICAL;
  }
  return v1::COVARIANCE_TYPE_UNSPECIFIED;
}

}  // namespace

absl::StatusOr<ReconstructRequest> FromProto(const v1::ReconstructRequest& request) {
  ReconstructRequest out{request.space(), FromProto(request.clip())};
  if (request.has_dims()) out.options.dims = request.dims();
  out.options.error_curve = request.error_curve();
  out.output = OutputOf(request);
  return out;
}

absl::StatusOr<InterpolateRequest> FromProto(const v1::InterpolateRequest& request) {
  InterpolateRequest out{request.space(), FromProto(request.from()), FromProto(request.to())};
  out.options.t.assign(request.t().begin(), request.t().end());
  if (request.has_steps()) out.options.steps = request.steps();
  if (request.has_dims()) out.options.dims = request.dims();
  switch (request.method()) {
    case v1::INTERPOLATION_METHOD_UNSPECIFIED:
    case v1::INTERPOLATION_METHOD_MC_LERP:
      out.method = InterpolationMethod::kMcLerp;
      break;
    case v1::INTERPOLATION_METHOD_SLERP:
      out.method = InterpolationMethod::kSlerp;
      break;
    default:
      return absl::InvalidArgumentError(absl::StrCat("method: unknown value ", request.method()));
  }
  out.output = OutputOf(request);
  return out;
}

absl::StatusOr<BlendRequest> FromProto(const v1::BlendRequest& request) {
  BlendRequest out{request.space()};
  for (const v1::PlanarPose& pose : request.poses()) {
    out.poses.push_back({FromProto(pose.pose()), pose.x(), pose.y()});
  }
  for (const v1::PlanePoint& point : request.path()) out.path.emplace_back(point.x(), point.y());
  if (request.has_frames_per_segment()) out.frames_per_segment = request.frames_per_segment();
  if (request.has_epsilon()) out.options.epsilon = request.epsilon();
  out.output = OutputOf(request);
  return out;
}

absl::StatusOr<FillGapRequest> FromProto(const v1::FillGapRequest& request) {
  FillGapRequest out{request.space(), FromProto(request.first()), FromProto(request.second())};
  if (request.has_gap_s()) out.gap_s = request.gap_s();
  switch (request.method()) {
    case v1::GAP_METHOD_UNSPECIFIED:
    case v1::GAP_METHOD_HERMITE:
      out.gap.method = GapMethod::kHermite;
      break;
    case v1::GAP_METHOD_LINEAR:
      out.gap.method = GapMethod::kLinear;
      break;
    default:
      return absl::InvalidArgumentError(absl::StrCat("method: unknown value ", request.method()));
  }
  if (request.has_damping()) out.gap.damping = request.damping();
  out.gap.derivative_smoothing = request.derivative_smoothing();
  out.overlap_s = request.overlap_s();
  out.blend.align = !request.no_align();
  if (request.has_slope_limit()) out.blend.warp.slope_limit = request.slope_limit();
  if (request.has_warp_dims()) out.blend.warp.dims = request.warp_dims();
  out.output = OutputOf(request);
  return out;
}

absl::StatusOr<ScaleRequest> FromProto(const v1::ScaleRequest& request) {
  ScaleRequest out{CurveEditOf(request)};
  if (request.has_factor()) out.options.factor = request.factor();
  switch (request.centre()) {
    case v1::SCALE_CENTRE_UNSPECIFIED:
    case v1::SCALE_CENTRE_ORIGIN:
      out.options.centre = ScaleCentre::kOrigin;
      break;
    case v1::SCALE_CENTRE_SELECTION_MEAN:
      out.options.centre = ScaleCentre::kSelectionMean;
      break;
    default:
      return absl::InvalidArgumentError(absl::StrCat("centre: unknown value ", request.centre()));
  }
  if (request.has_sigmoid()) {
    out.options.sigmoid = Sigmoid{request.sigmoid().threshold(), request.sigmoid().width()};
  }
  return out;
}

absl::StatusOr<TranslateRequest> FromProto(const v1::TranslateRequest& request) {
  TranslateRequest out{CurveEditOf(request)};
  const bool axis = request.has_axis_from() || request.has_axis_to();
  if (request.has_target() == axis ||
      (axis && !(request.has_axis_from() && request.has_axis_to()))) {
    return absl::InvalidArgumentError(
        "target: give a target pose, or axis_from and axis_to, not both");
  }
  if (request.has_target()) {
    out.options.mode = TranslateMode::kTowardPose;
    out.poses = {FromProto(request.target())};
  } else {
    out.options.mode = TranslateMode::kAlongAxis;
    out.poses = {FromProto(request.axis_from()), FromProto(request.axis_to())};
  }
  if (request.has_amount()) out.options.amount = request.amount();
  return out;
}

absl::StatusOr<SmoothRequest> FromProto(const v1::SmoothRequest& request) {
  SmoothRequest out{CurveEditOf(request)};
  if (request.has_level()) out.options.level = request.level();
  return out;
}

absl::StatusOr<PoseModelRequest> FromProto(const v1::CreatePoseModelRequest& request) {
  PoseModelRequest out{request.name(), request.space()};
  for (const v1::ClipRange& range : request.examples()) out.examples.push_back(FromProto(range));
  PoseModelOptions& options = out.options;
  if (request.has_components()) options.components = request.components();
  MOTIONDB_ASSIGN_OR_RETURN(options.covariance, FromProto(request.covariance()));
  if (request.has_dims()) options.dims = request.dims();
  if (request.has_seed()) options.seed = request.seed();
  if (request.has_threshold_quantile()) options.threshold_quantile = request.threshold_quantile();
  if (request.has_max_iterations()) options.max_iterations = request.max_iterations();
  out.parameters_json = JsonOf(request);
  return out;
}

absl::StatusOr<DetectRequest> FromProto(const v1::DetectPoseRequest& request) {
  return DetectRequest{request.model(), FromProto(request.clip()),
                       Optional(request.has_threshold(), request.threshold()),
                       request.min_duration_s()};
}

void ToProto(EditResult&& result, v1::EditResult* out) {
  out->set_bvh(std::move(result.bvh));
  out->set_file_name(result.file_name);
  out->set_frames(result.frames);
  out->set_fps(result.fps);
  if (result.stored) ToProto(*result.stored, out->mutable_stored());
}

void ToProto(EditResult&& result, v1::EditResponse* response) {
  ToProto(std::move(result), response->mutable_result());
}

void ToProto(ReconstructOutcome&& outcome, v1::ReconstructResponse* response) {
  ToProto(std::move(outcome.result), response->mutable_result());
  response->set_dims(outcome.dims);
  for (const JointReconstructionError& joint : outcome.joints) {
    v1::JointError* out = response->add_joints();
    out->set_joint(ValidUtf8(joint.joint));
    out->set_mean_rad(joint.error.mean_rad);
    out->set_max_rad(joint.error.max_rad);
  }
  response->set_mean_rad(outcome.overall.mean_rad);
  response->set_max_rad(outcome.overall.max_rad);
  for (const ReconstructionError& level : outcome.curve) {
    v1::ReconstructionError* out = response->add_curve();
    out->set_dims(level.dims);
    out->set_mean_rad(level.mean_rad);
    out->set_max_rad(level.max_rad);
  }
}

void ToProto(InterpolateOutcome&& outcome, v1::InterpolateResponse* response) {
  ToProto(std::move(outcome.result), response->mutable_result());
  response->set_other_bvh(std::move(outcome.other_bvh));
  const Interpolation& comparison = outcome.comparison;
  for (size_t i = 0; i < comparison.t.size(); ++i) {
    v1::InterpolationStep* step = response->add_steps();
    step->set_t(comparison.t[i]);
    step->set_mean_rad(comparison.difference[i].mean_rad);
    step->set_max_rad(comparison.difference[i].max_rad);
    step->set_curve_distance(comparison.curve_distance[i]);
  }
  response->set_mean_rad(comparison.overall.mean_rad);
  response->set_max_rad(comparison.overall.max_rad);
}

void ToProto(BlendOutcome&& outcome, v1::BlendResponse* response) {
  ToProto(std::move(outcome.result), response->mutable_result());
  for (Eigen::Index k = 0; k < outcome.weights.rows(); ++k) {
    v1::BlendWeights* frame = response->add_frames();
    for (Eigen::Index i = 0; i < outcome.weights.cols(); ++i) {
      frame->add_weights(outcome.weights(k, i));
    }
  }
}

void ToProto(FillGapOutcome&& outcome, v1::FillGapResponse* response) {
  ToProto(std::move(outcome.result), response->mutable_result());
  response->set_transition_frames(outcome.transition_frames);
  for (const SeamJump& seam : outcome.seams) {
    v1::SeamJump* out = response->add_seams();
    out->set_mean_rad_s(seam.chosen.mean_rad);
    out->set_max_rad_s(seam.chosen.max_rad);
    out->set_linear_mean_rad_s(seam.linear.mean_rad);
    out->set_linear_max_rad_s(seam.linear.max_rad);
  }
  response->set_warp_score(outcome.warp_score);
}

void ToProto(const StoredPoseModel& stored, v1::PoseModel* model) {
  model->set_name(stored.record.name);
  model->set_space(stored.record.space_name);
  model->set_dims(stored.model.dims);
  model->set_components(static_cast<int32_t>(stored.model.weights.size()));
  model->set_covariance(ToProto(stored.model.covariance));
  model->set_threshold(stored.model.threshold);
  model->set_log_likelihood(stored.model.log_likelihood);
  model->set_iterations(stored.model.iterations);
  for (const double weight : stored.model.weights) model->add_weights(weight);
  model->set_created_unix_ms(stored.record.created_unix_ms);
  model->set_parameters_json(stored.record.parameters_json);
}

void ToProto(const DetectOutcome& outcome, v1::DetectPoseResponse* response) {
  response->set_space(outcome.space);
  response->set_first_frame(outcome.frames.first);
  response->set_last_frame(outcome.frames.last);
  response->set_sample_rate(outcome.sample_rate);
  const Eigen::VectorXf values = outcome.log_likelihood.cast<float>();
  AppendFloat32s(values.data(), values.size(), response->mutable_log_likelihood());
  response->set_threshold(outcome.threshold);
  for (const DetectedRange& range : outcome.intervals) {
    v1::DetectedInterval* out = response->add_intervals();
    out->set_first_frame(range.first_frame);
    out->set_last_frame(range.last_frame);
    out->set_start_s(range.start_s);
    out->set_end_s(range.end_s);
    out->set_peak_frame(range.peak_frame);
    out->set_peak(range.peak);
  }
}

}  // namespace motiondb::server
