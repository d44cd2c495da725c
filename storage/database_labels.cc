#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"
#include "storage/database.h"
#include "storage/internal/database_impl.h"
#include "storage/internal/record_checks.h"
#include "storage/internal/record_rows.h"
#include "util/status_macros.h"

namespace motiondb::storage {
namespace {

// The columns ReadLabel reads, of labels as `l`, clips as `c` and spaces as `s`
// (kLabelTables). NULLs of manual labels read as 0 and ''.
constexpr absl::string_view kLabelColumns =
    "l.label_id, l.clip_id, l.first_frame, l.last_frame, l.descriptor, l.value, l.origin, "
    "coalesce(l.source_label_id, 0), coalesce(l.space_id, 0), coalesce(l.score, 0), "
    "coalesce(l.job_id, ''), l.created_unix_ms, c.name, c.frame_time, coalesce(s.name, '')";
constexpr absl::string_view kLabelTables =
    "labels l JOIN clips c ON c.clip_id = l.clip_id LEFT JOIN spaces s ON s.space_id = l.space_id";

absl::string_view OriginText(LabelOrigin origin) {
  return origin == LabelOrigin::kManual ? "manual" : "propagated";
}

LabelRecord ReadLabel(const SqliteStatement& row) {
  LabelRecord label;
  label.label_id = row.ColumnInt64(0);
  label.clip_id = row.ColumnInt64(1);
  label.first_frame = row.ColumnInt64(2);
  label.last_frame = row.ColumnInt64(3);
  label.descriptor = row.ColumnText(4);
  label.value = row.ColumnDouble(5);
  // The schema allows these two only.
  label.origin = row.ColumnText(6) == "manual" ? LabelOrigin::kManual : LabelOrigin::kPropagated;
  label.source_label_id = row.ColumnInt64(7);
  label.space_id = row.ColumnInt64(8);
  label.score = row.ColumnDouble(9);
  label.job_id = row.ColumnText(10);
  label.created_unix_ms = row.ColumnInt64(11);
  label.clip_name = row.ColumnText(12);
  label.frame_time = row.ColumnDouble(13);
  label.space_name = row.ColumnText(14);
  return label;
}

// Every row of `query` (bound, selecting kLabelColumns).
absl::StatusOr<std::vector<LabelRecord>> ReadLabels(SqliteStatement& query) {
  std::vector<LabelRecord> labels;
  while (true) {
    MOTIONDB_ASSIGN_OR_RETURN(const bool row, query.Step());
    if (!row) return labels;
    labels.push_back(ReadLabel(query));
  }
}

// "SELECT <label columns> FROM <label tables> <rest>".
std::string LabelSelect(absl::string_view rest) {
  return absl::StrCat("SELECT ", kLabelColumns, " FROM ", kLabelTables, " ", rest);
}

// The conditions of `filter` on the columns of labels (as `prefix`, "l." or ""), each after
// " AND ", on the parameters ?3 to ?6 that BindFilter binds; ?1 and ?2 are the caller's.
std::string FilterSql(const LabelFilter& filter, absl::string_view prefix) {
  std::string sql;
  if (filter.clip_id != 0) absl::StrAppend(&sql, " AND ", prefix, "clip_id = ?3");
  if (!filter.descriptor.empty()) absl::StrAppend(&sql, " AND ", prefix, "descriptor = ?4");
  if (filter.origin) absl::StrAppend(&sql, " AND ", prefix, "origin = ?5");
  if (filter.min_value) absl::StrAppend(&sql, " AND ", prefix, "value >= ?6");
  return sql;
}

void BindFilter(SqliteStatement& statement, const LabelFilter& filter) {
  if (filter.clip_id != 0) statement.BindInt64(3, filter.clip_id);
  if (!filter.descriptor.empty()) statement.BindText(4, filter.descriptor);
  if (filter.origin) statement.BindText(5, OriginText(*filter.origin));
  if (filter.min_value) statement.BindDouble(6, *filter.min_value);
}

// A page of at most `page_size` of `labels`, read with one row more than the page so as to know
// whether another follows; `token` makes the next page's token from the page's last label.
template <typename Token>
LabelPage PageOf(std::vector<LabelRecord> labels, int page_size, const Token& token) {
  LabelPage page;
  if (static_cast<int>(labels.size()) > page_size) {
    labels.resize(page_size);
    page.next_page_token = token(labels.back());
  }
  page.labels = std::move(labels);
  return page;
}

// A min_value of a filter or query: NaN would match nothing, a value outside [0, 1] is a slip.
absl::Status CheckMinValue(double min_value) {
  if (min_value >= 0 && min_value <= 1) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrCat("min_value: ", min_value, " is outside [0, 1]"));
}

absl::Status MalformedToken(const std::string& page_token) {
  return absl::InvalidArgumentError(
      absl::StrCat("malformed page_token '", page_token.substr(0, 40), "'"));
}

// Where a FindLabels page starts: after the label of this value, clip, first frame and id. The
// first page starts above every value.
struct FindStart {
  double value = 2;
  int64_t clip_id = 0, first_frame = 0, label_id = 0;
};

// "f:VALUE:CLIP:FIRST:ID", the value in 17 digits so that it reads back exactly.
std::string FindToken(const LabelRecord& last) {
  return absl::StrFormat("f:%.17g:%d:%d:%d", last.value, last.clip_id, last.first_frame,
                         last.label_id);
}

absl::StatusOr<FindStart> ParseFindToken(const std::string& page_token) {
  FindStart start;
  if (page_token.empty()) return start;
  const std::vector<std::string> parts = absl::StrSplit(page_token, ':');
  if (parts.size() != 5 || parts[0] != "f" || !absl::SimpleAtod(parts[1], &start.value) ||
      !absl::SimpleAtoi(parts[2], &start.clip_id) ||
      !absl::SimpleAtoi(parts[3], &start.first_frame) ||
      !absl::SimpleAtoi(parts[4], &start.label_id) || !std::isfinite(start.value) ||
      start.value < 0 || start.value > 1) {
    return MalformedToken(page_token);
  }
  return start;
}

// Where a page of a clip's timeline starts: after the label of this first frame, last frame and
// id. The first page starts before every label.
struct TimelineStart {
  int64_t first_frame = -1, last_frame = -1, label_id = 0;
};

// "t:FIRST:LAST:ID".
std::string TimelineToken(const LabelRecord& last) {
  return absl::StrCat("t:", last.first_frame, ":", last.last_frame, ":", last.label_id);
}

absl::StatusOr<TimelineStart> ParseTimelineToken(const std::string& page_token) {
  TimelineStart start;
  if (page_token.empty()) return start;
  const std::vector<std::string> parts = absl::StrSplit(page_token, ':');
  if (parts.size() != 4 || parts[0] != "t" || !absl::SimpleAtoi(parts[1], &start.first_frame) ||
      !absl::SimpleAtoi(parts[2], &start.last_frame) ||
      !absl::SimpleAtoi(parts[3], &start.label_id)) {
    return MalformedToken(page_token);
  }
  return start;
}

// NOT_FOUND naming `field` when no clip has `clip_id`.
absl::Status CheckClipExists(SqliteConnection& db, int64_t clip_id, absl::string_view field) {
  MOTIONDB_ASSIGN_OR_RETURN(const bool exists,
                            Exists(db, "SELECT 1 FROM clips WHERE clip_id = ?", clip_id));
  if (exists) return absl::OkStatus();
  return absl::NotFoundError(absl::StrCat(field, ": clip ", clip_id, " not found"));
}

// The frame counts of the clips a batch names, read once each in the batch's transaction.
class ClipFrames {
 public:
  explicit ClipFrames(SqliteConnection& db) : db_(db) {}

