// SpaceService's messages and the application's space types (server/space_*.h, the registry's
// snapshots), both ways. INVALID_ARGUMENT names the field for what no struct can hold (an
// unknown enum value, weights given twice); defaults for unset fields are the application's.
#ifndef MOTIONDB_SERVER_GRPC_SPACE_CONVERSION_H_
#define MOTIONDB_SERVER_GRPC_SPACE_CONVERSION_H_

#include "absl/status/statusor.h"
#include "motiondb/v1/space_service.pb.h"
#include "server/index_registry.h"
#include "server/listing.h"
#include "server/space_builder.h"
#include "server/space_curve.h"
#include "server/space_report.h"

namespace motiondb::server {

absl::StatusOr<SpaceRequest> FromProto(const v1::CreateSpaceRequest& request);
CurveRequest FromProto(const v1::GetCurveRequest& request);

void ToProto(const SpaceReport& report, v1::SpaceBuildReport* out);
// The space's record, stored report and resident index.
void ToProto(const SpaceSnapshot& snapshot, v1::Space* space);
void ToProto(const SpaceSnapshot& snapshot, v1::SpaceIndex* index);
void ToProto(const SpacePage& page, v1::ListSpacesResponse* response);
// Coordinates as little-endian float32, as the API promises.
void ToProto(const Curve& curve, v1::GetCurveResponse* response);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_SPACE_CONVERSION_H_
