// The query frames a search anchors its warps at (thesis 6.2.1; several of them, 7.2.3): poses
// of maximal extension, found as the frames farthest from a neutral pose.
#ifndef MOTIONDB_CORE_SEARCH_CHARACTERISTIC_POINTS_H_
#define MOTIONDB_CORE_SEARCH_CHARACTERISTIC_POINTS_H_

#include <vector>

#include "core/index/coordinate_view.h"
#include "core/search/search_params.h"

namespace motiondb {

// Query seconds per characteristic point when SearchParams::characteristic_points is 0. A query
// of under twice this keeps the thesis's one point.
inline constexpr double kSecondsPerCharacteristicPoint = 3.0;

// The query frame farthest, over the first `dims` coordinates, from the neutral pose.
int FindCharacteristicFrame(CoordinateView query, int dims, NeutralPose neutral);

// `count` frames, increasing: the query cut into `count` parts of equal length (a frame each at
// least), in each the frame farthest from the whole query's neutral pose.
std::vector<int> FindCharacteristicFrames(CoordinateView query, int dims, NeutralPose neutral,
                                          int count);

// The frames a search anchors at by SearchParams' rules: characteristic_frames, else
// characteristic_frame, else characteristic_points found (0: one per
// kSecondsPerCharacteristicPoint at `rate`, the query's frames per second). Assumes the
// parameters passed PrepareQuery's checks.
std::vector<int> CharacteristicFrames(CoordinateView query, double rate,
                                      const SearchParams& params);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_CHARACTERISTIC_POINTS_H_
