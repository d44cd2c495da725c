#include "core/ops/aligned_blend.h"

#include <algorithm>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/index/coordinate_view.h"
#include "core/ops/internal/op_checks.h"
#include "util/status_macros.h"
#include "util/stop_poll.h"

namespace motiondb {
namespace {

// Cells of the warp between two polls of a stop function, as the search's (its table's fresh
// pages cost more than its cells): a few milliseconds at most.
constexpr int64_t kWarpCellsPerStopPoll = int64_t{1} << 18;

absl::Status CheckOptions(const AlignedBlendOptions& options, Eigen::Index a_frames, int dims) {
  MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckBetween(
      "overlap_frames", options.overlap_frames, 1, std::min<double>(kMaxOverlapFrames, a_frames)));
  MOTIONDB_RETURN_IF_ERROR(
      ops_internal::CheckBetween("warp.slope_limit", options.warp.slope_limit, 1, kMaxSlopeLimit));
  return ops_internal::CheckBetween("warp.dims", options.warp.dims, 1, dims);
}

// The second clip's frame for each overlap frame: the warp's path, or frame for frame.
absl::StatusOr<std::vector<int64_t>> OverlapPath(const Eigen::Ref<const RowMatrixXd>& a_overlap,
                                                 const Eigen::Ref<const RowMatrixXd>& b,
                                                 const AlignedBlendOptions& options,
                                                 const std::function<bool()>& should_stop,
                                                 double* score) {
  const int overlap = options.overlap_frames;
  const int dims = options.warp.dims;
  if (!options.align) {
    if (b.rows() < overlap) {
      return absl::InvalidArgumentError(absl::StrCat("b: the second clip has ", b.rows(),
                                                     " frames, fewer than the ", overlap,
                                                     " of the overlap"));
    }
    std::vector<int64_t> path(overlap);
    double total = 0.0;
    for (int i = 0; i < overlap; ++i) {
      path[i] = i;
      total += (a_overlap.row(i).head(dims) - b.row(i).head(dims)).norm();
    }
    *score = total / overlap;
    return path;
  }
  const Eigen::Index reach = std::min<Eigen::Index>(
      b.rows(), static_cast<Eigen::Index>(options.warp.slope_limit) * overlap);
  const RowMatrixXf query = a_overlap.leftCols(dims).cast<float>();
  const RowMatrixXf clip = b.topRows(reach).leftCols(dims).cast<float>();
  WarpWorkspace workspace;
  StopPoll stop(should_stop, kWarpCellsPerStopPoll);
  const std::optional<Warp> warp =
      AnchoredWarp(CoordinateView::Of(query), CoordinateView::Of(clip), 0, 0, options.warp,
                   /*with_path=*/true, workspace, std::numeric_limits<float>::infinity(), &stop);
  if (stop.stopped()) return absl::CancelledError("the overlap's warp was stopped by its caller");
  if (!warp) {
    return absl::InvalidArgumentError(absl::StrCat(
        "b: the second clip (", b.rows(), " frames) is too short to align an overlap of ", overlap,
        " frames at slope limit ", options.warp.slope_limit));
  }
  *score = warp->score;
  return warp->path;
}

}  // namespace

absl::StatusOr<AlignedBlend> PlanAlignedBlend(const Eigen::Ref<const RowMatrixXd>& a,
                                              const Eigen::Ref<const RowMatrixXd>& b,
                                              const AlignedBlendOptions& options,
                                              const std::function<bool()>& should_stop) {
  const int dims = static_cast<int>(a.cols());
  MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckPoints("a", a, dims, 1, true));
  MOTIONDB_RETURN_IF_ERROR(ops_internal::CheckPoints("b", b, dims, 1, true));
  MOTIONDB_RETURN_IF_ERROR(CheckOptions(options, a.rows(), dims));
  const int overlap = options.overlap_frames;
  const int a_first = static_cast<int>(a.rows()) - overlap;
  AlignedBlend blend;
  MOTIONDB_ASSIGN_OR_RETURN(
      const std::vector<int64_t> path,
      OverlapPath(a.bottomRows(overlap), b, options, should_stop, &blend.warp_score));
  for (int f = 0; f < a_first; ++f) blend.frames.push_back({f, -1, 0.0});
  for (int i = 0; i < overlap; ++i) {
    const double ramp = static_cast<double>(i + 1) / (overlap + 1);
    blend.frames.push_back({a_first + i, static_cast<int>(path[i]), ramp});
  }
  for (int f = static_cast<int>(path.back()) + 1; f < b.rows(); ++f) {
    blend.frames.push_back({-1, f, 1.0});
  }
  return blend;
}

RowMatrixXd MixCurves(const std::vector<BlendFrame>& frames, const Eigen::Ref<const RowMatrixXd>& a,
                      const Eigen::Ref<const RowMatrixXd>& b) {
  RowMatrixXd mixed(frames.size(), a.cols());
  for (size_t k = 0; k < frames.size(); ++k) {
    const BlendFrame& frame = frames[k];
    mixed.row(k).setZero();
    if (frame.a >= 0) mixed.row(k) += (1.0 - frame.weight_b) * a.row(frame.a);
    if (frame.b >= 0) mixed.row(k) += frame.weight_b * b.row(frame.b);
  }
  return mixed;
}

}  // namespace motiondb
