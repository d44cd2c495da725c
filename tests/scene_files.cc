#include "tests/scene_files.h"

#include <map>
#include <mutex>

#include "absl/strings/str_cat.h"
#include "tests/test_data.h"
#include "util/status_macros.h"

namespace motiondb::testing {
std::filesystem::path FirstTake() {
  return MocapRoot() / "bandai2-normal" / "dataset-2_raise-up-both-hands_normal_001.bvh";
}

std::filesystem::path SecondTake() {
  return MocapRoot() / "bandai2-normal" / "dataset-2_raise-up-both-hands_normal_002.bvh";
}

absl::StatusOr<std::filesystem::path> BlenderFile(const std::string& name) {
  static std::mutex mutex;
  static std::map<std::string, std::filesystem::path>* made = nullptr;
  static std::filesystem::path dir;
  const std::lock_guard<std::mutex> lock(mutex);
  if (made == nullptr) {
    made = new std::map<std::string, std::filesystem::path>;
    dir = MakeTempDir("blender_files");
  }
  if (const auto found = made->find(name); found != made->end()) return found->second;
  const std::filesystem::path path(name);
  const std::string stem = path.stem().string();
  const std::string format = path.extension().string().substr(1);
  SceneFileRequest request;
  request.formats = format;
  if (stem == "one") {
    request.takes = {FirstTake()};
  } else if (stem == "two") {
    request.takes = {FirstTake(), SecondTake()};
  } else if (stem == "zup") {
    request.takes = {FirstTake()};
    request.up_axis = 'Z';
  } else if (stem != "mesh") {
    return absl::InvalidArgumentError("no such test file: " + name);
  }
  if (!request.takes.empty() && !MocapDir()) {
    return absl::UnavailableError("../shared/mocap is absent; skipped");
  }
  MOTIONDB_RETURN_IF_ERROR(MakeSceneFiles(request, dir / stem));
  return (*made)[name] = dir / name;
}

}  // namespace motiondb::testing