  // NOT_FOUND naming the item when the clip is unknown.
  absl::StatusOr<int64_t> Count(int64_t clip_id, absl::string_view item) {
    if (const auto known = counts_.find(clip_id); known != counts_.end()) return known->second;
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query,
                              db_.Prepare("SELECT frame_count FROM clips WHERE clip_id = ?"));
    MOTIONDB_ASSIGN_OR_RETURN(const bool found, query.BindInt64(1, clip_id).Step());
    if (!found) {
      return absl::NotFoundError(absl::StrCat(item, ".clip_id: clip ", clip_id, " not found"));
    }
    return counts_[clip_id] = query.ColumnInt64(0);
  }

 private:
  SqliteConnection& db_;
  absl::flat_hash_map<int64_t, int64_t> counts_;
};

// What CheckLabel cannot know: that the clip (and a propagated label's source and space) exist,
// and that the range ends inside the clip.
absl::Status CheckLabelReferences(SqliteConnection& db, ClipFrames& clips, const LabelRecord& label,
                                  size_t index) {
  const std::string item = absl::StrCat("labels[", index, "]");
  MOTIONDB_ASSIGN_OR_RETURN(const int64_t frames, clips.Count(label.clip_id, item));
  if (label.last_frame >= frames) {
    return absl::InvalidArgumentError(absl::StrCat(
        item, ".last_frame: ", label.last_frame, " is outside the clip's frames 0..", frames - 1));
  }
  if (label.origin == LabelOrigin::kManual) return absl::OkStatus();
  MOTIONDB_ASSIGN_OR_RETURN(const bool source, Exists(db, "SELECT 1 FROM labels WHERE label_id = ?",
                                                      label.source_label_id));
  if (!source) {
    return absl::NotFoundError(
        absl::StrCat(item, ".source_label_id: label ", label.source_label_id, " not found"));
  }
  if (label.space_id == 0) return absl::OkStatus();
  MOTIONDB_ASSIGN_OR_RETURN(const bool space,
                            Exists(db, "SELECT 1 FROM spaces WHERE space_id = ?", label.space_id));
  if (!space) {
    return absl::NotFoundError(
        absl::StrCat(item, ".space_id: space ", label.space_id, " not found"));
  }
  return absl::OkStatus();
}

