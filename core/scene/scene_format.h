// Which motion file a client sent, told from its first bytes rather than its name: a BVH text, an
// FBX (binary or ASCII) or a glTF (.gltf JSON or .glb binary). Pure.
#ifndef MOTIONDB_CORE_SCENE_SCENE_FORMAT_H_
#define MOTIONDB_CORE_SCENE_SCENE_FORMAT_H_

#include <optional>

#include "absl/strings/string_view.h"

namespace motiondb {

enum class MotionFileFormat { kBvh, kFbx, kGltf, kGlb };

// "bvh", "fbx", "gltf", "glb".
absl::string_view MotionFileFormatName(MotionFileFormat format);

// The format of a file beginning with `head` (its first kMotionFileHeadBytes bytes, or all of a
// shorter file); nullopt when it is none of them.
std::optional<MotionFileFormat> DetectMotionFileFormat(absl::string_view head);
inline constexpr int kMotionFileHeadBytes = 64;

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SCENE_SCENE_FORMAT_H_
