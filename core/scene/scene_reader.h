// FBX and glTF files read through assimp: the skeleton and every animation (take) of a file, each
// a clip at the frame rate and length it was stored at.
//
// A file's skeleton is the smallest node tree that holds every animated node: its root is their
// lowest common ancestor, its joints the nodes on the way to an animated node, and a still leaf
// below a joint is that joint's end site. What lies above the root (an armature's transform, a
// unit scale) is folded into the root's motion, and a file whose up axis is not Y is turned Y up.
// Each joint keeps the file's own local rotation (its bone's rest orientation included, so that
// every file of one rig agrees; an FBX's nodes hold a pose, not always its bind pose) and its
// translation as the offset, in the file's units (SceneFacts): the world positions are the
// file's. Each joint gets rotation channels; the root, and a joint whose translation is
// animated, position channels too.
//
// Assimp parses files a client sent: the server calls this only in a child process
// (server/scene_import/), never in its own. Thread-safe: each call has its own importer.
#ifndef MOTIONDB_CORE_SCENE_SCENE_READER_H_
#define MOTIONDB_CORE_SCENE_SCENE_READER_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/motion/clip.h"
#include "core/scene/scene_format.h"

namespace motiondb {

struct SceneReadOptions {
  // Largest clip, in bytes of its rotations and positions as doubles, checked before it is
  // built: RESOURCE_EXHAUSTED beyond.
  int64_t max_clip_bytes = int64_t{1} << 30;
  // Most takes one file may hold; INVALID_ARGUMENT beyond.
  int max_takes = 1000;
};

struct SceneTake {
  std::string name;  // the animation's name, or "take_N" (from 1) when it has none
  Clip clip;
};

// What the file says of itself.
struct SceneFacts {
  MotionFileFormat format = MotionFileFormat::kFbx;
  double unit_m = 1.0;    // metres per unit of the clips' positions
  char up_axis = 'Y';     // the file's up axis ('X', 'Y' or 'Z'); the clips are turned Y up
  std::string generator;  // the tool that wrote the file, when it says
};

struct SceneReadResult {
  std::vector<SceneTake> takes;  // in the file's order; at least one
  SceneFacts facts;
  std::vector<std::string> warnings;  // what was read but not kept (animated scale, say)
};

// Reads `bytes`, a file of `format` (kFbx, kGltf or kGlb). INVALID_ARGUMENT, saying what is
// missing or wrong, for a file assimp cannot read or one without a skeletal animation (a mesh
// or a still scene). Several characters' hierarchies are read as one skeleton, with a warning.
absl::StatusOr<SceneReadResult> ReadScene(absl::string_view bytes, MotionFileFormat format,
                                          const SceneReadOptions& options = {});

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SCENE_SCENE_READER_H_
