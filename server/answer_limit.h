// How large one answer may be (--max-answer-mb), and what the answers that grow with their
// request are estimated at, from sizes known before they are made: a BVH text from its frames and
// skeleton, poses from frames x joints, a page from its rows. Each estimate is an upper bound on
// the answer's encoding (every number at its longest, every name at the longest the database
// stores), so that an answer checked here cannot exceed the limit, nor gRPC's 2 GiB ceiling on
// one message (past which the process aborts while serialising it).
//
// Pure values and functions; thread-safe.
#ifndef MOTIONDB_SERVER_ANSWER_LIMIT_H_
#define MOTIONDB_SERVER_ANSWER_LIMIT_H_

#include <cstdint>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "core/motion/skeleton.h"

namespace motiondb::server {

// --max-answer-mb's default, and its largest value: below gRPC's 2 GiB.
inline constexpr int kDefaultMaxAnswerMb = 256;
inline constexpr int kMaxAnswerMbCeiling = 2047;

// What every answer may hold besides the parts that grow with its request, counted once: its
// numbers, names (at most storage::kMaxNameBytes each), a clip's tags (64 of 128 bytes), a
// content hash, framing.
inline constexpr int64_t kAnswerFixedBytes = int64_t{64} << 10;
// A field's tag and length prefix, at most (field numbers below 2048, lengths below 2^35).
inline constexpr int64_t kFieldFramingBytes = 7;
// A number field at its longest: its tag and a 10-byte varint (a double takes 8).
inline constexpr int64_t kNumberFieldBytes = 12;
// A clip range (ClipRange: a clip id and two frames) in a list.
inline constexpr int64_t kClipRangeBytes = 3 * kNumberFieldBytes + kFieldFramingBytes;

class AnswerLimit {
 public:
  explicit AnswerLimit(int64_t max_bytes = int64_t{kDefaultMaxAnswerMb} << 20)
      : max_bytes_(max_bytes) {}

  int64_t max_bytes() const { return max_bytes_; }

  // OK when an answer of at most `bytes` fits; else RESOURCE_EXHAUSTED naming the limit, the
  // flag, `what` would take and `remedy`: "the BVH of clip 4's frames 0..499999 could take up to
  // 2.8 GiB, more than the server's answer limit of 256 MiB (--max-answer-mb); export it with
  // ExportClipStream ...".
  absl::Status Check(int64_t bytes, absl::string_view what, absl::string_view remedy) const;

  // The most items of at most `item_bytes` each that an answer holds within the limit, beside
  // kAnswerFixedBytes: the largest page a listing gives (at least 1).
  int64_t MostItems(int64_t item_bytes) const;

 private:
  int64_t max_bytes_;
};

// A text or bytes field of at most `bytes`, framed.
inline int64_t TextFieldBytes(int64_t bytes) { return bytes + kFieldFramingBytes; }

// A BVH text field of `frames` frames of a clip of `skeleton` (core/bvh/bvh_writer.h's
// BvhTextBound).
int64_t BvhFieldBytes(const Skeleton& skeleton, int64_t frames);

// A label (LabelService's Label): every name at its longest.
int64_t LabelAnswerBytes();

// A clip in a listing (ClipService.ListClips) besides its text (names, hash, tags, provenance),
// which the listing's page counts as it reads it (storage::ClipFilter::max_text_bytes): its
// numbers and the framing of its text fields.
int64_t ClipListItemBytes();

// A clip's poses (ClipService.GetClipPoses): frames x joints x 3 float32, the joints' names and
// parents.
int64_t PosesAnswerBytes(const Skeleton& skeleton, int64_t frames);

// A search's answer (without kAnswerFixedBytes: a batch holds many): `results` hits, each with a
// path of `path_rows` frames (0: no path) and, when `explained`, an explanation naming each joint
// of `skeleton` (the space's).
int64_t SearchAnswerBytes(int64_t results, int64_t path_rows, bool explained,
                          const Skeleton& skeleton);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_ANSWER_LIMIT_H_
