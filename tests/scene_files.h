// The tests' FBX and glTF files, made once a process from Bandai takes by Debian's Blender
// (testing/blender_scene_files.h). Tests skip, saying so, when Blender is absent.
#ifndef MOTIONDB_TESTS_SCENE_FILES_H_
#define MOTIONDB_TESTS_SCENE_FILES_H_

#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include "absl/status/statusor.h"
#include "testing/blender_scene_files.h"

namespace motiondb::testing {

// The Bandai takes the files below are made from (../shared/mocap/bandai2-normal).
std::filesystem::path FirstTake();
std::filesystem::path SecondTake();

// A file made on first use in this process (ctest runs each test in a process of its own, and
// Blender takes about two seconds a file): "one.fbx" and "one.glb" (the first take), "two.fbx"
// (both takes), "zup.fbx" (the first, Z up), "mesh.fbx" and "mesh.glb" (a cube, no animation).
// UNAVAILABLE, its message the skip's, when Blender or the takes are absent.
absl::StatusOr<std::filesystem::path> BlenderFile(const std::string& name);

}  // namespace motiondb::testing

// A Blender-made file, or the test is skipped saying why.
#define MOTIONDB_BLENDER_FILE(variable, name)                    \
  const absl::StatusOr<std::filesystem::path> variable##_made =  \
      ::motiondb::testing::BlenderFile(name);                    \
  if (absl::IsUnavailable(variable##_made.status())) {           \
    GTEST_SKIP() << variable##_made.status().message();          \
  }                                                              \
  ASSERT_TRUE(variable##_made.ok()) << variable##_made.status(); \
  const std::filesystem::path& variable = *variable##_made

#endif  // MOTIONDB_TESTS_SCENE_FILES_H_
