#include "server/upload/streamed_upload.h"

#include <utility>

#include "server/upload/scene_import.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::server {

StreamedUpload::StreamedUpload(std::string name, const UploadLimits& limits)
    : name_(std::move(name)), limits_(limits), reader_(UploadReadOptions(limits)) {}

absl::Status StreamedUpload::Append(absl::string_view chunk, UploadBudget::Ticket& ticket) {
  // The file's own limit first: it is final, while the budget's refusal is worth a retry.
  MOTIONDB_RETURN_IF_ERROR(
      Prefixed(name_, CheckUploadSize(bytes_ + static_cast<int64_t>(chunk.size()), limits_)));
  MOTIONDB_RETURN_IF_ERROR(ticket.Reserve(static_cast<int64_t>(chunk.size())));
  bytes_ += static_cast<int64_t>(chunk.size());
  if (format_ == MotionFileFormat::kBvh) return Prefixed(name_, reader_.Append(chunk));
  held_.append(chunk.data(), chunk.size());
  if (!format_ && held_.size() >= kMotionFileHeadBytes) return Settle(UploadFormat(held_));
  return absl::OkStatus();
}

absl::Status StreamedUpload::Settle(MotionFileFormat format) {
  format_ = format;
  if (format != MotionFileFormat::kBvh) return absl::OkStatus();
  const std::string head = std::exchange(held_, std::string());
  return Prefixed(name_, reader_.Append(head));
}

absl::StatusOr<UploadedFile> StreamedUpload::Finish(const std::function<bool()>& should_stop) {
  if (!format_) MOTIONDB_RETURN_IF_ERROR(Settle(UploadFormat(held_)));
  if (format_ != MotionFileFormat::kBvh) {
    return Prefixed(name_, ImportScene(held_, *format_, limits_, should_stop));
  }
  MOTIONDB_ASSIGN_OR_RETURN(BvhReadResult read, Prefixed(name_, reader_.Finish()));
  return FromBvh(std::move(read));
}

}  // namespace motiondb::server
