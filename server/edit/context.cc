#include "server/edit/context.h"

#include <algorithm>
#include <limits>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "core/bvh/bvh_writer.h"
#include "core/motion/resample.h"
#include "server/clip_export.h"
#include "server/selected_frames.h"
#include "server/space_lookup.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::server {

absl::Status EditStopped() {
  return absl::CancelledError("the operator was stopped by its caller");
}

absl::Status CheckEditStop(const std::function<bool()>& should_stop) {
  return should_stop && should_stop() ? EditStopped() : absl::OkStatus();
}

absl::StatusOr<EditSource> LoadSource(storage::Database& database, const SpaceSnapshot& snapshot,
                                      const ClipSelection& selection, absl::string_view field,
                                      const std::function<bool()>& should_stop) {
  // Reading the range is one step (the take's whole blob, up to seconds): not begun once stopped.
  MOTIONDB_RETURN_IF_ERROR(CheckEditStop(should_stop));
  MOTIONDB_RETURN_IF_ERROR(
      Prefixed(field, CheckClipInSpace(database, snapshot, selection.clip_id)));
  MOTIONDB_ASSIGN_OR_RETURN(const SelectedFrames selected,
                            ReadSelectedFrames(database, selection, field));
  EditSource source;
  source.range.clip_id = selection.clip_id;
  source.range.frames = selected.frames;
  source.clip_name = selected.record.name;
  source.fps = selected.clip.fps();
  source.skeleton = selected.clip.shared_skeleton();
  MOTIONDB_RETURN_IF_ERROR(CheckEditStop(should_stop));
  MOTIONDB_ASSIGN_OR_RETURN(source.motion, EnterSpace(*snapshot.space, selected.clip, should_stop));
  return source;
}

absl::StatusOr<SourceShape> ShapeOf(storage::Database& database, const SpaceSnapshot& snapshot,
                                    const ClipSelection& selection, absl::string_view field) {
  MOTIONDB_RETURN_IF_ERROR(
      Prefixed(field, CheckClipInSpace(database, snapshot, selection.clip_id)));
  MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipLayout layout,
                            database.GetClipLayout(selection.clip_id));
  SourceShape shape;
  shape.skeleton = layout.skeleton;
  shape.fps = 1.0 / layout.record.frame_time;
  MOTIONDB_ASSIGN_OR_RETURN(
      shape.frames,
      ResolveFrameRange(selection, static_cast<int>(layout.record.frame_count), field));
  shape.space_frames = ResampledFrameCount(shape.frames.size(), layout.record.frame_time,
                                           snapshot.space->sample_rate());
  return shape;
}

absl::Status CheckEditAnswer(const EditContext& context, const MotionSpace& space,
                             const SourceShape& like, const EditAnswer& answer,
                             const EditOutput& output, absl::string_view remedy) {
  // FinishEdit's resampling from the space's rate to the source's.
  const int64_t frames = ResampledFrameCount(
      static_cast<int>(std::min<int64_t>(answer.space_frames, std::numeric_limits<int>::max())),
      1.0 / space.sample_rate(), like.fps);
  int64_t bytes = answer.results * BvhFieldBytes(*like.skeleton, frames) + answer.extra_bytes +
                  kAnswerFixedBytes;
  if (!output.store_name.empty()) {
    bytes += answer.sources * kClipRangeBytes +
             TextFieldBytes(static_cast<int64_t>(output.parameters_json.size()));
  }
  return context.answers.Check(
      bytes,
      absl::StrCat("the answer (", answer.results == 1 ? "a BVH" : "two BVHs", " of ", frames,
                   " frames at ", like.fps, " fps)"),
      remedy);
}

absl::StatusOr<EditPose> PoseOf(const MotionSpace& space, const EditSource& source) {
  const SpaceMotion& motion = source.motion;
  EditPose pose;
  if (motion.coordinates.rows() == 1) {
    pose.coordinates = motion.coordinates;
    pose.rotations = motion.rotations;
    pose.placement = motion.placement;
    return pose;
  }
  pose.coordinates = motion.coordinates.colwise().mean();
  MOTIONDB_ASSIGN_OR_RETURN(pose.rotations, space.Reconstruct(pose.coordinates));
  const int frames = static_cast<int>(motion.coordinates.rows());
  std::vector<PlacementFrame> sources;
  for (int f = 0; f < frames; ++f) sources.push_back({&motion.placement, f});
  pose.placement = EmptyPlacement(motion.placement, 1);
  MixPlacementFrame(sources, std::vector<double>(frames, 1.0 / frames), &pose.placement, 0);
  return pose;
}

absl::StatusOr<EditResult> FinishEdit(const EditContext& context, const MotionSpace& space,
                                      const EditSource& like, const EditedMotion& motion,
                                      Provenance provenance, const EditOutput& output,
                                      const std::function<bool()>& should_stop) {
  MOTIONDB_RETURN_IF_ERROR(CheckEditStop(should_stop));
  MOTIONDB_ASSIGN_OR_RETURN(
      const Clip at_space_rate,
      ToClip(space, like.skeleton, PlaceRotations(space, motion.rotations, motion.placement),
             motion.placement));
  MOTIONDB_RETURN_IF_ERROR(CheckEditStop(should_stop));
  MOTIONDB_ASSIGN_OR_RETURN(const Clip clip,
                            Resample(at_space_rate, like.fps, kBvhAnswerThreads, should_stop));
  EditResult result;
  MOTIONDB_ASSIGN_OR_RETURN(result.bvh,
                            WriteBvh(clip, std::nullopt, kBvhAnswerThreads, should_stop));
  MOTIONDB_RETURN_IF_ERROR(CheckEditStop(should_stop));
  result.frames = clip.frame_count();
  result.fps = clip.fps();
  const std::string stem = output.store_name.empty() ? like.clip_name : output.store_name;
  result.file_name = absl::StrCat(absl::StrReplaceAll(stem, {{"/", "_"}, {"\\", "_"}}), "_",
                                  provenance.op, ".bvh");
  if (output.store_name.empty()) return result;
  storage::ClipRecord record;
  record.name = output.store_name;
  record.source_file = result.file_name;
  record.tags = output.store_tags;
  provenance.parameters_json = output.parameters_json;
  record.provenance = ProvenanceJson(provenance);
  absl::StatusOr<IngestedClip> stored = context.catalog.IngestClip(
      record, clip, {.on_conflict = OnConflict::kError, .clip_id = 0}, should_stop);
  if (!stored.ok()) {
    // The catalogue names a bad tag "tags[i]" ("tags[0] must not be empty"); whatever else it
    // refuses is about the name.
    const absl::Status& status = stored.status();
    if (!absl::StartsWith(status.message(), "tags")) return Prefixed("output.store_name", status);
    return absl::Status(status.code(), absl::StrCat("output.store_", status.message()));
  }
  result.stored = std::move(stored->record);
  return result;
}

}  // namespace motiondb::server
