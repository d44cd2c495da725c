#include "server/upload/upload.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "server/upload/scene_import.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::server {
namespace {

// Bytes of BVH text parsed between two polls of a stop function: about a millisecond's parsing
// (bench/notes/2026-11-22-bvh-parse.md: bvh_parse_bench).
constexpr size_t kUploadBytesPerStopPoll = size_t{256} << 10;

absl::StatusOr<BvhReadResult> ReadBvhUpload(absl::string_view bvh, absl::string_view name,
                                            const UploadLimits& limits,
                                            const std::function<bool()>& should_stop) {
  if (!should_stop) return Prefixed(name, ReadBvh(bvh, UploadReadOptions(limits)));
  // Parsed a piece at a time, as a stream's chunks are (the same clip, the same errors), so that
  // the stop function is asked about every millisecond of parsing.
  BvhStreamReader reader(UploadReadOptions(limits));
  for (size_t at = 0; at < bvh.size(); at += kUploadBytesPerStopPoll) {
    if (should_stop()) {
      return absl::CancelledError(absl::StrCat(name, ": parsing was stopped by its caller"));
    }
    MOTIONDB_RETURN_IF_ERROR(
        Prefixed(name, reader.Append(bvh.substr(at, kUploadBytesPerStopPoll))));
  }
  return Prefixed(name, reader.Finish());
}

}  // namespace

absl::Status CheckUploadSize(int64_t bytes, const UploadLimits& limits) {
  if (bytes <= limits.max_bvh_bytes) return absl::OkStatus();
  return absl::ResourceExhaustedError(absl::StrCat("the file is ", bytes,
                                                   " bytes or more; this server accepts at most ",
                                                   limits.max_bvh_bytes, " (--max-bvh-mb)"));
}

MotionFileFormat UploadFormat(absl::string_view head) {
  return DetectMotionFileFormat(head.substr(0, kMotionFileHeadBytes))
      .value_or(MotionFileFormat::kBvh);
}

BvhReadOptions UploadReadOptions(const UploadLimits& limits) {
  BvhReadOptions options;
  options.max_bytes = limits.max_bvh_bytes;
  // No one upload's clip may take more than all of them may hold: a small file of many joints
  // and rows would otherwise make a clip of gigabytes.
  options.max_clip_bytes = limits.max_buffered_bytes;
  return options;
}

UploadedFile FromBvh(BvhReadResult read) {
  UploadedFile file;
  file.takes.push_back({"", std::move(read.clip)});
  file.warnings = std::move(read.warnings);
  return file;
}

absl::StatusOr<UploadedFile> ReadUpload(absl::string_view bytes, absl::string_view name,
                                        const UploadLimits& limits,
                                        const std::function<bool()>& should_stop) {
  MOTIONDB_RETURN_IF_ERROR(
      Prefixed(name, CheckUploadSize(static_cast<int64_t>(bytes.size()), limits)));
  if (const MotionFileFormat format = UploadFormat(bytes); format != MotionFileFormat::kBvh) {
    return Prefixed(name, ImportScene(bytes, format, limits, should_stop));
  }
  MOTIONDB_ASSIGN_OR_RETURN(BvhReadResult read, ReadBvhUpload(bytes, name, limits, should_stop));
  return FromBvh(std::move(read));
}

}  // namespace motiondb::server
