#include <algorithm>
#include <limits>
#include <optional>
#include <utility>

#include "absl/container/flat_hash_map.h"
#include "absl/container/flat_hash_set.h"
#include "absl/strings/ascii.h"
#include "absl/strings/escaping.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"
#include "storage/blob_codec.h"
#include "storage/content_hash.h"
#include "storage/database.h"
#include "storage/internal/clip_frames.h"
#include "storage/internal/database_impl.h"
#include "storage/internal/record_checks.h"
#include "storage/internal/record_rows.h"
#include "storage/sqlite_blob.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::storage {
namespace {

// Where a page starts: after the clip `clip_id` (0: at the first), whose sort key is `key` (a
// name, or a time in decimal; unused in id order).
struct PageStart {
  int64_t clip_id = 0;
  std::string key;
};

bool IsDecimal(absl::string_view text) {
  return !text.empty() &&
         std::all_of(text.begin(), text.end(), [](char c) { return absl::ascii_isdigit(c); });
}

absl::StatusOr<PageStart> ParsePageToken(ClipOrder order, const std::string& page_token) {
  PageStart start;
  if (page_token.empty()) return start;
  absl::string_view id = page_token, key;
  bool ok = true;
  if (order != ClipOrder::kId) {
    const std::vector<absl::string_view> parts =
        absl::StrSplit(page_token, absl::MaxSplits('.', 2));
    ok = parts.size() == 3 && parts[0] == (order == ClipOrder::kName ? "n" : "c");
    if (ok) {
      id = parts[1];
      key = parts[2];
    }
  }
  ok = ok && IsDecimal(id) && absl::SimpleAtoi(id, &start.clip_id) && start.clip_id > 0;
  if (ok && order == ClipOrder::kName) ok = absl::WebSafeBase64Unescape(key, &start.key);
  if (ok && order == ClipOrder::kCreated) {
    ok = IsDecimal(key);
    start.key = std::string(key);
  }
  if (!ok) {
    return absl::InvalidArgumentError(
        absl::StrCat("malformed page_token '", page_token.substr(0, 40), "'"));
  }
  return start;
}

// Adds `tags` to the clip; those it carries already stay as they are.
absl::Status InsertTags(SqliteConnection& db, int64_t clip_id,
                        const std::vector<std::string>& tags) {
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement insert_tag,
      db.Prepare("INSERT OR IGNORE INTO clip_tags (clip_id, tag) VALUES (?, ?)"));
  for (const std::string& tag : tags) {
    insert_tag.Reset();
    MOTIONDB_RETURN_IF_ERROR(insert_tag.BindInt64(1, clip_id).BindText(2, tag).Run());
  }
  return absl::OkStatus();
}

// The rotation blob of the clip row `clip_id`, inserted as a zero blob of its size, written
// in pieces (the column is the row's last: storage/schema.cc, migration 5).
absl::Status WriteRotations(SqliteConnection& db, int64_t clip_id, const RowMatrixXd& rotations) {
  MOTIONDB_ASSIGN_OR_RETURN(SqliteBlob blob, SqliteBlob::Open(db, "clips", "rotations", clip_id,
                                                              SqliteBlob::Mode::kWrite));
  int64_t offset = 0;
  MOTIONDB_RETURN_IF_ERROR(ForEachFloat32Piece(rotations, [&](absl::string_view piece) {
    MOTIONDB_RETURN_IF_ERROR(blob.Write(piece, offset));
    offset += static_cast<int64_t>(piece.size());
    return absl::OkStatus();
  }));
  if (offset != blob.size()) {
    return absl::InternalError(absl::StrCat("wrote ", offset, " bytes of clip ", clip_id,
                                            "'s rotation blob of ", blob.size()));
  }
  return absl::OkStatus();
}

// The records, tags included, of the rows `query` returns: bound, and selecting
// kClipRecordColumns of clips as `c`.
// The text a clip's record holds: what ClipFilter::max_text_bytes counts.
int64_t TextBytes(const ClipRecord& record) {
  int64_t bytes =
      static_cast<int64_t>(record.name.size() + record.source_file.size() +
                           record.content_hash.size() + record.provenance.size() +
                           record.source_facts.format.size() + record.source_facts.up_axis.size());
  for (const std::string& tag : record.tags) bytes += static_cast<int64_t>(tag.size());
  return bytes;
}

