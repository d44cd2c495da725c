#include "server/edit/pose_models.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/ops/pose_model_serialization.h"
#include "server/edit/internal/request_fields.h"
#include "server/space_lookup.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

absl::StatusOr<StoredPoseModel> Parsed(storage::PoseModelRecord record) {
  StoredPoseModel stored;
  MOTIONDB_ASSIGN_OR_RETURN(stored.model, ParsePoseModel(record.data));
  record.data.clear();
  stored.record = std::move(record);
  return stored;
}

// Space frame k of a range starting at clip frame `first` to the clip's frame.
int ClipFrame(int k, int first, const FrameRange& range, double fps, double rate) {
  return std::clamp(first + static_cast<int>(std::lround(k * fps / rate)), range.first, range.last);
}

}  // namespace

absl::StatusOr<StoredPoseModel> CreatePoseModel(const EditContext& context,
                                                const PoseModelRequest& request,
                                                const std::function<bool()>& should_stop) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> snapshot,
                            FindSpace(context.registry, request.space));
  if (request.examples.empty()) return absl::InvalidArgumentError("examples: no poses given");
  // The answer holds the model's request as its parameters.
  MOTIONDB_RETURN_IF_ERROR(context.answers.Check(
      TextFieldBytes(static_cast<int64_t>(request.parameters_json.size())) + kAnswerFixedBytes,
      "the model with its parameters", "give fewer examples, as longer ranges"));
  std::vector<RowMatrixXd> parts;
  std::vector<int> groups;  // each example range is a group for the threshold
  for (size_t i = 0; i < request.examples.size(); ++i) {
    MOTIONDB_ASSIGN_OR_RETURN(const EditSource source,
                              LoadSource(context.database, *snapshot, request.examples[i],
                                         absl::StrCat("examples[", i, "]"), should_stop));
    groups.insert(groups.end(), source.motion.coordinates.rows(), static_cast<int>(i));
    parts.push_back(source.motion.coordinates);
  }
  RowMatrixXd examples(groups.size(), snapshot->space->dims());
  Eigen::Index row = 0;
  for (const RowMatrixXd& part : parts) {
    examples.middleRows(row, part.rows()) = part;
    row += part.rows();
  }
  StoredPoseModel stored;
  MOTIONDB_ASSIGN_OR_RETURN(stored.model,
                            FitPoseModel(examples, request.options, groups, should_stop));
  stored.record.name = request.name;
  stored.record.space_id = snapshot->record.space_id;
  stored.record.space_name = snapshot->record.name;
  stored.record.data = SerializePoseModel(stored.model);
  stored.record.parameters_json = request.parameters_json;
  MOTIONDB_ASSIGN_OR_RETURN(stored.record.model_id,
                            context.database.InsertPoseModel(stored.record, {should_stop}));
  MOTIONDB_ASSIGN_OR_RETURN(storage::PoseModelRecord written,
                            context.database.GetPoseModel(request.name));
  return Parsed(std::move(written));
}

absl::StatusOr<std::vector<StoredPoseModel>> ListPoseModels(const EditContext& context,
                                                            const std::string& space) {
  int64_t space_id = 0;
  if (!space.empty()) {
    MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> snapshot,
                              FindSpace(context.registry, space));
    space_id = snapshot->record.space_id;
  }
  MOTIONDB_ASSIGN_OR_RETURN(std::vector<storage::PoseModelRecord> records,
                            context.database.ListPoseModels(space_id));
  std::vector<StoredPoseModel> models;
  for (storage::PoseModelRecord& record : records) {
    MOTIONDB_ASSIGN_OR_RETURN(StoredPoseModel model, Parsed(std::move(record)));
    models.push_back(std::move(model));
  }
  return models;
}

absl::Status DeletePoseModel(const EditContext& context, const std::string& name,
                             const std::function<bool()>& should_stop) {
  return context.database.DeletePoseModel(name, {should_stop});
}

namespace {

absl::StatusOr<DetectOutcome> Detect(const EditContext& context, const DetectRequest& request,
                                     const std::function<bool()>& should_stop) {
  if (request.model.empty()) return absl::InvalidArgumentError("model: a model name is required");
  MOTIONDB_ASSIGN_OR_RETURN(storage::PoseModelRecord record,
                            context.database.GetPoseModel(request.model));
  MOTIONDB_ASSIGN_OR_RETURN(const StoredPoseModel stored, Parsed(std::move(record)));
  MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> snapshot,
                            FindSpace(context.registry, stored.record.space_name));
  MOTIONDB_ASSIGN_OR_RETURN(const SourceShape shape,
                            ShapeOf(context.database, *snapshot, request.clip, "clip"));
  // The curve, a float32 a sample, and the intervals, at most one every other sample.
  const int64_t samples = shape.space_frames;
  MOTIONDB_RETURN_IF_ERROR(context.answers.Check(
      TextFieldBytes(samples * static_cast<int64_t>(sizeof(float))) +
          (samples + 1) / 2 * (6 * kNumberFieldBytes + kFieldFramingBytes) + kAnswerFixedBytes,
      absl::StrCat("the detection over clip ", request.clip.clip_id, "'s frames ",
                   shape.frames.first, "..", shape.frames.last, " (", samples, " samples)"),
      "ask for a shorter range of the clip"));
  MOTIONDB_ASSIGN_OR_RETURN(const EditSource source, LoadSource(context.database, *snapshot,
                                                                request.clip, "clip", should_stop));
  const double rate = snapshot->space->sample_rate();
  MOTIONDB_RETURN_IF_ERROR(
      CheckDuration("min_duration_s", request.min_duration_s, true, kMaxMinFrames, rate));
  DetectionOptions options;
  options.threshold = request.threshold;
  options.min_frames = std::max(1, static_cast<int>(std::ceil(request.min_duration_s * rate)));
  MOTIONDB_ASSIGN_OR_RETURN(
      Detection detection,
      motiondb::DetectPose(stored.model, source.motion.coordinates, options, should_stop));
  DetectOutcome outcome;
  outcome.space = stored.record.space_name;
  outcome.frames = source.range.frames;
  outcome.sample_rate = rate;
  outcome.threshold = detection.threshold;
  outcome.log_likelihood = std::move(detection.log_likelihood);
  const int first = outcome.frames.first;
  for (const DetectedInterval& interval : detection.intervals) {
    DetectedRange range;
    range.first_frame = ClipFrame(interval.first, first, outcome.frames, source.fps, rate);
    range.last_frame = ClipFrame(interval.last, first, outcome.frames, source.fps, rate);
    range.peak_frame = ClipFrame(interval.peak_frame, first, outcome.frames, source.fps, rate);
    range.start_s = range.first_frame / source.fps;
    range.end_s = range.last_frame / source.fps;
    range.peak = interval.peak;
    outcome.intervals.push_back(range);
  }
  return outcome;
}

}  // namespace

absl::StatusOr<DetectOutcome> DetectPose(const EditContext& context, const DetectRequest& request,
                                         const std::function<bool()>& should_stop) {
  // The operator scores the clip's range as a curve; min_duration_s is checked before it
  // becomes the operator's min_frames.
  return InRequestFields(Detect(context, request, should_stop), {{"curve", "clip"}});
}

}  // namespace motiondb::server
