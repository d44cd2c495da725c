// A BVH file sent by a client, to ingest or to search with: its size checked against the
// server's limit, parsed, and its errors prefixed with what the client called it, so that every
// upload fails the same way ("walk.bvh: line 19: expected ...").
#ifndef MOTIONDB_SERVER_UPLOAD_UPLOAD_H_
#define MOTIONDB_SERVER_UPLOAD_UPLOAD_H_

#include <chrono>
#include <cstdint>
#include <functional>

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
  // Bytes of text the ingests in progress may hold together (--max-upload-buffer-mb); a message
  // or chunk beyond fails its upload with RESOURCE_EXHAUSTED. An upload peaks at 1.9-4.2x its
  // text (the parsed clip and its stored copy;
  // bench/notes/2026-12-03-upload-memory.md), and no one upload's clip may
  // take more than this either, so this is what bounds the server's memory under many uploads.
  int64_t max_buffered_bytes = int64_t{2} << 30;
  // An upload arriving slower than this on average, once `rate_grace` has passed, is ended
  // (--min-upload-kbps): 32 streams sending a byte every 20 s once kept every ingest out.
  double min_bytes_per_s = 64 << 10;
  std::chrono::milliseconds rate_grace{10'000};
};

// RESOURCE_EXHAUSTED when `bytes` (an upload's size, or a stream's so far) exceeds the limit;
// streams call it as chunks arrive, so an oversize upload is refused before it is all buffered.
absl::Status CheckUploadSize(int64_t bytes, const UploadLimits& limits);

// The parsed file; errors (the size check's too) begin with `name`. `should_stop` is asked
// between pieces of the text (a gigabyte takes seconds to parse): CANCELLED once it says stop.
absl::StatusOr<BvhReadResult> ReadUpload(absl::string_view bvh, absl::string_view name,
                                         const UploadLimits& limits,
                                         const std::function<bool()>& should_stop = {});

// How the server reads an upload: its size limit, and its clip at most the budget of all.
BvhReadOptions UploadReadOptions(const UploadLimits& limits);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_UPLOAD_UPLOAD_H_