// The records `query` (bound) selects, in its order; with `max_text_bytes` (> 0), only those
// whose text fits it (at least one), `*cut` set when a record was left out for it.
absl::StatusOr<std::vector<ClipRecord>> ReadClipRecords(SqliteConnection& db,
                                                        SqliteStatement& query,
                                                        int64_t max_text_bytes = 0,
                                                        bool* cut = nullptr) {
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement tags, PrepareTagQuery(db));
  std::vector<ClipRecord> records;
  int64_t text_bytes = 0;
  while (true) {
    MOTIONDB_ASSIGN_OR_RETURN(const bool row, query.Step());
    if (!row) return records;
    ClipRecord record = ReadClipRecord(query);
    MOTIONDB_ASSIGN_OR_RETURN(record.tags, LoadTags(tags, record.clip_id));
    text_bytes += TextBytes(record);
    if (max_text_bytes > 0 && text_bytes > max_text_bytes && !records.empty()) {
      if (cut != nullptr) *cut = true;
      return records;
    }
    records.push_back(std::move(record));
  }
}

// "SELECT <record columns> FROM clips c <rest>".
absl::StatusOr<SqliteStatement> PrepareClipRecordQuery(SqliteConnection& db,
                                                       absl::string_view rest) {
  return db.Prepare(absl::StrCat("SELECT ", kClipRecordColumns, " FROM clips c ", rest));
}

// The one record `query` (bound) selects; NOT_FOUND with `missing` when there is none.
absl::StatusOr<ClipRecord> ReadOneClipRecord(SqliteConnection& db, SqliteStatement& query,
                                             absl::string_view missing) {
  MOTIONDB_ASSIGN_OR_RETURN(std::vector<ClipRecord> records, ReadClipRecords(db, query));
  if (records.empty()) return absl::NotFoundError(missing);
  return std::move(records.front());
}

absl::StatusOr<ClipRecord> ClipRecordById(SqliteConnection& db, int64_t clip_id) {
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query,
                            PrepareClipRecordQuery(db, "WHERE c.clip_id = ?"));
  query.BindInt64(1, clip_id);
  return ReadOneClipRecord(db, query, absl::StrCat("clip ", clip_id, " not found"));
}

// Deletes the clip's row; its tags, projections and labels cascade.
absl::Status DeleteClipRow(SqliteConnection& db, int64_t clip_id, absl::string_view missing) {
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement erase,
                            db.Prepare("DELETE FROM clips WHERE clip_id = ?"));
  return DeleteRow(db, erase.BindInt64(1, clip_id), missing);
}

// Checks an update before its transaction; returns the tags to add, canonical.
absl::StatusOr<std::vector<std::string>> CheckClipUpdate(const ClipUpdate& update) {
  if (update.name) MOTIONDB_RETURN_IF_ERROR(CheckClipName(*update.name));
  MOTIONDB_ASSIGN_OR_RETURN(std::vector<std::string> add_tags,
                            CanonicalTags(update.add_tags, "add_tags"));
  for (size_t i = 0; i < update.remove_tags.size(); ++i) {
    const std::string& tag = update.remove_tags[i];
    if (tag.empty()) {
      return absl::InvalidArgumentError(absl::StrCat("remove_tags[", i, "] must not be empty"));
    }
    if (std::binary_search(add_tags.begin(), add_tags.end(), tag)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "remove_tags[", i, "] '", absl::CHexEscape(tag), "' is in add_tags too; give it once"));
    }
  }
  return add_tags;
}

