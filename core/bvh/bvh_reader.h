// Reads BVH motion capture files into a Clip, tolerating the dialects real exporters write
// (any rotation order per joint, 3 or 6 channels on any joint, leaves without End Site, CRLF,
// tabs, E-notation, colons and spaces in joint names) and rejecting malformed input with the
// line number and what was expected.
#ifndef MOTIONDB_CORE_BVH_BVH_READER_H_
#define MOTIONDB_CORE_BVH_BVH_READER_H_

#include <cstdint>
#include <string>
#include <vector>
#include "absl/strings/string_view.h"

#include "absl/status/statusor.h"
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
};

struct BvhReadResult {
  Clip clip;
  // Non-fatal oddities, e.g. a `Frames:` header that disagrees with the rows present.
  std::vector<std::string> warnings;
};

// Parses BVH text. Errors are INVALID_ARGUMENT ("line N: expected ..., found ...") or
// RESOURCE_EXHAUSTED for inputs over the options' limits.
absl::StatusOr<BvhReadResult> ReadBvh(absl::string_view text, const BvhReadOptions& options = {});

// Reads and parses a file; errors are prefixed with the path. NOT_FOUND when it cannot be opened.
absl::StatusOr<BvhReadResult> ReadBvhFile(const std::string& path,
                                          const BvhReadOptions& options = {});

}  // namespace motiondb

#endif  // MOTIONDB_CORE_BVH_BVH_READER_H_
