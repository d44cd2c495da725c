#include "server/upload/upload_budget.h"

#include <utility>

#include "absl/strings/str_cat.h"

namespace motiondb::server {

UploadBudget::Ticket::Ticket(Ticket&& other) noexcept
    : budget_(std::exchange(other.budget_, nullptr)),
      reserved_(std::exchange(other.reserved_, 0)) {}

UploadBudget::Ticket::~Ticket() {
  if (budget_ == nullptr) return;
  std::lock_guard<std::mutex> lock(budget_->mutex_);
  --budget_->uploads_;
  budget_->buffered_bytes_ -= reserved_;
}

absl::Status UploadBudget::Ticket::Reserve(int64_t bytes) {
  std::lock_guard<std::mutex> lock(budget_->mutex_);
  const int64_t max = budget_->limits_.max_buffered_bytes;
  if (budget_->buffered_bytes_ + bytes > max) {
    return absl::ResourceExhaustedError(
        absl::StrCat("the uploads in progress hold ", budget_->buffered_bytes_,
                     " bytes; this server buffers at most ", max,
                     " across them (--max-upload-buffer-mb); retry when they are done"));
  }
  budget_->buffered_bytes_ += bytes;
  reserved_ += bytes;
  return absl::OkStatus();
}

absl::StatusOr<UploadBudget::Ticket> UploadBudget::Admit() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (uploads_ >= limits_.max_uploads) {
    return absl::ResourceExhaustedError(
        absl::StrCat(uploads_,
                     " uploads are in progress, the most this server takes at once "
                     "(--max-uploads); retry when one is done"));
  }
  ++uploads_;
  return Ticket(this);
}

int UploadBudget::uploads() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return uploads_;
}

int64_t UploadBudget::buffered_bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return buffered_bytes_;
}

}  // namespace motiondb::server
