#include "server/upload.h"

#include "absl/strings/str_cat.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::server {

absl::Status CheckUploadSize(int64_t bytes, const UploadLimits& limits) {
  if (bytes <= limits.max_bvh_bytes) return absl::OkStatus();
  return absl::ResourceExhaustedError(absl::StrCat("the BVH file is ", bytes,
                                                   " bytes or more; this server accepts at most ",
                                                   limits.max_bvh_bytes, " (--max-bvh-mb)"));
}

absl::StatusOr<BvhReadResult> ReadUpload(absl::string_view bvh, absl::string_view name,
                                         const UploadLimits& limits) {
  MOTIONDB_RETURN_IF_ERROR(
      Prefixed(name, CheckUploadSize(static_cast<int64_t>(bvh.size()), limits)));
  BvhReadOptions options;
  options.max_bytes = limits.max_bvh_bytes;
  return Prefixed(name, ReadBvh(bvh, options));
}

}  // namespace motiondb::server
