// A clip's poses for drawing it (ClipService.GetClipPoses): every joint's world position on
// every frame of the clip or a range of it, resampled down to a rate a viewer needs.
#ifndef MOTIONDB_SERVER_CLIP_POSES_H_
#define MOTIONDB_SERVER_CLIP_POSES_H_

#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "core/motion/matrix.h"
#include "server/answer_limit.h"
#include "server/frame_conversion.h"
#include "storage/database.h"

namespace motiondb::server {

// A viewer's frame rate: what a person sees of motion, and a quarter of a 120 Hz capture's data.
inline constexpr double kDefaultPoseRate = 30;

struct PosesRequest {
  ClipSelection clip;
  // At most this many frames a second; unset: kDefaultPoseRate; 0: the clip's own rate.
  std::optional<double> max_rate;
};

struct ClipPoses {
  int64_t clip_id = 0;
  std::vector<std::string> joint_names;
  std::vector<int> parents;  // -1 for the root
  double sample_rate = 0;    // of `positions`
  FrameRange frames;         // the range covered, at the clip's rate
  // frames x (3 * joints), world positions in the file's units (core/motion/forward_kinematics.h).
  RowMatrixXf positions;
};

// NOT_FOUND for an unknown clip; INVALID_ARGUMENT naming the field for a range outside the clip
// or a max_rate that is negative or not a number; RESOURCE_EXHAUSTED, before the frames are
// read, when the poses could exceed `answers` (frames after resampling x joints x 12 bytes).
absl::StatusOr<ClipPoses> ReadClipPoses(storage::Database& database, const PosesRequest& request,
                                        const AnswerLimit& answers);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_CLIP_POSES_H_
