// Writes a clip, or a range of it, as glTF 2.0 (tinygltf), which three.js, Blender, Maya and
// every engine read: a node a joint (named as the joint, its offset as the node's translation,
// a leaf node where the joint has an End Site), a skin over them so that DCCs make an armature,
// and one animation of the joints' rotations and translations at the clip's frame times.
// Positions stay in the clip's units. Pure and thread-safe.
#ifndef MOTIONDB_CORE_GLTF_GLTF_WRITER_H_
#define MOTIONDB_CORE_GLTF_GLTF_WRITER_H_

#include <cstdint>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "core/motion/clip.h"

namespace motiondb {

struct GltfWriteOptions {
  bool binary = false;  // true: a .glb; false: a .gltf with its buffer embedded (base64)
  std::string name;     // the animation's name (and the asset's); empty: "motion"
  std::optional<FrameRange> range;  // default: the whole clip
};

// The file's bytes. OUT_OF_RANGE for a range outside the clip.
absl::StatusOr<std::string> WriteGltf(const Clip& clip, const GltfWriteOptions& options = {});

// At least the size of WriteGltf's file of `frames` frames of a clip of `skeleton`, either
// kind, with a name of `name_bytes`: what an answer holding it is checked against before it is
// written.
int64_t GltfBound(const Skeleton& skeleton, int64_t frames, int64_t name_bytes);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_GLTF_GLTF_WRITER_H_
