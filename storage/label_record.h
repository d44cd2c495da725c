// Labels (SPEC 5): a descriptor with a value in [0, 1] on an inclusive range of a clip's frames,
// at the clip's own rate. Manual labels are given by people; propagated ones are written by a
// propagation job, from a manual label (their source) found again in a space with a score.
// What storage::Database's label operations take and return.
#ifndef MOTIONDB_STORAGE_LABEL_RECORD_H_
#define MOTIONDB_STORAGE_LABEL_RECORD_H_

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace motiondb::storage {

inline constexpr size_t kMaxDescriptorBytes = 256;

enum class LabelOrigin { kManual, kPropagated };

struct LabelRecord {
  int64_t label_id = 0;  // assigned by AddLabels
  int64_t clip_id = 0;
  int64_t first_frame = 0;  // inclusive, at the clip's own rate
  int64_t last_frame = 0;
  // 1 to 256 bytes of printable text (util/name_text.h), like clip names.
  std::string descriptor;
  double value = 1;  // in [0, 1]
  LabelOrigin origin = LabelOrigin::kManual;
  // Propagated labels only; 0 and empty on manual ones.
  int64_t source_label_id = 0;
  int64_t space_id = 0;  // 0 once the space is deleted: the label stays
  double score = 0;
  std::string job_id;
  int64_t created_unix_ms = 0;  // 0 on insert: the time of the insert
  // Filled on read, from the clip and the space: what a listing shows without another query.
  std::string clip_name;
  double frame_time = 0;
  std::string space_name;
};

// Which labels a listing (or a delete by filter) takes; what is unset takes any.
struct LabelFilter {
  int64_t clip_id = 0;
  std::string descriptor{};
  std::optional<LabelOrigin> origin{};
  std::optional<double> min_value{};  // value >= min_value

  bool empty() const { return clip_id == 0 && descriptor.empty() && !origin && !min_value; }
};

// A semantic query: the ranges carrying `descriptor` at `min_value` or more, strongest first.
struct LabelQuery {
  std::string descriptor{};
  double min_value = 0;
  std::vector<std::string> tags{};  // only clips carrying at least one of them; empty: any
};

// What Database::AddLabels did with a batch: its labels as stored, in its order, their ids and
// creation times filled in (an item already stored: the stored label's), and the items
// (indices, ascending) that were already stored and so were not added again.
struct AddedLabels {
  std::vector<LabelRecord> labels;
  std::vector<size_t> skipped;
};

struct LabelPage {
  std::vector<LabelRecord> labels;
  std::string next_page_token;  // empty on the last page
};

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_LABEL_RECORD_H_
