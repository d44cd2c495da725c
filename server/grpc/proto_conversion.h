// Every conversion between motiondb.v1 messages and the application layer's types, in one
// place: requests to the application's request structs (INVALID_ARGUMENT naming the field for
// values no struct can hold, such as unknown enum values), and results to response messages.
// Defaults for unset fields are the application's, not decided here. Joint names go out through
// ValidUtf8 (util/name_text.h): an older version stored a BVH file's names unchecked, and one
// name that is not UTF-8 would fail every answer holding it.
#ifndef MOTIONDB_SERVER_GRPC_PROTO_CONVERSION_H_
#define MOTIONDB_SERVER_GRPC_PROTO_CONVERSION_H_

#include "absl/status/statusor.h"
#include "motiondb/v1/clip_service.pb.h"
#include "motiondb/v1/edit_service.pb.h"
#include "motiondb/v1/job_service.pb.h"
#include "motiondb/v1/label_service.pb.h"
#include "motiondb/v1/search_service.pb.h"
#include "motiondb/v1/server_service.pb.h"
#include "motiondb/v1/space_service.pb.h"
#include "server/clip_export.h"
#include "server/clip_ingest.h"
#include "server/clip_poses.h"
#include "server/edit_blends.h"
#include "server/edit_curves.h"
#include "server/edit_reconstruct.h"
#include "server/edit_transitions.h"
#include "server/frame_conversion.h"
#include "server/index_registry.h"
#include "server/label_catalog.h"
#include "server/listing.h"
#include "server/pose_models.h"
#include "server/propagation.h"
#include "server/search_runner.h"
#include "server/space_builder.h"
#include "server/space_curve.h"
#include "server/space_report.h"
#include "storage/database.h"

namespace motiondb::server {

// Requests.
ClipSelection FromProto(const v1::ClipRange& range);
absl::StatusOr<IngestRequest> FromProto(const v1::IngestClipRequest& request);
// The first message of the stream (the one that carries the request's fields).
absl::StatusOr<IngestRequest> FromProto(const v1::IngestClipStreamRequest& first);
storage::ClipUpdate FromProto(const v1::UpdateClipRequest& request);
absl::StatusOr<SearchRequest> FromProto(const v1::SearchRequest& request);
absl::StatusOr<SpaceRequest> FromProto(const v1::CreateSpaceRequest& request);
CurveRequest FromProto(const v1::GetCurveRequest& request);
ClipListRequest FromProto(const v1::ListClipsRequest& request);
PosesRequest FromProto(const v1::GetClipPosesRequest& request);
std::vector<NewLabel> FromProto(const v1::AddLabelsRequest& request);
absl::StatusOr<storage::LabelFilter> FromProto(const v1::ListLabelsRequest& request);
absl::StatusOr<LabelDeletion> FromProto(const v1::DeleteLabelsRequest& request);
storage::LabelQuery FromProto(const v1::FindLabelsRequest& request);
// INVALID_ARGUMENT naming search.FIELD for a search field the job sets itself.
absl::StatusOr<PropagationRequest> FromProto(const v1::StartPropagationRequest& request);

// Results.
void ToProto(const storage::ClipRecord& record, v1::Clip* clip);
void ToProto(const storage::ClipPage& page, v1::ListClipsResponse* response);
// Positions as little-endian float32, as the API promises.
void ToProto(const ClipPoses& poses, v1::ClipPoses* response);
void ToProto(const storage::SkeletonSummary& summary, v1::Skeleton* skeleton);
void ToProto(const storage::Counts& counts, v1::DatabaseCounts* out);
void ToProto(const IngestOutcome& outcome, v1::IngestClipResponse* response);
// The BVH text is moved into the message (1-2 MB for 10 s at 120 fps: a copy cost 0.8 ms).
void ToProto(ExportedBvh&& exported, v1::ExportClipResponse* response);
void ToProto(const SearchExplanation& explanation, v1::SearchExplanation* out);
void ToProto(const SearchOutcome& outcome, v1::SearchResponse* response);
void ToProto(const SpaceReport& report, v1::SpaceBuildReport* out);
// The space's record, stored report and resident index.
void ToProto(const SpaceSnapshot& snapshot, v1::Space* space);
void ToProto(const SpaceSnapshot& snapshot, v1::SpaceIndex* index);
// Coordinates as little-endian float32, as the API promises.
void ToProto(const Curve& curve, v1::GetCurveResponse* response);
// The range also in seconds (frame x the clip's frame time).
void ToProto(const storage::LabelRecord& record, v1::Label* label);
void ToProto(const storage::LabelPage& page, v1::ListLabelsResponse* response);
void ToProto(const storage::LabelPage& page, v1::FindLabelsResponse* response);
void ToProto(const ClipTimeline& timeline, v1::GetClipLabelsResponse* response);
// The space and descriptors read from the job's parameters.
void ToProto(const storage::JobRecord& record, v1::Job* job);
void ToProto(const storage::JobPage& page, v1::ListJobsResponse* response);

// EditService (issue 16). Each request's parameters (without its output) are kept as proto3
// JSON in EditOutput::parameters_json, for the provenance of a stored result.
absl::StatusOr<ReconstructRequest> FromProto(const v1::ReconstructRequest& request);
absl::StatusOr<InterpolateRequest> FromProto(const v1::InterpolateRequest& request);
absl::StatusOr<BlendRequest> FromProto(const v1::BlendRequest& request);
absl::StatusOr<FillGapRequest> FromProto(const v1::FillGapRequest& request);
absl::StatusOr<ScaleRequest> FromProto(const v1::ScaleRequest& request);
// INVALID_ARGUMENT naming target unless exactly one of target and the axis is given.
absl::StatusOr<TranslateRequest> FromProto(const v1::TranslateRequest& request);
absl::StatusOr<SmoothRequest> FromProto(const v1::SmoothRequest& request);
absl::StatusOr<PoseModelRequest> FromProto(const v1::CreatePoseModelRequest& request);
absl::StatusOr<DetectRequest> FromProto(const v1::DetectPoseRequest& request);
// The results' BVH text is moved, as ExportedBvh's.
void ToProto(EditResult&& result, v1::EditResult* out);
void ToProto(EditResult&& result, v1::EditResponse* response);
void ToProto(ReconstructOutcome&& outcome, v1::ReconstructResponse* response);
void ToProto(InterpolateOutcome&& outcome, v1::InterpolateResponse* response);
void ToProto(BlendOutcome&& outcome, v1::BlendResponse* response);
void ToProto(FillGapOutcome&& outcome, v1::FillGapResponse* response);
void ToProto(const StoredPoseModel& stored, v1::PoseModel* model);
// The log-likelihood as little-endian float32.
void ToProto(const DetectOutcome& outcome, v1::DetectPoseResponse* response);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_PROTO_CONVERSION_H_
