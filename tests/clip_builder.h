// Builds small synthetic clips for tests: a skeleton and per-frame rotations from a function.
#ifndef MOTIONDB_TESTS_CLIP_BUILDER_H_
#define MOTIONDB_TESTS_CLIP_BUILDER_H_

#include <functional>
#include <memory>

#include "core/motion/clip.h"

namespace motiondb::testing {

// A chain root -> child -> leaf (with an End Site): the root has 6 channels in ZXY order, the
// child 3 channels in XYZ order, the leaf 3 channels in YZX order.
std::shared_ptr<const Skeleton> ChainSkeleton();

// A clip on `skeleton` whose joint j at frame f has rotation rotation(f, j) and whose joints
// with position channels sit at position(f, j).
Clip MakeClip(std::shared_ptr<const Skeleton> skeleton, int frames, double frame_time,
              const std::function<Quat(int frame, int joint)>& rotation,
              const std::function<Eigen::Vector3d(int frame, int joint)>& position);

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTS_CLIP_BUILDER_H_
