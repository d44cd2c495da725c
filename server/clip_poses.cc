#include "server/clip_poses.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/motion/forward_kinematics.h"
#include "core/motion/resample.h"
#include "server/selected_frames.h"
#include "util/status_macros.h"

namespace motiondb::server {

absl::StatusOr<ClipPoses> ReadClipPoses(storage::Database& database, const PosesRequest& request,
                                        const AnswerLimit& answers) {
  const double max_rate = request.max_rate.value_or(kDefaultPoseRate);
  if (!(max_rate >= 0) || !std::isfinite(max_rate)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "max_rate: ", max_rate, " must be 0 (the clip's own rate) or a positive rate"));
  }
  // The answer's size from the clip's layout, before its frames are read.
  MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipLayout layout,
                            database.GetClipLayout(request.clip.clip_id));
  MOTIONDB_ASSIGN_OR_RETURN(
      const FrameRange span,
      ResolveFrameRange(request.clip, static_cast<int>(layout.record.frame_count), "clip"));
  const double fps = 1.0 / layout.record.frame_time;
  const int64_t frames = max_rate > 0 && max_rate < fps
                             ? ResampledFrameCount(span.size(), layout.record.frame_time, max_rate)
                             : span.size();
  MOTIONDB_RETURN_IF_ERROR(answers.Check(
      PosesAnswerBytes(*layout.skeleton, frames) + kAnswerFixedBytes,
      absl::StrCat("the poses of clip ", request.clip.clip_id, "'s frames ", span.first, "..",
                   span.last, " (", frames, " frames of ", layout.skeleton->joint_count(),
                   " joints)"),
      "ask for a range of the clip (clip.first_frame, clip.last_frame) or a lower max_rate"));
  MOTIONDB_ASSIGN_OR_RETURN(SelectedFrames selected,
                            ReadSelectedFrames(database, request.clip, "clip"));
  ClipPoses poses;
  poses.clip_id = request.clip.clip_id;
  poses.frames = selected.frames;
  Clip range = std::move(selected.clip);
  if (max_rate > 0 && max_rate < range.fps()) {
    MOTIONDB_ASSIGN_OR_RETURN(range, Resample(range, max_rate));
  }
  poses.sample_rate = range.fps();
  for (const Joint& joint : range.skeleton().joints()) {
    poses.joint_names.push_back(joint.name);
    poses.parents.push_back(joint.parent);
  }
  poses.positions = ForwardKinematics(range).cast<float>();
  return poses;
}

}  // namespace motiondb::server
