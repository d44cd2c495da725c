// A space's build report (motiondb.v1.SpaceBuildReport): what the space is (dimensions, rate,
// heading, metric, joint weights, explained variance) and how it was built (training ranges,
// reconstruction error, timing). Stored as JSON in storage::SpaceRecord::build_report_json, in
// the protobuf JSON mapping with the .proto field names, so that GetSpace returns exactly what
// CreateSpace did. Also the API's view of a resident space (motiondb.v1.Space).
#ifndef MOTIONDB_SERVER_SPACE_REPORT_H_
#define MOTIONDB_SERVER_SPACE_REPORT_H_

#include <string>
#include <vector>

#include "core/space/motion_space.h"
#include "motiondb/v1/space_service.pb.h"
#include "server/index_registry.h"

namespace motiondb::server {

// The fields that follow from the space alone.
v1::SpaceBuildReport DescribeSpace(const MotionSpace& space);

void AddReconstructionErrors(const std::vector<ReconstructionError>& errors,
                             v1::SpaceBuildReport* report);

std::string ReportToJson(const v1::SpaceBuildReport& report);
// The stored report; DescribeSpace(space) when the JSON is missing or unreadable (a space stored
// by another tool), so that a report always has the space's own facts.
v1::SpaceBuildReport ReportFromJson(const std::string& json, const MotionSpace& space);

// The space's record, stored report and resident index.
void FillSpace(const SpaceSnapshot& snapshot, v1::Space* space);
void FillSpaceIndex(const SpaceSnapshot& snapshot, v1::SpaceIndex* index);

v1::SpaceMetric ToProto(SpaceMetric metric);
v1::WeightPreset ToProto(WeightPreset preset);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_SPACE_REPORT_H_
