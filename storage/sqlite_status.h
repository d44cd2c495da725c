// Translation of SQLite result codes into absl::Status.
#ifndef MOTIONDB_STORAGE_SQLITE_STATUS_H_
#define MOTIONDB_STORAGE_SQLITE_STATUS_H_

#include <sqlite3.h>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace motiondb::storage {

// The status of the failed SQLite call that returned `rc` (an extended result code) on `db`
// (nullptr when there is no connection yet), prefixed with `context`, the operation. The
// message carries sqlite3_errmsg, so call it before anything else runs on `db`.
//
// BUSY/LOCKED (the busy timeout ran out) -> UNAVAILABLE; FULL, NOMEM, TOOBIG ->
// RESOURCE_EXHAUSTED; CORRUPT, NOTADB -> DATA_LOSS; UNIQUE -> ALREADY_EXISTS; FOREIGNKEY,
// READONLY, CANTOPEN -> FAILED_PRECONDITION; other constraints -> INVALID_ARGUMENT;
// INTERRUPT -> CANCELLED; anything else, I/O errors included, -> INTERNAL.
absl::Status SqliteStatus(sqlite3* db, int rc, absl::string_view context);

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_SQLITE_STATUS_H_
