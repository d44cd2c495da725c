#include "testing/corpus_paths.h"

#include <cstdlib>
#include <system_error>

namespace motiondb::testing {

std::filesystem::path MocapRoot() {
  if (const char* env = std::getenv("MOTIONDB_MOCAP_DIR"); env != nullptr && *env != '\0') {
    return env;
  }
  return MOTIONDB_MOCAP_DIR;
}

std::optional<std::filesystem::path> MocapDir() {
  const std::filesystem::path root = MocapRoot();
  std::error_code error;
  // An empty folder is a corpus not fetched (a mount point, a cleared checkout): absent too, so
  // that what needs it skips rather than fails on its first file.
  if (!std::filesystem::is_directory(root, error)) return std::nullopt;
  if (std::filesystem::is_empty(root, error) || error) return std::nullopt;
  return root;
}

}  // namespace motiondb::testing
