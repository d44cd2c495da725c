#ifndef MOTIONDB_SERVER_UPLOAD_STREAMED_UPLOAD_H_
#define MOTIONDB_SERVER_UPLOAD_STREAMED_UPLOAD_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/bvh/bvh_reader.h"
#include "server/upload/upload.h"
#include "server/upload/upload_budget.h"

namespace motiondb::server {

// A file that arrives in chunks (IngestClipStream). A BVH is parsed as it arrives
// (BvhStreamReader), so that the server holds the clip being built rather than the text; an FBX
// or glTF file, told apart by its first bytes, is held whole, as its reader needs it, and read
// when it ends. Errors, the size check's too, begin with `name`, as ReadUpload's do. Not
// thread-safe.
class StreamedUpload {
 public:
  StreamedUpload(std::string name, const UploadLimits& limits);

  // Checks the size so far against the limit, reserves `chunk` in the upload's budget, then
  // parses what `chunk` completes.
  absl::Status Append(absl::string_view chunk, UploadBudget::Ticket& ticket);
  // The file has ended: the parsed file. Call once. `should_stop` as ReadUpload takes it.
  absl::StatusOr<UploadedFile> Finish(const std::function<bool()>& should_stop = {});

 private:
  // Once the first bytes tell the format: a BVH's go to the reader, another's are kept.
  absl::Status Settle(MotionFileFormat format);

  std::string name_;
  UploadLimits limits_;
  int64_t bytes_ = 0;
  std::optional<MotionFileFormat> format_;  // unknown while fewer bytes than its head arrived
  std::string held_;  // the head until the format is known; then an FBX or glTF file whole
  BvhStreamReader reader_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_UPLOAD_STREAMED_UPLOAD_H_
