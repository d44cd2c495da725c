// Reads BVH motion capture files into a Clip, tolerating the dialects real exporters write
// (any rotation order per joint, 3 or 6 channels on any joint, leaves without End Site, CRLF,
// tabs, E-notation, colons and spaces in joint names) and rejecting malformed input with the
// line number and what was expected; a joint name must be printable UTF-8 (util/name_text.h:
// a Latin-1 file is refused, to be converted first).
#ifndef MOTIONDB_CORE_BVH_BVH_READER_H_
#define MOTIONDB_CORE_BVH_BVH_READER_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/motion/clip.h"

namespace motiondb {

struct BvhReadOptions {
  // Inputs larger than this are refused before parsing.
  int64_t max_bytes = int64_t{1} << 30;
  // Frame counts above this (in the header or in the rows) are refused: 10M is 23 h at 120 fps.
  int64_t max_frames = 10'000'000;
  // Hierarchies with more joints than this are refused.
  int max_joints = 1000;
  // Rotation values beyond +-this many degrees are refused with their line: capture stays
  // within a few turns, and an angle such as 1e308 keeps none of its digits through the sine
  // and cosine (it would be stored, and exported, as some other angle).
  double max_abs_rotation_degrees = 1e5;
  // The header (HIERARCHY to the frame time's line) may be at most this long: 1000 joints take
  // about 200 KB, and a stream waits for the whole header before it parses a row.
  int64_t max_header_bytes = int64_t{4} << 20;
  // A frame row may be at most this long (1000 joints of 6 values in 30 characters each take
  // 180 KB): a stream holds a row until its newline arrives.
  int64_t max_row_bytes = int64_t{1} << 20;
  // The clip may take at most this much memory (every frame 32 bytes a joint, channels or not,
  // and 24 a position joint), so that a small file of many joints and rows cannot make a huge
  // clip; the server sets it to its upload budget.
  int64_t max_clip_bytes = int64_t{16} << 30;
};

struct BvhReadResult {
  Clip clip;
  // Non-fatal oddities, e.g. a `Frames:` header that disagrees with the rows present.
  std::vector<std::string> warnings;
};

// Parses BVH text that arrives in pieces (a streamed upload) as it arrives, holding the clip
// being built and the unparsed tail of the last piece rather than the whole text. Whatever the
// pieces, the result and the errors are ReadBvh's for their concatenation, except that text over
// `max_bytes` is refused when it arrives rather than before it is parsed. A row's error is
// reported by the Append() that completes its line (a row short of values one byte later, when
// it is known whether the text ends there: the error then says the file is truncated); a header
// error once the text so far has doubled since the header was last tried, which keeps a header
// sent in tiny pieces linear to parse. So a client learns of an error before it has sent the
// rest. Not thread-safe.
class BvhStreamReader {
 public:
  explicit BvhStreamReader(const BvhReadOptions& options = {});
  ~BvhStreamReader();
  BvhStreamReader(BvhStreamReader&&) noexcept;
  BvhStreamReader& operator=(BvhStreamReader&&) noexcept;

  // Parses what `piece` completes. An error is final: every later call returns it.
  absl::Status Append(absl::string_view piece);
  // The text has ended: parses its unfinished last line and returns the clip. Call once.
  absl::StatusOr<BvhReadResult> Finish();
  // Bytes appended so far.
  int64_t bytes() const { return bytes_; }

 private:
  class Motion;
  absl::Status AppendToHeader(absl::string_view piece);
  absl::Status AppendToMotion(absl::string_view piece);
  // Parses the header from `text` (the whole text so far); leaves motion_ unset when the text
  // may end inside the header and more is to come (`final` false).
  absl::Status ParseHeader(absl::string_view text, bool final);

  BvhReadOptions options_;
  absl::Status status_;
  int64_t bytes_ = 0;
  // The header's text while it is incomplete, then the motion's unfinished last line.
  std::string pending_;
  // The header is parsed again once pending_ reaches this size: doubling it keeps the work of
  // a header that arrives in tiny pieces linear.
  size_t next_header_attempt_ = 0;
  std::unique_ptr<Motion> motion_;  // once the header is parsed
};

// Parses BVH text. Errors are INVALID_ARGUMENT ("line N: expected ..., found ...") or
// RESOURCE_EXHAUSTED for inputs over the options' limits.
absl::StatusOr<BvhReadResult> ReadBvh(absl::string_view text, const BvhReadOptions& options = {});

// Reads and parses a file; errors are prefixed with the path. NOT_FOUND when it cannot be opened.
absl::StatusOr<BvhReadResult> ReadBvhFile(const std::string& path,
                                          const BvhReadOptions& options = {});

}  // namespace motiondb

#endif  // MOTIONDB_CORE_BVH_BVH_READER_H_
