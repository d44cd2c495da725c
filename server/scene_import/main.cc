// motiondb-scene-import --format fbx|gltf|glb --max-clip-bytes N --max-memory-mb M
//
// Reads one FBX or glTF file from standard input (ReadScene) and writes to standard output:
//   motiondb-scene-import 1
//   fact unit_m 0.01          (and `fact up_axis Z`, `fact generator TEXT`)
//   warning TEXT
//   take NAME_BYTES BVH_BYTES   followed by the take's name and its BVH text, for each take
//   end
// or, when the file cannot be read, `error CODE TEXT` (CODE an absl::StatusCode) and exit 1.
// Texts are one line each. It limits its own address space first: what assimp allocates for a
// hostile file ends this process, not the server that runs it.
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <iterator>
#include <new>
#include <string>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "core/bvh/bvh_writer.h"
#include "core/scene/scene_reader.h"

namespace {

std::string OneLine(absl::string_view text) {
  return absl::StrReplaceAll(text, {{"\n", " "}, {"\r", " "}});
}

int Fail(const absl::Status& status) {
  std::cout << "error " << static_cast<int>(status.code()) << " " << OneLine(status.message())
            << "\n";
  std::cout.flush();
  return 1;
}

absl::Status Run(motiondb::MotionFileFormat format, const motiondb::SceneReadOptions& options) {
  std::string bytes(std::istreambuf_iterator<char>(std::cin), {});
  auto scene = motiondb::ReadScene(bytes, format, options);
  if (!scene.ok()) return scene.status();
  std::string().swap(bytes);
  std::cout << "motiondb-scene-import 1\n"
            << "fact unit_m " << absl::StrCat(scene->facts.unit_m) << "\n"
            << "fact up_axis " << scene->facts.up_axis << "\n";
  if (!scene->facts.generator.empty()) {
    std::cout << "fact generator " << OneLine(scene->facts.generator) << "\n";
  }
  for (const std::string& warning : scene->warnings) {
    std::cout << "warning " << OneLine(warning) << "\n";
  }
  for (const motiondb::SceneTake& take : scene->takes) {
    auto bvh = motiondb::WriteBvh(take.clip);
    if (!bvh.ok()) return bvh.status();
    std::cout << "take " << take.name.size() << " " << bvh->size() << "\n" << take.name << *bvh;
  }
  std::cout << "end\n";
  std::cout.flush();
  return std::cout ? absl::OkStatus() : absl::UnavailableError("standard output was closed");
}

}  // namespace

int main(int argc, char** argv) {
  std::ios::sync_with_stdio(false);
  motiondb::MotionFileFormat format = motiondb::MotionFileFormat::kBvh;  // kBvh: none given
  bool usable = argc % 2 == 1;
  motiondb::SceneReadOptions options;
  int64_t max_memory_mb = 0;
  for (int i = 1; i + 1 < argc; i += 2) {
    const absl::string_view flag = argv[i];
    const absl::string_view value = argv[i + 1];
    if (flag == "--format") {
      for (auto f : {motiondb::MotionFileFormat::kFbx, motiondb::MotionFileFormat::kGltf,
                     motiondb::MotionFileFormat::kGlb}) {
        if (value == motiondb::MotionFileFormatName(f)) format = f;
      }
    } else if (flag == "--max-clip-bytes") {
      usable &= absl::SimpleAtoi(value, &options.max_clip_bytes);
    } else if (flag == "--max-memory-mb") {
      usable &= absl::SimpleAtoi(value, &max_memory_mb);
    }
  }
  if (!usable || format == motiondb::MotionFileFormat::kBvh) {
    return Fail(absl::InvalidArgumentError(
        "usage: motiondb-scene-import --format fbx|gltf|glb [--max-clip-bytes N] "
        "[--max-memory-mb M]"));
  }
  const rlimit no_core{0, 0};
  setrlimit(RLIMIT_CORE, &no_core);
  // A sanitizer's shadow memory is terabytes of address space: such a build goes unlimited.
#if !defined(__SANITIZE_ADDRESS__) && !defined(MOTIONDB_SANITIZED)
  if (max_memory_mb > 0) {
    const rlim_t bytes = static_cast<rlim_t>(max_memory_mb) << 20;
    const rlimit memory{bytes, bytes};
    setrlimit(RLIMIT_AS, &memory);
  }
#endif
  try {
    if (absl::Status status = Run(format, options); !status.ok()) return Fail(status);
  } catch (const std::bad_alloc&) {
    return Fail(absl::ResourceExhaustedError(
        absl::StrCat("reading the file needs more than ", max_memory_mb, " MiB")));
  }
  return 0;
}