// Inserts the new clip's projections, which must be one into every space of its skeleton (its
// own, or one over several that lists it).
absl::Status InsertProjectionsOfClip(
    SqliteConnection& db, int64_t clip_id, int64_t skeleton_id,
    const std::vector<std::pair<int64_t, Projection>>& projections) {
  // The spaces of this skeleton, each of which must receive the clip's projection.
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement spaces,
      db.Prepare("SELECT space_id, name, dims FROM spaces WHERE skeleton_id = ?1 OR space_id IN "
                 "(SELECT space_id FROM space_skeletons WHERE skeleton_id = ?1)"));
  spaces.BindInt64(1, skeleton_id);
  absl::flat_hash_map<int64_t, std::pair<std::string, int>> needed;
  while (true) {
    MOTIONDB_ASSIGN_OR_RETURN(const bool row, spaces.Step());
    if (!row) break;
    needed[spaces.ColumnInt64(0)] = {spaces.ColumnText(1), static_cast<int>(spaces.ColumnInt64(2))};
  }
  MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement insert_projection, PrepareProjectionInsert(db));
  for (const auto& [space_id, projection] : projections) {
    const auto space = needed.find(space_id);
    if (space == needed.end()) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool exists,
                                Exists(db, "SELECT 1 FROM spaces WHERE space_id = ?", space_id));
      if (!exists) return absl::NotFoundError(absl::StrCat("space ", space_id, " not found"));
      return absl::FailedPreconditionError(
          absl::StrCat("space ", space_id, " belongs to another skeleton than the clip's"));
    }
    MOTIONDB_RETURN_IF_ERROR(CheckProjection(projection.coordinates, space->second.second,
                                             absl::StrCat("projection into space ", space_id)));
    MOTIONDB_RETURN_IF_ERROR(
        InsertProjection(insert_projection, space_id, clip_id, projection.coordinates));
    needed.erase(space);
  }
  if (!needed.empty()) {
    const auto& [space_id, space] = *needed.begin();
    return absl::FailedPreconditionError(absl::StrCat(
        "the clip has no projection into space ", space_id, " ('", space.first,
        "') of its skeleton; a clip is stored with its projection into every such space"));
  }
  return absl::OkStatus();
}

}  // namespace

std::string ClipPageToken(ClipOrder order, const ClipRecord& last) {
  // Id order keeps the plain decimal id of earlier servers; the others are "n.ID.BASE64(name)"
  // and "c.ID.MS", so that a token of one order is not read in another. Names may hold any
  // printable byte, hence the base64.
  switch (order) {
    case ClipOrder::kName:
      return absl::StrCat("n.", last.clip_id, ".", absl::WebSafeBase64Escape(last.name));
    case ClipOrder::kCreated:
      return absl::StrCat("c.", last.clip_id, ".", last.created_unix_ms);
    case ClipOrder::kId:
      break;
  }
  return absl::StrCat(last.clip_id);
}

