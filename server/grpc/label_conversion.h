// LabelService's messages and the labels' types (server/label_catalog.h, storage's records),
// both ways; a label's range also in seconds (frame x the clip's frame time).
#ifndef MOTIONDB_SERVER_GRPC_LABEL_CONVERSION_H_
#define MOTIONDB_SERVER_GRPC_LABEL_CONVERSION_H_

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "motiondb/v1/label_service.pb.h"
#include "server/label_catalog.h"
#include "storage/database.h"

namespace motiondb::server {

std::vector<NewLabel> FromProto(const v1::AddLabelsRequest& request);
absl::StatusOr<storage::LabelFilter> FromProto(const v1::ListLabelsRequest& request);
absl::StatusOr<LabelDeletion> FromProto(const v1::DeleteLabelsRequest& request);
storage::LabelQuery FromProto(const v1::FindLabelsRequest& request);

void ToProto(const storage::LabelRecord& record, v1::Label* label);
void ToProto(const storage::AddedLabels& added, v1::AddLabelsResponse* response);
void ToProto(int64_t deleted, v1::DeleteLabelsResponse* response);
void ToProto(const storage::LabelPage& page, v1::ListLabelsResponse* response);
void ToProto(const storage::LabelPage& page, v1::FindLabelsResponse* response);
void ToProto(const ClipTimeline& timeline, v1::GetClipLabelsResponse* response);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_LABEL_CONVERSION_H_
