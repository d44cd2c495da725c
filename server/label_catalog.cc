#include "server/label_catalog.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::server {
namespace {

// The clips a batch names, each read once: a studio's import labels few clips many times. The
// records are held by pointer, so one that Resolve returns stays valid as the maps grow.
class ClipResolver {
 public:
  explicit ClipResolver(storage::Database& database) : database_(database) {}

  absl::StatusOr<const storage::ClipRecord*> Resolve(const NewLabel& label,
                                                     const std::string& item) {
    if (label.clip_id == 0 && label.clip_name.empty()) {
      return absl::InvalidArgumentError(absl::StrCat(item, ": give clip_id or clip_name"));
    }
    const storage::ClipRecord* by_id = nullptr;
    if (label.clip_id != 0) {
      MOTIONDB_ASSIGN_OR_RETURN(by_id,
                                Cached(by_id_, label.clip_id, absl::StrCat(item, ".clip_id"),
                                       [&] { return database_.GetClipRecord(label.clip_id); }));
      if (label.clip_name.empty()) return by_id;
    }
    MOTIONDB_ASSIGN_OR_RETURN(
        const storage::ClipRecord* by_name,
        Cached(by_name_, label.clip_name, absl::StrCat(item, ".clip_name"),
               [&] { return database_.GetClipRecordByName(label.clip_name); }));
    // Both given: they must name one clip, or which one was meant is a guess.
    if (by_id != nullptr && by_id->clip_id != by_name->clip_id) {
      return absl::InvalidArgumentError(
          absl::StrCat(item, ": clip_id ", label.clip_id, " and clip_name '", label.clip_name,
                       "' (clip ", by_name->clip_id, ") name different clips; give one"));
    }
    return by_name;
  }

 private:
  template <typename Key, typename Read>
  absl::StatusOr<const storage::ClipRecord*> Cached(
      absl::flat_hash_map<Key, std::unique_ptr<storage::ClipRecord>>& cache, const Key& key,
      const std::string& field, const Read& read) {
    auto found = cache.find(key);
    if (found == cache.end()) {
      MOTIONDB_ASSIGN_OR_RETURN(storage::ClipRecord record, Prefixed(field, read()));
      found = cache.emplace(key, std::make_unique<storage::ClipRecord>(std::move(record))).first;
    }
    return found->second.get();
  }

  storage::Database& database_;
  absl::flat_hash_map<int64_t, std::unique_ptr<storage::ClipRecord>> by_id_;
  absl::flat_hash_map<std::string, std::unique_ptr<storage::ClipRecord>> by_name_;
};

// The frame nearest `seconds` into `clip`; INVALID_ARGUMENT naming `field` for a time that is
// not finite, negative, or past the clip's last frame. An `end` may be the clip's end (its
// duration, frame_count x frame time, as tools write a half-open range), give or take half a
// frame: that is the last frame.
absl::StatusOr<int64_t> FrameAt(double seconds, const storage::ClipRecord& clip,
                                const std::string& field, bool end) {
  if (!std::isfinite(seconds) || seconds < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ": ", seconds, " is not a time in the clip (seconds from 0)"));
  }
  const double last = static_cast<double>(clip.frame_count - 1);
  double frame = std::round(seconds / clip.frame_time);
  if (end && frame == last + 1) frame = last;
  if (frame > last) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ": ", seconds, " s is past the clip's last frame ",
                     clip.frame_count - 1, " at ", (clip.frame_count - 1) * clip.frame_time, " s"));
  }
  return static_cast<int64_t>(frame);
}

// Sets `record`'s range from `label`'s frames or seconds; storage checks the frames.
absl::Status ResolveRange(const NewLabel& label, const storage::ClipRecord& clip,
                          const std::string& item, storage::LabelRecord& record) {
  const bool frames = label.first_frame || label.last_frame;
  const bool seconds = label.start_s || label.end_s;
  if (frames && seconds) {
    return absl::InvalidArgumentError(
        absl::StrCat(item,
                     ": give the range in frames (first_frame, last_frame) or in seconds "
                     "(start_s, end_s), not both"));
  }
  record.first_frame = label.first_frame.value_or(0);
  record.last_frame = label.last_frame.value_or(clip.frame_count - 1);
  // Storage checks the range as given; a first frame past the clip, the last one unset, would
  // be told as a reversed range.
  if (label.first_frame && *label.first_frame >= clip.frame_count) {
    return absl::InvalidArgumentError(absl::StrCat(item, ".first_frame: ", *label.first_frame,
                                                   " is outside the clip's frames 0..",
                                                   clip.frame_count - 1));
  }
  if (label.start_s) {
    MOTIONDB_ASSIGN_OR_RETURN(record.first_frame,
                              FrameAt(*label.start_s, clip, absl::StrCat(item, ".start_s"), false));
  }
  if (label.end_s) {
    MOTIONDB_ASSIGN_OR_RETURN(record.last_frame,
                              FrameAt(*label.end_s, clip, absl::StrCat(item, ".end_s"), true));
  }
  if (label.start_s && label.end_s && *label.end_s < *label.start_s) {
    return absl::InvalidArgumentError(
        absl::StrCat(item, ".end_s: ", *label.end_s, " is before start_s ", *label.start_s));
  }
  return absl::OkStatus();
}