absl::StatusOr<int64_t> Database::InsertClip(
    const ClipRecord& record, const Clip& clip,
    const std::vector<std::pair<int64_t, Projection>>& projections,
    const InsertClipOptions& options, const WriteOptions& write) {
  MOTIONDB_RETURN_IF_ERROR(CheckClipName(record.name));
  MOTIONDB_RETURN_IF_ERROR(
      CheckName("source file name", record.source_file, kMaxNameBytes, /*may_be_empty=*/true));
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<std::string> tags, CanonicalTags(record.tags));
  MOTIONDB_RETURN_IF_ERROR(CheckFloat32Range(clip.positions(), "clip position"));
  if (options.clip_id < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("clip id ", options.clip_id, ": a clip's id is positive"));
  }
  absl::flat_hash_set<int64_t> space_ids;
  for (const auto& [space_id, projection] : projections) {
    if (!space_ids.insert(space_id).second) {
      return absl::InvalidArgumentError(
          absl::StrCat("two projections of the clip into space ", space_id));
    }
    // The dimensions are checked against the stored space in InsertProjectionsOfClip.
    MOTIONDB_RETURN_IF_ERROR(CheckProjection(projection.coordinates, std::nullopt,
                                             absl::StrCat("projection into space ", space_id)));
  }
  // Encoded before the write lock, which other writers wait for; the rotations, the largest
  // blob, are never encoded whole: hashed in pieces here, converted again piece by piece under
  // the lock as they are written (a conversion costs far less than holding a second copy).
  const std::string key = TopologyKey(clip.skeleton());
  const std::string layout = SkeletonLayoutBlob(clip.skeleton());
  const std::string positions = Float32Blob(clip.positions());
  MOTIONDB_ASSIGN_OR_RETURN(const std::string content_hash, ContentHash(clip));
  const int64_t now = CreationTime(record.created_unix_ms);

  int64_t clip_id = 0;
  MOTIONDB_RETURN_IF_ERROR(impl_->Write(write, [&](SqliteConnection& db) -> absl::Status {
    if (options.replace_clip_id != 0) {
      MOTIONDB_RETURN_IF_ERROR(
          DeleteClipRow(db, options.replace_clip_id,
                        absl::StrCat("clip ", options.replace_clip_id, " to replace not found")));
    }
    MOTIONDB_RETURN_IF_ERROR(CheckNameFree(db, "clips", "clip", record.name));
    if (options.clip_id != 0) {
      MOTIONDB_ASSIGN_OR_RETURN(
          const bool taken, Exists(db, "SELECT 1 FROM clips WHERE clip_id = ?", options.clip_id));
      if (taken) {
        return absl::AlreadyExistsError(
            absl::StrCat("clip id ", options.clip_id, " is another clip's"));
      }
    }
    MOTIONDB_ASSIGN_OR_RETURN(const int64_t skeleton_id,
                              FindOrCreateSkeleton(db, clip.skeleton(), key, now));
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement insert,
        db.Prepare("INSERT INTO clips (clip_id, name, source_file, skeleton_id, frame_time, "
                   "frame_count, joint_count, position_joint_count, layout, rotations, positions, "
                   "created_unix_ms, content_hash, provenance) "
                   "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)"));
    // Left unbound, the id is NULL: SQLite's next.
    if (options.clip_id != 0) insert.BindInt64(1, options.clip_id);
    MOTIONDB_RETURN_IF_ERROR(insert.BindText(2, record.name)
                                 .BindText(3, record.source_file)
                                 .BindInt64(4, skeleton_id)
                                 .BindDouble(5, clip.frame_time())
                                 .BindInt64(6, clip.frame_count())
                                 .BindInt64(7, clip.skeleton().joint_count())
                                 .BindInt64(8, clip.skeleton().position_joint_count())
                                 .BindBlob(9, layout)
                                 .BindZeroBlob(10, clip.rotations().size() * sizeof(float))
                                 .BindBlob(11, positions)
                                 .BindInt64(12, now)
                                 .BindText(13, content_hash)
                                 .BindText(14, record.provenance)
                                 .Run());
    clip_id = db.last_insert_rowid();
    if (!record.source_facts.format.empty()) {
      MOTIONDB_ASSIGN_OR_RETURN(
          SqliteStatement source,
          db.Prepare("INSERT INTO clip_sources (clip_id, format, unit_m, up_axis) "
                     "VALUES (?, ?, ?, ?)"));
      MOTIONDB_RETURN_IF_ERROR(source.BindInt64(1, clip_id)
                                   .BindText(2, record.source_facts.format)
                                   .BindDouble(3, record.source_facts.unit_m)
                                   .BindText(4, record.source_facts.up_axis)
                                   .Run());
    }
    MOTIONDB_RETURN_IF_ERROR(WriteRotations(db, clip_id, clip.rotations()));
    MOTIONDB_RETURN_IF_ERROR(InsertTags(db, clip_id, tags));
    return InsertProjectionsOfClip(db, clip_id, skeleton_id, projections);
  }));
  return clip_id;
}

absl::StatusOr<int64_t> Database::FindSkeleton(const Skeleton& skeleton) {
  const std::string key = TopologyKey(skeleton);
  int64_t skeleton_id = -1;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement find,
        db.Prepare("SELECT skeleton_id FROM skeletons WHERE topology_key = ?"));
    MOTIONDB_ASSIGN_OR_RETURN(const bool found, find.BindText(1, key).Step());
    if (found) skeleton_id = find.ColumnInt64(0);
    return absl::OkStatus();
  }));
  return skeleton_id;
}

absl::StatusOr<std::vector<int64_t>> Database::ClipsOfSkeleton(int64_t skeleton_id) {
  std::vector<int64_t> clip_ids;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        const bool exists,
        Exists(db, "SELECT 1 FROM skeletons WHERE skeleton_id = ?", skeleton_id));
    if (!exists) return absl::NotFoundError(absl::StrCat("skeleton ", skeleton_id, " not found"));
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        db.Prepare("SELECT clip_id FROM clips WHERE skeleton_id = ? ORDER BY clip_id"));
    query.BindInt64(1, skeleton_id);
    while (true) {
      MOTIONDB_ASSIGN_OR_RETURN(const bool row, query.Step());
      if (!row) return absl::OkStatus();
      clip_ids.push_back(query.ColumnInt64(0));
    }
  }));
  return clip_ids;
}

absl::StatusOr<StoredClip> Database::GetClip(int64_t clip_id, std::optional<FrameRange> frames) {
  std::optional<StoredClip> result;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(result, ReadStoredClip(db, clip_id, frames));
    return absl::OkStatus();
  }));
  return *std::move(result);
}

absl::StatusOr<ClipRecord> Database::GetClipRecord(int64_t clip_id) {
  ClipRecord record;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(record, ClipRecordById(db, clip_id));
    return absl::OkStatus();
  }));
  return record;
}

