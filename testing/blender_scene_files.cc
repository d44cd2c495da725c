#include "testing/blender_scene_files.h"

#include <cstdlib>

#include "absl/strings/str_cat.h"
#include "util/file_io.h"

namespace motiondb::testing {
namespace {

std::string Quoted(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

// Blender's log, shown when it failed: its last lines say why. A runaway log (over 1 MiB) is
// not shown; the error in its place says how large it is.
std::string BlenderLog(const std::filesystem::path& path) {
  const absl::StatusOr<std::string> log = ReadFileBytes(path.string(), int64_t{1} << 20);
  return log.ok() ? *log : log.status().ToString();
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
  // Blender exits 0 when a script raises; the files it should have written tell.
  for (const std::string format : {"fbx", "glb"}) {
    if (request.formats.find(format) == std::string::npos) continue;
    if (status != 0 || !std::filesystem::exists(absl::StrCat(base.string(), ".", format))) {
      return absl::InternalError(absl::StrCat("blender did not write the ", format,
                                              " file: ", command, "\n", BlenderLog(log)));
    }
  }
  return absl::OkStatus();
}

}  // namespace motiondb::testing
