#include "util/file_io.h"

#include <cstdio>
#include <fstream>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb {

absl::StatusOr<std::string> ReadFileBytes(const std::string& path, int64_t max_bytes) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return absl::NotFoundError(absl::StrCat(path, ": cannot open file"));
  const std::streamoff size = in.tellg();
  if (size < 0) return absl::InvalidArgumentError(absl::StrCat(path, ": cannot read file"));
  if (size > max_bytes) {
    return absl::ResourceExhaustedError(
        absl::StrCat(path, ": file is ", size, " bytes, over the limit of ", max_bytes));
  }
  std::string bytes(static_cast<size_t>(size), '\0');
  in.seekg(0);
  if (!in.read(bytes.data(), size)) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": cannot read file"));
  }
  return bytes;
}

AtomicFileWriter::AtomicFileWriter(std::string path)
    : path_(std::move(path)),
      temporary_(path_ + ".tmp"),
      out_(temporary_, std::ios::binary | std::ios::trunc) {
  if (!out_) status_ = absl::PermissionDeniedError(absl::StrCat(path_, ": cannot create file"));
}

AtomicFileWriter::~AtomicFileWriter() {
  if (committed_) return;
  out_.close();
  std::remove(temporary_.c_str());
}

absl::Status AtomicFileWriter::Append(absl::string_view bytes) {
  if (!status_.ok()) return status_;
  out_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out_) status_ = absl::DataLossError(absl::StrCat(path_, ": write failed"));
  return status_;
}

absl::Status AtomicFileWriter::Commit() {
  if (!status_.ok()) return status_;
  out_.close();
  if (!out_) return status_ = absl::DataLossError(absl::StrCat(path_, ": write failed"));
  if (std::rename(temporary_.c_str(), path_.c_str()) != 0) {
    return status_ = absl::PermissionDeniedError(absl::StrCat(path_, ": cannot rename into place"));
  }
  committed_ = true;
  return absl::OkStatus();
}

absl::Status WriteFileAtomically(const std::string& path, absl::string_view bytes) {
  AtomicFileWriter file(path);
  MOTIONDB_RETURN_IF_ERROR(file.Append(bytes));
  return file.Commit();
}

}  // namespace motiondb
