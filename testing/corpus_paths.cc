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
  if (std::filesystem::is_directory(root, error)) return root;
  return std::nullopt;
}

}  // namespace motiondb::testing
