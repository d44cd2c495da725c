// What the operators of EditService (issue 16, core/ops) share in the application: a stored
// clip range brought into a space, a pose taken from one (a frame, or the projected mean of a
// range, thesis 5.2), and a result turned into BVH with its source's hierarchy and channel
// orders at its source's frame rate, and, when asked, stored as a clip with its provenance.
#ifndef MOTIONDB_SERVER_EDIT_CONTEXT_H_
#define MOTIONDB_SERVER_EDIT_CONTEXT_H_

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/ops/space_motion.h"
#include "server/answer_limit.h"
#include "server/catalog.h"
#include "server/edit/provenance.h"
#include "server/frame_conversion.h"
#include "server/index_registry.h"
#include "server/search_runner.h"
#include "storage/database.h"

namespace motiondb::server {

// What an operator request says about its result besides its own parameters.
struct EditOutput {
  std::string store_name{};  // empty: the result is only returned
  std::vector<std::string> store_tags{};
  // The request's parameters, for the stored clip's provenance (empty without store_name).
  std::string parameters_json{};
};

struct EditResult {
  std::string bvh;
  std::string file_name;  // a suggestion: "<store name or source name>_<operator>.bvh"
  int frames = 0;
  double fps = 0;
  std::optional<storage::ClipRecord> stored;  // with store_name: the clip as stored
};

// A stored clip's range in a space.
struct EditSource {
  SourceRange range;  // at the clip's own rate
  std::string clip_name;
  double fps = 0;                            // the clip's own
  std::shared_ptr<const Skeleton> skeleton;  // the clip's own offsets and channels
  SpaceMotion motion;                        // at the space rate
};

// A pose of the space: its point, the pose rotations it encodes and its placement.
struct EditPose {
  RowMatrixXd coordinates;  // 1 x the space's dims
  RowMatrixXd rotations;    // 1 x 4 * joints
  Placement placement;      // 1 frame
};

// A result before it leaves the space: pose rotations (frames x 4 * joints) and placement at
// the space rate, exported with `like`'s skeleton at its rate.
struct EditedMotion {
  RowMatrixXd rotations;
  Placement placement;
};

// The services' shared handles; thread-safe as they are.
struct EditContext {
  storage::Database& database;
  Catalog& catalog;
  const IndexRegistry& registry;
  // The longest search query, in frames at a space's rate (--max-query-frames), which also
  // bounds the warp of an aligned overlap (FillGap).
  int max_query_frames = kDefaultMaxQueryFrames;
  AnswerLimit answers{};  // what an operator's answer may take (--max-answer-mb)
};

// A stored clip's range as an operator finds it, read without its frames: what the operator's
// answer is sized by before the work.
struct SourceShape {
  std::shared_ptr<const Skeleton> skeleton;  // the clip's own offsets and channels
  double fps = 0;                            // the clip's own
  FrameRange frames;                         // at the clip's rate
  int64_t space_frames = 0;                  // the range at the space's rate
};

// What an operator's answer holds, known before it runs: its BVH results of `space_frames`
// frames at the space's rate, exported like a source, and its own fields.
struct EditAnswer {
  int64_t space_frames = 0;
  int results = 1;          // BVH texts: Interpolate's other method's too
  int64_t sources = 1;      // clip ranges a stored clip's provenance names
  int64_t extra_bytes = 0;  // the operator's own fields (weights, steps, joints), at most
};

// Frames of a placement mixed (MixPlacementFrame) between two polls of a stop function: about
// a millisecond's.
inline constexpr int64_t kPlacementFramesPerStopPoll = 4096;

// CANCELLED: what an operator stopped by its caller returns.
absl::Status EditStopped();
// EditStopped() when `should_stop` says so: between the steps of an operator.
absl::Status CheckEditStop(const std::function<bool()>& should_stop);

// The selection's clip, range and motion in the space. NOT_FOUND for an unknown clip,
// FAILED_PRECONDITION for a clip of another skeleton (CheckClipInSpace), INVALID_ARGUMENT naming
// `field` for a range outside the clip. `should_stop` is asked as the range enters the space:
// CANCELLED once it says stop.
absl::StatusOr<EditSource> LoadSource(storage::Database& database, const SpaceSnapshot& snapshot,
                                      const ClipSelection& selection, absl::string_view field,
                                      const std::function<bool()>& should_stop = {});

// LoadSource's errors, from the clip's layout alone.
absl::StatusOr<SourceShape> ShapeOf(storage::Database& database, const SpaceSnapshot& snapshot,
                                    const ClipSelection& selection, absl::string_view field);

// OK when `answer`, its results exported like `like` (FinishEdit) and, with output.store_name,
// the stored clip and its provenance (output.parameters_json), fits context.answers; else
// RESOURCE_EXHAUSTED naming the limit, the frames and `remedy`.
absl::Status CheckEditAnswer(const EditContext& context, const MotionSpace& space,
                             const SourceShape& like, const EditAnswer& answer,
                             const EditOutput& output, absl::string_view remedy);

// The source's only frame, or the projected mean of its frames with the mean of their
// placements and the pose the mean unprojects to.
absl::StatusOr<EditPose> PoseOf(const MotionSpace& space, const EditSource& source);

// The BVH of `motion` placed and exported with `like`'s skeleton at its rate, stored as a clip
// when output.store_name is set (Catalog::IngestClip refusing a taken name; its errors name
// output.store_name or output.store_tags[i]). `provenance` names the operator and its sources.
// `should_stop` is asked between the steps and inside the long ones: CANCELLED once it says
// stop, before anything is stored.
absl::StatusOr<EditResult> FinishEdit(const EditContext& context, const MotionSpace& space,
                                      const EditSource& like, const EditedMotion& motion,
                                      Provenance provenance, const EditOutput& output,
                                      const std::function<bool()>& should_stop);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_EDIT_CONTEXT_H_
