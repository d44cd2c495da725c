// Where the tests find their data: the shared mocap corpus, Debian's assimp-testmodels, the
// built CLI; and helpers to compare clips.
#ifndef MOTIONDB_TESTS_TEST_DATA_H_
#define MOTIONDB_TESTS_TEST_DATA_H_

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "testing/corpus_paths.h"  // MocapDir()

namespace motiondb::testing {

// Debian's assimp-testmodels BVH folder, or nullopt when the package is not installed.
std::optional<std::filesystem::path> AssimpBvhDir();
// The built motiondb CLI.
std::string CliPath();

struct CommandResult {
  int exit_code = -1;
  std::string out;  // standard output
  std::string err;  // standard error
};
// Runs the built CLI with `args` (each shell-quoted here) and captures its output.
CommandResult RunCli(const std::vector<std::string>& args);

// A self-signed certificate for localhost and 127.0.0.1, a day long, and its key: cert.pem and
// key.pem written into `dir` by the openssl command. NOT_FOUND when openssl is not installed
// (tests skip then), INTERNAL when it fails.
struct TlsFiles {
  std::string cert;
  std::string key;
};
absl::StatusOr<TlsFiles> MakeTlsCertificate(const std::filesystem::path& dir);

// Every *.bvh below `dir`, sorted.
// A new, empty folder below GoogleTest's temporary directory, named `prefix` and a unique
// suffix (mkdtemp): ctest runs tests in parallel, each in its own process, so a name built from
// the test or the pid alone can be shared by two of them or by a second checkout's run.
std::filesystem::path MakeTempDir(const std::string& prefix);

std::vector<std::filesystem::path> BvhFilesUnder(const std::filesystem::path& dir);
std::string ReadFileOrDie(const std::filesystem::path& path);

// The largest joint-rotation difference in radians (sign-invariant) between two clips of the
// same shape, and the largest difference of any joint's position channels relative to the
// larger magnitude.
double MaxRotationError(const Clip& a, const Clip& b);
double MaxRelativePositionError(const Clip& a, const Clip& b);

}  // namespace motiondb::testing

// Skips the current test with a message when the shared corpus is missing.
#define MOTIONDB_REQUIRE_MOCAP(dir_variable)                                          \
  const auto dir_variable##_optional = ::motiondb::testing::MocapDir();               \
  if (!dir_variable##_optional) GTEST_SKIP() << "../shared/mocap is absent; skipped"; \
  const std::filesystem::path dir_variable = *dir_variable##_optional

#endif  // MOTIONDB_TESTS_TEST_DATA_H_
