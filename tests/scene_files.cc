#include "tests/scene_files.h"

#include <cstdlib>
#include <map>
#include <mutex>

#include "absl/strings/str_cat.h"
#include "tests/test_data.h"
#include "util/status_macros.h"

namespace motiondb::testing {
namespace {

std::string Quoted(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

}  // namespace

std::string BlenderMissing() {
  if (std::system("command -v blender >/dev/null 2>&1") == 0) return "";
  return "blender is not installed (scripts/packages-dev.txt installs it); skipped";
}

absl::Status MakeSceneFiles(const SceneFileRequest& request, const std::filesystem::path& base) {
  if (const std::string missing = BlenderMissing(); !missing.empty()) {
    return absl::UnavailableError(missing);
  }
  std::string command = absl::StrCat("blender -b --factory-startup --python ",
                                     Quoted(MOTIONDB_SCENE_SCRIPT), " -- ", Quoted(base.string()));
  for (const std::filesystem::path& take : request.takes) {
    absl::StrAppend(&command, " ", Quoted(take.string()));
  }
  absl::StrAppend(&command, " --up ", std::string(1, request.up_axis), " --formats ",
                  Quoted(request.formats));
  const std::filesystem::path log = base.string() + ".blender.log";
  absl::StrAppend(&command, " >", Quoted(log.string()), " 2>&1");
  const int status = std::system(command.c_str());
  const std::string output = ReadFileOrDie(log);
  // Blender exits 0 when a script raises; the files it should have written tell.
  for (const std::string format : {"fbx", "glb"}) {
    if (request.formats.find(format) == std::string::npos) continue;
    if (status != 0 || !std::filesystem::exists(absl::StrCat(base.string(), ".", format))) {
      return absl::InternalError(
          absl::StrCat("blender did not write the ", format, " file: ", command, "\n", output));
    }
  }
  return absl::OkStatus();
}

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
