// Where the shared motion-capture corpus is: $MOTIONDB_MOCAP_DIR when set and not empty, else
// the build's MOTIONDB_MOCAP_DIR (../shared/mocap beside the checkout). Tests and benchmarks
// find it the same way.
#ifndef MOTIONDB_TESTING_CORPUS_PATHS_H_
#define MOTIONDB_TESTING_CORPUS_PATHS_H_

#include <filesystem>
#include <optional>

namespace motiondb::testing {

// The folder, whether or not it exists.
std::filesystem::path MocapRoot();
// The folder, or nullopt when it does not exist or is empty (callers skip, saying so).
std::optional<std::filesystem::path> MocapDir();

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTING_CORPUS_PATHS_H_
