#include "server/space_curve.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "server/space_lookup.h"
#include "util/status_macros.h"
#include "util/stop_poll.h"

namespace motiondb::server {
namespace {

constexpr int kDefaultCurveDims = 3;  // the thesis's plots
// Products of a coordinate (a row's dims, times the space's with a learned metric) between two
// polls of a stop function: about a millisecond's.
constexpr int64_t kCurveProductsPerStopPoll = int64_t{1} << 18;

}  // namespace

absl::StatusOr<Curve> ReadCurve(const IndexRegistry& registry, storage::Database& database,
                                const CurveRequest& request, const AnswerLimit& answers,
                                const std::function<bool()>& should_stop) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> snapshot,
                            FindSpace(registry, request.space));
  const int64_t clip_id = request.clip.clip_id;
  MOTIONDB_RETURN_IF_ERROR(CheckClipInSpace(database, *snapshot, clip_id));
  const int space_dims = snapshot->space->dims();
  const int dims = request.dims.value_or(std::min(kDefaultCurveDims, space_dims));
  if (dims < 1 || dims > space_dims) {
    return absl::InvalidArgumentError(
        absl::StrCat("dims: ", dims, " is outside 1..", space_dims, " (the space's dimensions)"));
  }
  Curve curve;
  MOTIONDB_ASSIGN_OR_RETURN(
      curve.frames,
      ResolveFrameRange(request.clip, snapshot->clips.at(clip_id).frame_count, "clip"));
  const auto [first, last] = snapshot->Conversion(clip_id).ToSpace(curve.frames);
  MOTIONDB_RETURN_IF_ERROR(answers.Check(
      TextFieldBytes((last - first + 1) * dims * static_cast<int64_t>(sizeof(float))) +
          kAnswerFixedBytes,
      absl::StrCat("the curve of clip ", clip_id, "'s frames ", curve.frames.first, "..",
                   curve.frames.last, " in ", dims, " dimensions"),
      "ask for a range of the clip (clip.first_frame, clip.last_frame) or fewer dims"));
  const CoordinateView rows = snapshot->index->clip_coordinates(snapshot->index->FindClip(clip_id))
                                  .middle_rows(first, last - first + 1);
  // The index holds search coordinates: the projection multiplied by the metric's scales (then
  // by a learned metric's transform, when the space has one); a plot wants the projection.
  MOTIONDB_ASSIGN_OR_RETURN(const Eigen::VectorXd scales, snapshot->space->MetricScales(dims));
  const RowMatrixXd& learned_inverse = snapshot->space->search_transform_inverse();
  curve.coordinates.resize(rows.rows, dims);
  Eigen::RowVectorXd scaled(dims);
  StopPoll stop(should_stop, kCurveProductsPerStopPoll);
  for (int64_t r = 0; r < rows.rows; ++r) {
    if (stop.Done(learned_inverse.size() > 0 ? int64_t{space_dims} * dims : dims)) {
      return absl::CancelledError("reading the curve was stopped by its caller");
    }
    if (learned_inverse.size() > 0) {
      scaled = Eigen::Map<const Eigen::RowVectorXf>(rows.row(r), space_dims).cast<double>() *
               learned_inverse.leftCols(dims);
    } else {
      scaled = Eigen::Map<const Eigen::RowVectorXf>(rows.row(r), dims).cast<double>();
    }
    for (int d = 0; d < dims; ++d) {
      curve.coordinates(r, d) = scales[d] > 0 ? static_cast<float>(scaled[d] / scales[d]) : 0;
    }
  }
  curve.sample_rate = snapshot->space->sample_rate();
  return curve;
}

}  // namespace motiondb::server
