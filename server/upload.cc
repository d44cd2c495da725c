#include "server/upload.h"

#include <utility>

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

namespace {

BvhReadOptions ReadOptions(const UploadLimits& limits) {
  BvhReadOptions options;
  options.max_bytes = limits.max_bvh_bytes;
  return options;
}

}  // namespace

absl::StatusOr<BvhReadResult> ReadUpload(absl::string_view bvh, absl::string_view name,
                                         const UploadLimits& limits) {
  MOTIONDB_RETURN_IF_ERROR(
      Prefixed(name, CheckUploadSize(static_cast<int64_t>(bvh.size()), limits)));
  return Prefixed(name, ReadBvh(bvh, ReadOptions(limits)));
}

StreamedUpload::StreamedUpload(std::string name, const UploadLimits& limits)
    : name_(std::move(name)), limits_(limits), reader_(ReadOptions(limits)) {}

absl::Status StreamedUpload::Append(absl::string_view chunk) {
  bytes_ += static_cast<int64_t>(chunk.size());
  MOTIONDB_RETURN_IF_ERROR(Prefixed(name_, CheckUploadSize(bytes_, limits_)));
  return Prefixed(name_, reader_.Append(chunk));
}

absl::StatusOr<BvhReadResult> StreamedUpload::Finish() { return Prefixed(name_, reader_.Finish()); }

}  // namespace motiondb::server
