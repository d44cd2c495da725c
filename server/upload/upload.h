// A motion file sent by a client, to ingest or to search with: its size checked against the
// server's limit, parsed, and its errors prefixed with what the client called it, so that every
// upload fails the same way ("walk.bvh: line 19: expected ..."). A BVH is parsed here; an FBX or
// glTF file in a child process (scene_import.h).
#ifndef MOTIONDB_SERVER_UPLOAD_UPLOAD_H_
#define MOTIONDB_SERVER_UPLOAD_UPLOAD_H_

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/bvh/bvh_reader.h"
#include "core/scene/scene_format.h"

namespace motiondb::server {

struct UploadLimits {
  // Largest file (BVH, FBX or glTF), in bytes, whether sent whole or streamed (--max-bvh-mb):
  // larger ones fail with RESOURCE_EXHAUSTED before they are parsed.
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
  // The program that reads FBX and glTF uploads (--scene-importer); empty:
  // motiondb-scene-import beside the running program, else the one this build made.
  std::string scene_importer;
  // What its process may take, address space included (--max-import-mb): a file that needs
  // more is refused with RESOURCE_EXHAUSTED, and the server's memory is not touched.
  int64_t max_import_bytes = int64_t{4} << 30;
  // How long it may read one file before it is stopped (DEADLINE_EXCEEDED).
  std::chrono::milliseconds max_import_time{300'000};
};

// One take of an uploaded file: a BVH holds one, an FBX or glTF file one an animation.
struct UploadedTake {
  std::string name;  // the animation's name; empty for a BVH
  Clip clip;
};

struct UploadedFile {
  MotionFileFormat format = MotionFileFormat::kBvh;
  std::vector<UploadedTake> takes;  // at least one
  // The reader's non-fatal findings (a BVH's `Frames:` header that disagrees with its rows, an
  // FBX's animated scale that was left out).
  std::vector<std::string> warnings;
  // What an FBX or glTF file says of itself; a BVH says neither.
  double unit_m = 0;      // metres per unit of its positions; 0: not said
  char up_axis = 0;       // 'X', 'Y' or 'Z' (its clips are turned Y up); 0: not said
  std::string generator;  // the tool that wrote it
};

// RESOURCE_EXHAUSTED when `bytes` (an upload's size, or a stream's so far) exceeds the limit;
// streams call it as chunks arrive, so an oversize upload is refused before it is all buffered.
absl::Status CheckUploadSize(int64_t bytes, const UploadLimits& limits);

// The format of a file that begins with `head`: BVH unless its first bytes say otherwise.
MotionFileFormat UploadFormat(absl::string_view head);

// The parsed file, of the format its first bytes tell (a file of none is read as BVH, whose
// errors then say what is wrong); errors (the size check's too) begin with `name`.
// `should_stop` is asked between pieces of the text (a gigabyte takes seconds to parse) and
// while the importer runs: CANCELLED once it says stop.
absl::StatusOr<UploadedFile> ReadUpload(absl::string_view bytes, absl::string_view name,
                                        const UploadLimits& limits,
                                        const std::function<bool()>& should_stop = {});

// A BVH's parse as an UploadedFile of one take.
UploadedFile FromBvh(BvhReadResult read);

// How the server reads an upload: its size limit, and its clip at most the budget of all.
BvhReadOptions UploadReadOptions(const UploadLimits& limits);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_UPLOAD_UPLOAD_H_