// Binds `label`'s columns to ?1..?10 of `statement` (reset here), in the labels table's order
// from clip_id to job_id; a manual label's propagation columns stay NULL.
void BindLabelColumns(SqliteStatement& statement, const LabelRecord& label) {
  statement.Reset();
  statement.BindInt64(1, label.clip_id)
      .BindInt64(2, label.first_frame)
      .BindInt64(3, label.last_frame)
      .BindText(4, label.descriptor)
      .BindDouble(5, label.value)
      .BindText(6, OriginText(label.origin));
  if (label.origin == LabelOrigin::kPropagated) {
    statement.BindInt64(7, label.source_label_id).BindDouble(9, label.score);
    if (label.space_id != 0) statement.BindInt64(8, label.space_id);
    if (!label.job_id.empty()) statement.BindText(10, label.job_id);
  }
}

// Whether a label identical to `label` in every column but id and creation time is stored;
// if so, `label` takes its id and time.
absl::StatusOr<bool> FindIdentical(SqliteStatement& find, LabelRecord& label) {
  BindLabelColumns(find, label);
  MOTIONDB_ASSIGN_OR_RETURN(const bool found, find.Step());
  if (found) {
    label.label_id = find.ColumnInt64(0);
    label.created_unix_ms = find.ColumnInt64(1);
  }
  return found;
}

}  // namespace

absl::StatusOr<AddedLabels> Database::AddLabels(const std::vector<LabelRecord>& labels,
                                                const WriteOptions& write) {
  if (labels.empty()) return absl::InvalidArgumentError("labels: the batch is empty");
  for (size_t i = 0; i < labels.size(); ++i) MOTIONDB_RETURN_IF_ERROR(CheckLabel(labels[i], i));
  AddedLabels added;
  MOTIONDB_RETURN_IF_ERROR(impl_->Write(write, [&](SqliteConnection& db) -> absl::Status {
    added = {labels, {}};
    ClipFrames clips(db);
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement insert,
        db.Prepare("INSERT INTO labels (clip_id, first_frame, last_frame, descriptor, value, "
                   "origin, source_label_id, space_id, score, job_id, created_unix_ms) "
                   "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11)"));
    // One seek in labels_by_clip (schema migration 6); IS matches the NULLs of manual labels.
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement find,
        db.Prepare("SELECT label_id, created_unix_ms FROM labels WHERE clip_id = ?1 AND "
                   "first_frame = ?2 AND last_frame = ?3 AND descriptor = ?4 AND value = ?5 AND "
                   "origin = ?6 AND source_label_id IS ?7 AND space_id IS ?8 AND score IS ?9 AND "
                   "job_id IS ?10 LIMIT 1"));
    for (size_t i = 0; i < added.labels.size(); ++i) {
      LabelRecord& label = added.labels[i];
      MOTIONDB_RETURN_IF_ERROR(CheckLabelReferences(db, clips, label, i));
      MOTIONDB_ASSIGN_OR_RETURN(const bool stored, FindIdentical(find, label));
      if (stored) {
        added.skipped.push_back(i);
        continue;
      }
      label.created_unix_ms = CreationTime(label.created_unix_ms);
      BindLabelColumns(insert, label);
      insert.BindInt64(11, label.created_unix_ms);
      MOTIONDB_RETURN_IF_ERROR(insert.Run());
      label.label_id = db.last_insert_rowid();
    }
    return absl::OkStatus();
  }));
  return added;
}