// A label listing's page, storage's: StoragePage's, and no more labels than an answer holds.
absl::StatusOr<storage::Page> LabelListingPage(const PageRequest& page,
                                               const AnswerLimit& answers) {
  MOTIONDB_ASSIGN_OR_RETURN(storage::Page stored, StoragePage(page));
  stored.page_size =
      static_cast<int>(std::min<int64_t>(stored.page_size, answers.MostItems(LabelAnswerBytes())));
  return stored;
}

}  // namespace

absl::StatusOr<storage::AddedLabels> AddLabels(storage::Database& database,
                                               const std::vector<NewLabel>& labels,
                                               const AnswerLimit& answers,
                                               const std::function<bool()>& should_stop) {
  if (labels.size() > kMaxLabelsPerBatch) {
    return absl::InvalidArgumentError(
        absl::StrCat("labels: at most ", kMaxLabelsPerBatch, " a call, got ", labels.size()));
  }
  // The answer holds every label as stored, its clip's name too.
  MOTIONDB_RETURN_IF_ERROR(answers.Check(
      static_cast<int64_t>(labels.size()) * LabelAnswerBytes() + kAnswerFixedBytes,
      absl::StrCat("the answer of ", labels.size(), " labels"),
      absl::StrCat("send at most ", answers.MostItems(LabelAnswerBytes()), " labels a call")));
  // One time for the batch, so that what is returned is what was stored.
  const int64_t now = absl::ToUnixMillis(absl::Now());
  ClipResolver clips(database);
  std::vector<storage::LabelRecord> records;
  records.reserve(labels.size());
  for (size_t i = 0; i < labels.size(); ++i) {
    const NewLabel& label = labels[i];
    const std::string item = absl::StrCat("labels[", i, "]");
    MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord* clip, clips.Resolve(label, item));
    storage::LabelRecord& record = records.emplace_back();
    record.clip_id = clip->clip_id;
    record.clip_name = clip->name;
    record.frame_time = clip->frame_time;
    MOTIONDB_RETURN_IF_ERROR(ResolveRange(label, *clip, item, record));
    record.descriptor = label.descriptor;
    record.value = label.value.value_or(1.0);
    record.created_unix_ms = now;
  }
  return database.AddLabels(records, {.should_stop = should_stop});
}

absl::StatusOr<std::vector<storage::LabelRecord>> ManualLabels(storage::Database& database,
                                                               const std::string& descriptor) {
  std::vector<storage::LabelRecord> labels;
  storage::Page page{.page_size = storage::kMaxPageSize, .page_token = ""};
  do {
    MOTIONDB_ASSIGN_OR_RETURN(storage::LabelPage read,
                              database.ListLabels(page, {.descriptor = descriptor,
                                                         .origin = storage::LabelOrigin::kManual}));
    labels.insert(labels.end(), read.labels.begin(), read.labels.end());
    page.page_token = read.next_page_token;
  } while (!page.page_token.empty());
  return labels;
}

absl::StatusOr<storage::LabelPage> ListLabels(storage::Database& database, const PageRequest& page,
                                              const storage::LabelFilter& filter,
                                              const AnswerLimit& answers) {
  MOTIONDB_ASSIGN_OR_RETURN(const storage::Page stored, LabelListingPage(page, answers));
  return database.ListLabels(stored, filter);
}

absl::StatusOr<storage::LabelPage> FindLabels(storage::Database& database, const PageRequest& page,
                                              const storage::LabelQuery& query,
                                              const AnswerLimit& answers) {
  MOTIONDB_ASSIGN_OR_RETURN(const storage::Page stored, LabelListingPage(page, answers));
  return database.FindLabels(stored, query);
}

absl::StatusOr<int64_t> DeleteLabels(storage::Database& database, const LabelDeletion& deletion,
                                     const std::function<bool()>& should_stop) {
  if (deletion.label_ids.empty()) {
    return database.DeleteLabels(deletion.filter, {.should_stop = should_stop});
  }
  if (!deletion.filter.empty()) {
    return absl::InvalidArgumentError("give label_ids or a filter, not both");
  }
  return database.DeleteLabels(deletion.label_ids, {.should_stop = should_stop});
}

absl::StatusOr<ClipTimeline> GetClipTimeline(storage::Database& database, int64_t clip_id,
                                             const PageRequest& page, const AnswerLimit& answers) {
  MOTIONDB_ASSIGN_OR_RETURN(const storage::Page stored, LabelListingPage(page, answers));
  ClipTimeline timeline;
  MOTIONDB_ASSIGN_OR_RETURN(timeline.clip, Prefixed("clip_id", database.GetClipRecord(clip_id)));
  MOTIONDB_ASSIGN_OR_RETURN(storage::LabelPage labels, database.ClipLabels(clip_id, stored));
  timeline.labels = std::move(labels.labels);
  timeline.next_page_token = std::move(labels.next_page_token);
  return timeline;
}

}  // namespace motiondb::server
