#include "server/grpc/server_info_conversion.h"

namespace motiondb::server {

void ToProto(const storage::Counts& counts, v1::DatabaseCounts* out) {
  out->set_skeletons(counts.skeletons);
  out->set_clips(counts.clips);
  out->set_frames(counts.frames);
  out->set_spaces(counts.spaces);
  out->set_projections(counts.projections);
  out->set_labels(counts.labels);
}

}  // namespace motiondb::server