absl::StatusOr<LabelPage> Database::ListLabels(const Page& page, const LabelFilter& filter) {
  MOTIONDB_ASSIGN_OR_RETURN(const int page_size, CheckPageSize(page.page_size));
  int64_t after = 0;
  if (!page.page_token.empty() && !absl::SimpleAtoi(page.page_token, &after)) {
    return MalformedToken(page.page_token);
  }
  if (filter.min_value) MOTIONDB_RETURN_IF_ERROR(CheckMinValue(*filter.min_value));
  const std::string sql = LabelSelect(absl::StrCat("WHERE l.label_id > ?1", FilterSql(filter, "l."),
                                                   " ORDER BY l.label_id LIMIT ?2"));
  LabelPage result;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    if (filter.clip_id != 0)
      MOTIONDB_RETURN_IF_ERROR(CheckClipExists(db, filter.clip_id, "clip_id"));
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query, db.Prepare(sql));
    query.BindInt64(1, after).BindInt64(2, page_size + 1);
    BindFilter(query, filter);
    MOTIONDB_ASSIGN_OR_RETURN(std::vector<LabelRecord> labels, ReadLabels(query));
    result = PageOf(std::move(labels), page_size,
                    [](const LabelRecord& last) { return absl::StrCat(last.label_id); });
    return absl::OkStatus();
  }));
  return result;
}

absl::StatusOr<LabelPage> Database::FindLabels(const Page& page, const LabelQuery& query) {
  MOTIONDB_ASSIGN_OR_RETURN(const int page_size, CheckPageSize(page.page_size));
  MOTIONDB_ASSIGN_OR_RETURN(const FindStart start, ParseFindToken(page.page_token));
  MOTIONDB_RETURN_IF_ERROR(CheckName("descriptor", query.descriptor, kMaxDescriptorBytes));
  MOTIONDB_RETURN_IF_ERROR(CheckMinValue(query.min_value));
  // At most kMaxTags, each once: the query binds one parameter per tag.
  if (query.tags.size() > kMaxTags) {
    return absl::InvalidArgumentError(
        absl::StrCat("tags: at most ", kMaxTags, " a query, got ", query.tags.size()));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<std::string> tags, CanonicalTags(query.tags, "tags"));
  // Strongest first; (value, clip, first frame, id) orders every label once, so a page starts
  // right after the last one of the page before.
  std::string sql = LabelSelect(
      "WHERE l.descriptor = ?1 AND l.value >= ?2 AND (l.value < ?3 OR (l.value = ?3 AND "
      "(l.clip_id, l.first_frame, l.label_id) > (?4, ?5, ?6)))");
  if (!tags.empty()) {
    std::vector<std::string> parameters;
    for (size_t i = 0; i < tags.size(); ++i) parameters.push_back(absl::StrCat("?", 8 + i));
    absl::StrAppend(&sql,
                    " AND EXISTS (SELECT 1 FROM clip_tags t WHERE t.clip_id = l.clip_id AND t.tag "
                    "IN (",
                    absl::StrJoin(parameters, ", "), "))");
  }
  absl::StrAppend(&sql, " ORDER BY l.value DESC, l.clip_id, l.first_frame, l.label_id LIMIT ?7");
  LabelPage result;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement statement, db.Prepare(sql));
    statement.BindText(1, query.descriptor)
        .BindDouble(2, query.min_value)
        .BindDouble(3, start.value)
        .BindInt64(4, start.clip_id)
        .BindInt64(5, start.first_frame)
        .BindInt64(6, start.label_id)
        .BindInt64(7, page_size + 1);
    for (size_t i = 0; i < tags.size(); ++i) statement.BindText(static_cast<int>(8 + i), tags[i]);
    MOTIONDB_ASSIGN_OR_RETURN(std::vector<LabelRecord> labels, ReadLabels(statement));
    result = PageOf(std::move(labels), page_size, FindToken);
    return absl::OkStatus();
  }));
  return result;
}

