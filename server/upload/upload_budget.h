// What the uploads in progress hold together: how many there are, and the bytes they have
// buffered, against UploadLimits' max_uploads and max_buffered_bytes. Each file is bounded by
// max_bvh_bytes on its own; this bounds a dozen of them at once, which would otherwise take the
// machine's memory.
//
// Thread-safe.
#ifndef MOTIONDB_SERVER_UPLOAD_UPLOAD_BUDGET_H_
#define MOTIONDB_SERVER_UPLOAD_UPLOAD_BUDGET_H_

#include <cstdint>
#include <mutex>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "server/upload/upload.h"

namespace motiondb::server {

class UploadBudget {
 public:
  explicit UploadBudget(const UploadLimits& limits) : limits_(limits) {}

  // One upload's share of the budget, given back when it is destroyed.
  class Ticket {
   public:
    Ticket(Ticket&& other) noexcept;
    Ticket& operator=(Ticket&&) = delete;
    ~Ticket();

    // Counts `bytes` more of this upload; RESOURCE_EXHAUSTED naming the limit when the uploads
    // in progress would hold more than max_buffered_bytes together (nothing counted then).
    absl::Status Reserve(int64_t bytes);

   private:
    friend class UploadBudget;
    explicit Ticket(UploadBudget* budget) : budget_(budget) {}

    UploadBudget* budget_;  // null once moved from
    int64_t reserved_ = 0;
  };

  // RESOURCE_EXHAUSTED naming the limit when max_uploads uploads are in progress.
  absl::StatusOr<Ticket> Admit();

  int uploads() const;
  int64_t buffered_bytes() const;

 private:
  const UploadLimits limits_;
  mutable std::mutex mutex_;
  int uploads_ = 0;             // guarded by mutex_
  int64_t buffered_bytes_ = 0;  // guarded by mutex_
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_UPLOAD_UPLOAD_BUDGET_H_
