// FBX and glTF files made from BVH takes by Debian's Blender, as a studio's tools make them:
// `blender -b` runs tests/scene/bvh_to_scene.py. Tests and benchmarks share it; what needs
// Blender skips, saying so, when it is absent.
#ifndef MOTIONDB_TESTING_BLENDER_SCENE_FILES_H_
#define MOTIONDB_TESTING_BLENDER_SCENE_FILES_H_

#include <filesystem>
#include <string>
#include <vector>

#include "absl/status/status.h"

namespace motiondb::testing {

struct SceneFileRequest {
  // The first take's skeleton and motion; each further one (of the same skeleton) another take
  // of the FBX.
  std::vector<std::filesystem::path> takes;
  char up_axis = 'Y';               // 'Z': the FBX is written Z up
  std::string formats = "fbx,glb";  // of "fbx", "glb"
};

// Writes `base`.fbx and/or `base`.glb (Blender's output beside them, `base`.blender.log).
// UNAVAILABLE when Blender is not installed (its message is the skip's), INTERNAL with Blender's
// output when it fails.
absl::Status MakeSceneFiles(const SceneFileRequest& request, const std::filesystem::path& base);

// Why what needs Blender is skipped, or empty when it is installed.
std::string BlenderMissing();

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTING_BLENDER_SCENE_FILES_H_