absl::StatusOr<LabelPage> Database::ClipLabels(int64_t clip_id, const Page& page) {
  MOTIONDB_ASSIGN_OR_RETURN(const int page_size, CheckPageSize(page.page_size));
  MOTIONDB_ASSIGN_OR_RETURN(const TimelineStart start, ParseTimelineToken(page.page_token));
  LabelPage result;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_RETURN_IF_ERROR(CheckClipExists(db, clip_id, "clip_id"));
    // (first frame, last frame, id) orders every label of the clip once, so a page starts
    // right after the last one of the page before.
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        db.Prepare(LabelSelect("WHERE l.clip_id = ?1 AND (l.first_frame, l.last_frame, "
                               "l.label_id) > (?2, ?3, ?4) ORDER BY l.first_frame, l.last_frame, "
                               "l.label_id LIMIT ?5")));
    query.BindInt64(1, clip_id)
        .BindInt64(2, start.first_frame)
        .BindInt64(3, start.last_frame)
        .BindInt64(4, start.label_id)
        .BindInt64(5, page_size + 1);
    MOTIONDB_ASSIGN_OR_RETURN(std::vector<LabelRecord> labels, ReadLabels(query));
    result = PageOf(std::move(labels), page_size, TimelineToken);
    return absl::OkStatus();
  }));
  return result;
}

absl::StatusOr<int64_t> Database::DeleteLabels(const std::vector<int64_t>& label_ids,
                                               const WriteOptions& write) {
  if (label_ids.empty()) return absl::InvalidArgumentError("label_ids: give at least one");
  MOTIONDB_RETURN_IF_ERROR(impl_->Write(write, [&](SqliteConnection& db) -> absl::Status {
    // Every id is checked before any is deleted: deleting a manual label takes those propagated
    // from it, which the list may name too.
    for (size_t i = 0; i < label_ids.size(); ++i) {
      MOTIONDB_ASSIGN_OR_RETURN(
          const bool exists, Exists(db, "SELECT 1 FROM labels WHERE label_id = ?", label_ids[i]));
      if (!exists) {
        return absl::NotFoundError(
            absl::StrCat("label_ids[", i, "]: label ", label_ids[i], " not found"));
      }
    }
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement erase,
                              db.Prepare("DELETE FROM labels WHERE label_id = ?"));
    for (const int64_t label_id : label_ids) {
      erase.Reset();
      MOTIONDB_RETURN_IF_ERROR(erase.BindInt64(1, label_id).Run());
    }
    return absl::OkStatus();
  }));
  // Repeated ids name one label.
  std::vector<int64_t> distinct = label_ids;
  std::sort(distinct.begin(), distinct.end());
  return std::unique(distinct.begin(), distinct.end()) - distinct.begin();
}

absl::StatusOr<int64_t> Database::DeleteLabels(const LabelFilter& filter,
                                               const WriteOptions& write) {
  if (filter.empty()) {
    return absl::InvalidArgumentError(
        "give label ids or a filter (clip, descriptor, origin, min_value); an empty filter would "
        "delete every label");
  }
  int64_t deleted = 0;
  MOTIONDB_RETURN_IF_ERROR(impl_->Write(write, [&](SqliteConnection& db) -> absl::Status {
    if (filter.clip_id != 0)
      MOTIONDB_RETURN_IF_ERROR(CheckClipExists(db, filter.clip_id, "clip_id"));
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement erase,
        db.Prepare(absl::StrCat("DELETE FROM labels WHERE 1", FilterSql(filter, ""))));
    BindFilter(erase, filter);
    MOTIONDB_RETURN_IF_ERROR(erase.Run());
    deleted = db.changes();
    return absl::OkStatus();
  }));
  return deleted;
}

}  // namespace motiondb::storage
