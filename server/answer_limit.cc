#include "server/answer_limit.h"

#include <algorithm>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/bvh/bvh_writer.h"
#include "storage/label_record.h"
#include "storage/record_limits.h"

namespace motiondb::server {
namespace {

// A job id: "job-" and a decimal int64.
constexpr int64_t kJobIdBytes = 24;
// A path's frame, a packed int32 varint: frame numbers are never negative, so at most 5 bytes.
constexpr int64_t kPathFrameBytes = 5;
// Names in a search explanation beside the joints' ("yaw rate", "root velocity"), with room.
constexpr int64_t kExtraShareNameBytes = 32;
// A search answer's timings and counts (15 numbers), characteristic frames (at most 17) and its
// framing as an item of a batch (a code, framing), with room.
constexpr int64_t kSearchFixedBytes = 1024;

std::string Size(int64_t bytes) {
  if (bytes < (int64_t{1} << 20)) return absl::StrCat(bytes, " bytes");
  return absl::StrFormat("%.1f MiB", static_cast<double>(bytes) / (1 << 20));
}

int64_t JointNameBytes(const Skeleton& skeleton) {
  int64_t bytes = 0;
  for (const Joint& joint : skeleton.joints()) {
    bytes += TextFieldBytes(static_cast<int64_t>(joint.name.size()));
  }
  return bytes;
}

}  // namespace

absl::Status AnswerLimit::Check(int64_t bytes, absl::string_view what,
                                absl::string_view remedy) const {
  if (bytes <= max_bytes_) return absl::OkStatus();
  return absl::ResourceExhaustedError(absl::StrCat(
      what, " could take up to ", Size(bytes), ", more than the server's answer limit of ",
      Size(max_bytes_), " (--max-answer-mb); ", remedy));
}

int64_t AnswerLimit::MostItems(int64_t item_bytes) const {
  return std::max<int64_t>(1, (max_bytes_ - kAnswerFixedBytes) / item_bytes);
}

int64_t BvhFieldBytes(const Skeleton& skeleton, int64_t frames) {
  return TextFieldBytes(BvhTextBound(skeleton, frames));
}

int64_t ClipListItemBytes() {
  // Ids, times, counts, rate, duration; the name, source file, hash, a tag each, and the
  // provenance's operator, space, parameters and a framing each; the clip's own in its list.
  constexpr int64_t kNumbers = 8;
  constexpr int64_t kTextFields = 3 + static_cast<int64_t>(storage::kMaxTags) + 4;
  return kNumbers * kNumberFieldBytes + (kTextFields + 1) * kFieldFramingBytes;
}

int64_t LabelAnswerBytes() {
  // Ids, frames, seconds, value, origin, score, creation time; the clip's name, the descriptor,
  // the space's name and the job's id; the label's own framing in its list.
  constexpr int64_t kNumbers = 11;
  return kNumbers * kNumberFieldBytes + TextFieldBytes(storage::kMaxNameBytes) +
         TextFieldBytes(storage::kMaxDescriptorBytes) + TextFieldBytes(storage::kMaxNameBytes) +
         TextFieldBytes(kJobIdBytes) + kFieldFramingBytes;
}

int64_t PosesAnswerBytes(const Skeleton& skeleton, int64_t frames) {
  const int64_t joints = skeleton.joint_count();
  return TextFieldBytes(frames * joints * 3 * static_cast<int64_t>(sizeof(float))) +
         JointNameBytes(skeleton) + TextFieldBytes(joints * kNumberFieldBytes);
}

int64_t SearchAnswerBytes(int64_t results, int64_t path_rows, bool explained,
                          const Skeleton& skeleton) {
  // Clip id, seconds, frames, score, seed frame, mirrored; the clip's name; the hit's framing.
  constexpr int64_t kHitNumbers = 8;
  int64_t hit =
      kHitNumbers * kNumberFieldBytes + TextFieldBytes(storage::kMaxNameBytes) + kFieldFramingBytes;
  if (path_rows > 0) hit += TextFieldBytes(path_rows * kPathFrameBytes);
  if (explained) {
    // A share (name, share, score) for each joint and the two extra groups; the full score and
    // speeds.
    const int64_t shares = skeleton.joint_count() + 2;
    hit += JointNameBytes(skeleton) + 2 * TextFieldBytes(kExtraShareNameBytes) +
           shares * (2 * kNumberFieldBytes + kFieldFramingBytes) + 3 * kNumberFieldBytes +
           kFieldFramingBytes;
  }
  return kSearchFixedBytes + results * hit;
}

}  // namespace motiondb::server