absl::StatusOr<ClipRecord> Database::GetClipRecordByName(const std::string& name) {
  ClipRecord record;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query,
                              PrepareClipRecordQuery(db, "WHERE c.name = ?"));
    query.BindText(1, name);
    MOTIONDB_ASSIGN_OR_RETURN(
        record, ReadOneClipRecord(db, query,
                                  absl::StrCat("no clip is named '", absl::CHexEscape(name), "'")));
    return absl::OkStatus();
  }));
  return record;
}

absl::StatusOr<std::vector<ClipRecord>> Database::FindClipsByContentHash(
    const std::string& content_hash, int limit) {
  std::vector<ClipRecord> records;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(
        SqliteStatement query,
        PrepareClipRecordQuery(db, "WHERE c.content_hash = ? ORDER BY c.clip_id LIMIT ?"));
    query.BindText(1, content_hash).BindInt64(2, limit);
    MOTIONDB_ASSIGN_OR_RETURN(records, ReadClipRecords(db, query));
    return absl::OkStatus();
  }));
  return records;
}

absl::StatusOr<ClipRecord> Database::UpdateClip(int64_t clip_id, const ClipUpdate& update,
                                                const WriteOptions& write) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<std::string> add_tags, CheckClipUpdate(update));
  ClipRecord updated;
  MOTIONDB_RETURN_IF_ERROR(impl_->Write(write, [&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(const ClipRecord current, ClipRecordById(db, clip_id));
    if (update.name && *update.name != current.name) {
      MOTIONDB_RETURN_IF_ERROR(CheckNameFree(db, "clips", "clip", *update.name));
      MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement rename,
                                db.Prepare("UPDATE clips SET name = ? WHERE clip_id = ?"));
      MOTIONDB_RETURN_IF_ERROR(rename.BindText(1, *update.name).BindInt64(2, clip_id).Run());
    }
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement remove_tag,
                              db.Prepare("DELETE FROM clip_tags WHERE clip_id = ? AND tag = ?"));
    for (const std::string& tag : update.remove_tags) {
      remove_tag.Reset();
      MOTIONDB_RETURN_IF_ERROR(remove_tag.BindInt64(1, clip_id).BindText(2, tag).Run());
    }
    MOTIONDB_RETURN_IF_ERROR(InsertTags(db, clip_id, add_tags));
    MOTIONDB_ASSIGN_OR_RETURN(updated, ClipRecordById(db, clip_id));
    // Counted after the change: tags already carried do not count twice.
    if (updated.tags.size() > kMaxTags) {
      return absl::InvalidArgumentError(absl::StrCat("add_tags: a clip has at most ", kMaxTags,
                                                     " tags; this one would have ",
                                                     updated.tags.size()));
    }
    return absl::OkStatus();
  }));
  return updated;
}

absl::StatusOr<ClipPage> Database::ListClips(const Page& page, const std::string& tag) {
  return ListClips(page, ClipFilter{.tag = tag});
}

namespace {

// The filter's conditions on the clips `c`, after a WHERE: ?3 the tag, ?4 the name part, ?6 the
// descriptor, ?7 the skeleton ("1" for none, so that callers may always append AND ...).
std::string ClipFilterSql(const ClipFilter& filter) {
  std::string sql = "1";
  if (!filter.tag.empty()) {
    absl::StrAppend(&sql,
                    " AND EXISTS (SELECT 1 FROM clip_tags t WHERE t.clip_id = c.clip_id "
                    "AND t.tag = ?3)");
  }
  if (!filter.name_contains.empty()) absl::StrAppend(&sql, " AND instr(c.name, ?4) > 0");
  // labels_by_clip serves the lookup per clip; labels_by_descriptor would serve the other way.
  if (!filter.descriptor.empty()) {
    absl::StrAppend(&sql,
                    " AND EXISTS (SELECT 1 FROM labels l WHERE l.clip_id = c.clip_id "
                    "AND l.descriptor = ?6)");
  }
  if (filter.skeleton_id != 0) absl::StrAppend(&sql, " AND c.skeleton_id = ?7");
  return sql;
}

void BindClipFilter(const ClipFilter& filter, SqliteStatement& query) {
  if (!filter.tag.empty()) query.BindText(3, filter.tag);
  if (!filter.name_contains.empty()) query.BindText(4, filter.name_contains);
  if (!filter.descriptor.empty()) query.BindText(6, filter.descriptor);
  if (filter.skeleton_id != 0) query.BindInt64(7, filter.skeleton_id);
}

absl::Status CheckClipFilter(const ClipFilter& filter) {
  if (!filter.tag.empty()) MOTIONDB_RETURN_IF_ERROR(CheckName("tag", filter.tag, kMaxTagBytes));
  if (!filter.descriptor.empty()) {
    MOTIONDB_RETURN_IF_ERROR(CheckDescriptor("descriptor", filter.descriptor));
  }
  if (filter.max_text_bytes < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_text_bytes: ", filter.max_text_bytes, " is negative (0: no bound)"));
  }
  if (filter.skeleton_id < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("skeleton_id: ", filter.skeleton_id, " is negative (0: any skeleton)"));
  }
  return absl::OkStatus();
}

