// The database schema, as a list of migrations keyed by PRAGMA user_version: migration i
// (counting from 1) takes a file from version i - 1 to version i. A new schema version appends
// a migration to the list in schema.cc; existing ones never change.
#ifndef MOTIONDB_STORAGE_SCHEMA_H_
#define MOTIONDB_STORAGE_SCHEMA_H_

#include <cstdint>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "storage/sqlite_connection.h"

namespace motiondb::storage {

// PRAGMA application_id of a motiondb file: "MDB1".
inline constexpr int32_t kApplicationId = 0x4D444231;

// The schema version this build creates and reads: the number of migrations.
int LatestSchemaVersion();

// Checks that `connection`'s file is a motiondb database this build can read, without writing:
// FAILED_PRECONDITION for a newer schema version, another application's id, or an unversioned
// file that already holds tables (another application's database).
absl::Status CheckSchemaVersion(SqliteConnection& connection);

// Applies the missing migrations up to `target_version`, with the C++ backfills some of them
// need, and stamps the version and application id, all in one write transaction: a crash leaves
// the file at its old version, to be migrated again on the next open. A file at or past
// `target_version` is left as it is. Open() migrates to the latest version; tests make the
// files of older builds with a lower one.
absl::Status MigrateSchema(SqliteConnection& connection,
                           int target_version = LatestSchemaVersion());

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_SCHEMA_H_
