// ClipService's messages and the application's clip types (server/clip_*.h, server/listing.h),
// both ways; a clip range's too, which every service that names frames of a clip reads.
// Requests: INVALID_ARGUMENT naming the field for what no struct can hold (an unknown enum
// value); defaults for unset fields are the application's. Joint names go out through ValidUtf8
// (util/name_text.h): an older version stored a BVH file's names unchecked, and one name that is
// not UTF-8 would fail every answer holding it.
#ifndef MOTIONDB_SERVER_GRPC_CLIP_CONVERSION_H_
#define MOTIONDB_SERVER_GRPC_CLIP_CONVERSION_H_

#include <vector>

#include "absl/status/statusor.h"
#include "motiondb/v1/clip_service.pb.h"
#include "server/clip_export.h"
#include "server/clip_ingest.h"
#include "server/clip_poses.h"
#include "server/listing.h"
#include "server/skeleton_map.h"
#include "storage/database.h"

namespace motiondb::server {

ClipSelection FromProto(const v1::ClipRange& range);
absl::StatusOr<IngestRequest> FromProto(const v1::IngestClipRequest& request);
// The first message of the stream (the one that carries the request's fields).
absl::StatusOr<IngestRequest> FromProto(const v1::IngestClipStreamRequest& first);
storage::ClipUpdate FromProto(const v1::UpdateClipRequest& request);
ClipListRequest FromProto(const v1::ListClipsRequest& request);
PosesRequest FromProto(const v1::GetClipPosesRequest& request);
// INVALID_ARGUMENT naming `set[i].slot` or `clear[i]` for a name that is not a slot's.
absl::StatusOr<storage::SlotOverrideChange> FromProto(const v1::MapSkeletonRequest& request);

void ToProto(const storage::ClipRecord& record, v1::Clip* clip);
// The record and the skeleton's joint names.
void ToProto(const storage::ClipLayout& layout, v1::Clip* clip);
void ToProto(const storage::ClipPage& page, v1::ListClipsResponse* response);
// Positions as little-endian float32, as the API promises.
void ToProto(const ClipPoses& poses, v1::ClipPoses* response);
void ToProto(const std::vector<storage::SkeletonSummary>& skeletons,
             v1::ListSkeletonsResponse* response);
void ToProto(const SkeletonMapView& view, v1::SkeletonDetail* detail);
void ToProto(const IngestedFile& file, v1::IngestClipResponse* response);
// The BVH text is moved into the message (1-2 MB for 10 s at 120 fps: a copy cost 0.8 ms).
void ToProto(ExportedFile&& exported, v1::ExportClipResponse* response);
// INVALID_ARGUMENT naming `format` for another than "bvh", "gltf", "glb" or empty.
absl::StatusOr<ExportFormat> ExportFormatFromProto(const std::string& format);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_CLIP_CONVERSION_H_
