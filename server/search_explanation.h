// Why a hit scored as it did (issue 12): its pose distance along the warp path over every
// dimension of the space, split by joint, and how fast the hit plays against the query.
#ifndef MOTIONDB_SERVER_SEARCH_EXPLANATION_H_
#define MOTIONDB_SERVER_SEARCH_EXPLANATION_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/index/coordinate_view.h"
#include "core/space/motion_space.h"

namespace motiondb::server {

// The window over which SearchExplanation::max_speed is taken, in seconds.
inline constexpr double kSpeedWindowS = 0.25;

struct JointShare {
  std::string name;  // a joint's, or "yaw rate" / "root velocity" for those dimensions
  double share = 0;  // of the squared distance along the path; the shares sum to 1 (to 0
                     // when the hit is the query itself)
  double score = 0;  // share x full_score: the parts sum to full_score
};

struct SearchExplanation {
  std::vector<JointShare> joints;  // largest share first
  // The mean pose distance along the path over every dimension the coordinates hold: the
  // score's full-space counterpart (the score itself counts the first dtw_dims only).
  double full_score = 0;
  double mean_speed = 0;  // hit frames per query frame, first to last along the path
  double max_speed = 0;   // the most over any kSpeedWindowS of the query
};

// `query` and `clip`: search coordinates (core/space/search_coordinates.h) of `space` at its
// rate; `path[i]` is the clip row matched to query row i. In the metric's coordinates m, the
// basis B turns a difference into pose-vector numbers u = B m with |u| = |m| (B orthonormal),
// so the squared distance splits exactly by joint. In a space with a learned metric (whose
// distance does not split by joint) the differences are turned back into the space's own metric
// coordinates first: the split, and full_score, are of the space's own pose distance. Thread-safe.
absl::StatusOr<SearchExplanation> ExplainHit(const MotionSpace& space, CoordinateView query,
                                             CoordinateView clip, const std::vector<int64_t>& path);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_SEARCH_EXPLANATION_H_
