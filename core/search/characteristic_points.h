// The query frames a search anchors its warps at (thesis 6.2.1; several of them, 7.2.3): poses
// of maximal extension, found as the frames farthest from a neutral pose.
#ifndef MOTIONDB_CORE_SEARCH_CHARACTERISTIC_POINTS_H_
#define MOTIONDB_CORE_SEARCH_CHARACTERISTIC_POINTS_H_

#include <vector>

#include "core/index/coordinate_view.h"
#include "core/search/search_params.h"

namespace motiondb {

// The actions of a query (SearchParams::characteristic_points 0) are its runs of poses farther
// from the neutral pose than this share of the farthest, joined across shorter dips than
// kMinActionPauseS (a stride's or a wave's turn), the shortest pause between two actions.
inline constexpr double kActionThreshold = 0.35;
inline constexpr double kMinActionPauseS = 0.3;

// The query frame farthest, over the first `dims` coordinates, from the neutral pose.
int FindCharacteristicFrame(CoordinateView query, int dims, NeutralPose neutral);

// `count` frames, increasing: the query cut into `count` parts of equal length (a frame each at
// least), in each the frame farthest from the whole query's neutral pose.
std::vector<int> FindCharacteristicFrames(CoordinateView query, int dims, NeutralPose neutral,
                                          int count);

// One frame per action of the query, its farthest from the neutral pose (see kActionThreshold),
// increasing; at most kMaxCharacteristicPoints, the farthest kept. `rate`: the query's frames
// per second.
std::vector<int> FindActionFrames(CoordinateView query, int dims, NeutralPose neutral, double rate);

// The frames a search anchors at by SearchParams' rules: characteristic_frames, else
// characteristic_frame, else characteristic_points found (0: one per action,
// FindActionFrames). Assumes the parameters passed PrepareQuery's checks.
std::vector<int> CharacteristicFrames(CoordinateView query, double rate,
                                      const SearchParams& params);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_CHARACTERISTIC_POINTS_H_
