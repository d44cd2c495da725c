#ifndef MOTIONDB_SERVER_UPLOAD_STREAMED_UPLOAD_H_
#define MOTIONDB_SERVER_UPLOAD_STREAMED_UPLOAD_H_

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/bvh/bvh_reader.h"
#include "server/upload/upload.h"
#include "server/upload/upload_budget.h"

namespace motiondb::server {

// A file that arrives in chunks (IngestClipStream), parsed as they arrive (BvhStreamReader) so
// that the server holds the clip being built rather than the text. Errors, the size check's
// too, begin with `name`, as ReadUpload's do. Not thread-safe.
class StreamedUpload {
 public:
  StreamedUpload(std::string name, const UploadLimits& limits);

  // Checks the size so far against the limit, reserves `chunk` in the upload's budget, then
  // parses what `chunk` completes.
  absl::Status Append(absl::string_view chunk, UploadBudget::Ticket& ticket);
  // The file has ended: the parsed clip. Call once.
  absl::StatusOr<BvhReadResult> Finish();

 private:
  std::string name_;
  UploadLimits limits_;
  BvhStreamReader reader_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_UPLOAD_STREAMED_UPLOAD_H_
