// A BVH file sent by a client, to ingest or to search with: its size checked against the
// server's limit, parsed, and its errors prefixed with what the client called it, so that every
// upload fails the same way ("walk.bvh: line 19: expected ...").
#ifndef MOTIONDB_SERVER_UPLOAD_H_
#define MOTIONDB_SERVER_UPLOAD_H_

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/bvh/bvh_reader.h"

namespace motiondb::server {

struct UploadLimits {
  // Largest BVH file, in bytes, whether sent whole or streamed (--max-bvh-mb): larger ones fail
  // with RESOURCE_EXHAUSTED before they are parsed.
  int64_t max_bvh_bytes = int64_t{1} << 30;
  // Ingests (unary or streamed) in progress at once (--max-uploads); one more is refused with
  // RESOURCE_EXHAUSTED before it is read.
  int max_uploads = 32;
  // Bytes the ingests in progress may hold together (--max-upload-buffer-mb); a message or
  // chunk beyond fails its upload with RESOURCE_EXHAUSTED. A streamed upload holds its clip
  // parsed as it arrives (about its size, measured in bench/RESULTS.md), a unary one its text
  // and then the clip, so this is what bounds the server's memory under many large uploads.
  int64_t max_buffered_bytes = int64_t{2} << 30;
};

// RESOURCE_EXHAUSTED when `bytes` (an upload's size, or a stream's so far) exceeds the limit;
// streams call it as chunks arrive, so an oversize upload is refused before it is all buffered.
absl::Status CheckUploadSize(int64_t bytes, const UploadLimits& limits);

// The parsed file; errors (the size check's too) begin with `name`.
absl::StatusOr<BvhReadResult> ReadUpload(absl::string_view bvh, absl::string_view name,
                                         const UploadLimits& limits);

// A file that arrives in chunks (IngestClipStream), parsed as they arrive (BvhStreamReader) so
// that the server holds the clip being built rather than the text. Errors, the size check's
// too, begin with `name`, as ReadUpload's do. Not thread-safe.
class StreamedUpload {
 public:
  StreamedUpload(std::string name, const UploadLimits& limits);

  // Checks the size so far against the limit, then parses what `chunk` completes.
  absl::Status Append(absl::string_view chunk);
  // The file has ended: the parsed clip. Call once.
  absl::StatusOr<BvhReadResult> Finish();

 private:
  std::string name_;
  UploadLimits limits_;
  int64_t bytes_ = 0;
  BvhStreamReader reader_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_UPLOAD_H_
