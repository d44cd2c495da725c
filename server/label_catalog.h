// Labels as the API gives and asks for them (LabelService): clips named by id or name, ranges in
// frames or seconds, resolved against the clip and stored by storage::Database, which checks
// the rest and writes each batch in one transaction. Labels touch no index, so unlike the
// Catalog's writes these need no lock of their own.
//
// Errors name the item and field as the request spells them ("labels[3].end_s: ...").
// Thread-safe, as the Database is.
#ifndef MOTIONDB_SERVER_LABEL_CATALOG_H_
#define MOTIONDB_SERVER_LABEL_CATALOG_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/answer_limit.h"
#include "server/listing.h"
#include "storage/database.h"

namespace motiondb::server {

inline constexpr size_t kMaxLabelsPerBatch = 100000;

// A manual label to add: the clip is clip_id, or when that is 0 the clip named clip_name (both
// set, they must name one clip); the inclusive range in frames or in seconds (each rounded to
// the nearest frame, an end_s at the clip's duration being its last frame), not both, an unset
// bound being the clip's first or last frame.
struct NewLabel {
  int64_t clip_id = 0;
  std::string clip_name{};
  std::optional<int> first_frame{}, last_frame{};
  std::optional<double> start_s{}, end_s{};
  std::string descriptor{};
  std::optional<double> value{};  // unset: 1
};

// Stores the batch, all or nothing; returns the labels as stored, in its order, an item
// identical to a stored label (or an earlier item) returned as that one and listed as skipped
// (storage::Database::AddLabels). NOT_FOUND for
// an unknown clip; INVALID_ARGUMENT for what storage::Database::AddLabels refuses, a first
// frame or time that is past the clip, a time that is not finite, negative or reversed, frames
// and seconds both given, no clip named or clip_id and clip_name naming two, or over
// kMaxLabelsPerBatch labels; RESOURCE_EXHAUSTED, before anything is stored, for more labels
// than an answer of `answers` holds. `should_stop` as the Catalog's writes take it.
absl::StatusOr<storage::AddedLabels> AddLabels(storage::Database& database,
                                               const std::vector<NewLabel>& labels,
                                               const AnswerLimit& answers,
                                               const std::function<bool()>& should_stop = {});

// Pages as ListClips pages (server/listing.h), of at most the labels an answer of `answers`
// holds (AnswerLimit::MostItems of LabelAnswerBytes: a larger page_size is read as that, as one
// over 1000 is read as 1000).
absl::StatusOr<storage::LabelPage> ListLabels(storage::Database& database, const PageRequest& page,
                                              const storage::LabelFilter& filter,
                                              const AnswerLimit& answers);
absl::StatusOr<storage::LabelPage> FindLabels(storage::Database& database, const PageRequest& page,
                                              const storage::LabelQuery& query,
                                              const AnswerLimit& answers);

// Every manual label of `descriptor` (empty: of any), every page read.
absl::StatusOr<std::vector<storage::LabelRecord>> ManualLabels(storage::Database& database,
                                                               const std::string& descriptor);

// Labels named by id, or else those the filter takes.
struct LabelDeletion {
  std::vector<int64_t> label_ids;
  storage::LabelFilter filter;
};
// Returns how many labels were named or taken.
absl::StatusOr<int64_t> DeleteLabels(storage::Database& database, const LabelDeletion& deletion,
                                     const std::function<bool()>& should_stop = {});

// A clip and a page of its labels by first frame, pages as ListLabels'; NOT_FOUND naming
// clip_id for an unknown clip.
struct ClipTimeline {
  storage::ClipRecord clip;
  std::vector<storage::LabelRecord> labels;
  std::string next_page_token;  // empty on the last page
};
absl::StatusOr<ClipTimeline> GetClipTimeline(storage::Database& database, int64_t clip_id,
                                             const PageRequest& page, const AnswerLimit& answers);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_LABEL_CATALOG_H_
