// Whole-file reads and atomic file writes, with errors that name the path.
//
// Pure functions; thread-safe (concurrent writers of one path race on the rename, last wins).
#ifndef MOTIONDB_UTIL_FILE_IO_H_
#define MOTIONDB_UTIL_FILE_IO_H_

#include <cstdint>
#include <fstream>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace motiondb {

// The file's bytes. NOT_FOUND when it cannot be opened, RESOURCE_EXHAUSTED over `max_bytes`.
absl::StatusOr<std::string> ReadFileBytes(const std::string& path, int64_t max_bytes);

// Writes `bytes` to `path` + ".tmp", then renames it into place, so that a reader never sees a
// half-written file.
absl::Status WriteFileAtomically(const std::string& path, absl::string_view bytes);

// WriteFileAtomically's file written piece by piece as the pieces arrive (a streamed download):
// into `path` + ".tmp", renamed into place by Commit(); destroyed uncommitted (a failed
// download), it removes the temporary file and leaves `path` as it was. Not thread-safe.
class AtomicFileWriter {
 public:
  explicit AtomicFileWriter(std::string path);
  ~AtomicFileWriter();
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;

  // The first error (creating, writing) is returned by every later call.
  absl::Status Append(absl::string_view bytes);
  absl::Status Commit();

 private:
  const std::string path_;
  const std::string temporary_;
  std::ofstream out_;
  absl::Status status_;
  bool committed_ = false;
};

}  // namespace motiondb

#endif  // MOTIONDB_UTIL_FILE_IO_H_