absl::StatusOr<int64_t> CountClips(SqliteConnection& db, const ClipFilter& filter) {
  MOTIONDB_ASSIGN_OR_RETURN(
      SqliteStatement count,
      db.Prepare(absl::StrCat("SELECT count(*) FROM clips c WHERE ", ClipFilterSql(filter))));
  BindClipFilter(filter, count);
  MOTIONDB_ASSIGN_OR_RETURN(const bool row, count.Step());
  return row ? count.ColumnInt64(0) : 0;
}

}  // namespace

absl::StatusOr<ClipPage> Database::ListClips(const Page& page, const ClipFilter& filter) {
  MOTIONDB_ASSIGN_OR_RETURN(const int page_size, CheckPageSize(page.page_size));
  MOTIONDB_ASSIGN_OR_RETURN(const PageStart start, ParsePageToken(filter.order, page.page_token));
  MOTIONDB_RETURN_IF_ERROR(CheckClipFilter(filter));

  // ?1 the last id, ?2 the limit, ?5 the last sort key, the filter's own (ClipFilterSql). The
  // id breaks ties of the key, so (key, id) orders every clip once.
  const absl::string_view key = filter.order == ClipOrder::kName      ? "c.name"
                                : filter.order == ClipOrder::kCreated ? "c.created_unix_ms"
                                                                      : "";
  const std::string sql = absl::StrCat(
      "SELECT ", kClipRecordColumns, " FROM clips c WHERE ",
      key.empty() ? "c.clip_id > ?1" : absl::StrCat("(", key, ", c.clip_id) > (?5, ?1)"), " AND ",
      ClipFilterSql(filter), " ORDER BY ", key.empty() ? "" : absl::StrCat(key, ", "),
      "c.clip_id LIMIT ?2");

  ClipPage result;
  MOTIONDB_RETURN_IF_ERROR(impl_->Read([&](SqliteConnection& db) -> absl::Status {
    MOTIONDB_ASSIGN_OR_RETURN(SqliteStatement query, db.Prepare(sql));
    // One row more than the page says whether another page follows.
    query.BindInt64(1, start.clip_id).BindInt64(2, page_size + 1);
    BindClipFilter(filter, query);
    if (filter.order == ClipOrder::kName) query.BindText(5, start.key);
    if (filter.order == ClipOrder::kCreated) {
      // The first page starts below every time; a later one after the token's.
      int64_t after_ms = std::numeric_limits<int64_t>::min();
      if (!start.key.empty() && !absl::SimpleAtoi(start.key, &after_ms)) {
        return absl::InvalidArgumentError("malformed page_token");
      }
      query.BindInt64(5, after_ms);
    }
    bool cut = false;
    MOTIONDB_ASSIGN_OR_RETURN(result.clips,
                              ReadClipRecords(db, query, filter.max_text_bytes, &cut));
    if (static_cast<int>(result.clips.size()) > page_size) {
      result.clips.pop_back();
      cut = true;
    }
    if (cut) result.next_page_token = ClipPageToken(filter.order, result.clips.back());
    // In the same read transaction: the total agrees with the page.
    MOTIONDB_ASSIGN_OR_RETURN(result.total_size, CountClips(db, filter));
    return absl::OkStatus();
  }));
  return result;
}

absl::Status Database::DeleteClip(int64_t clip_id, const WriteOptions& write) {
  return impl_->Write(write, [&](SqliteConnection& db) -> absl::Status {
    return DeleteClipRow(db, clip_id, absl::StrCat("clip ", clip_id, " not found"));
  });
}

}  // namespace motiondb::storage
