// The query frames a search anchors its warps at (thesis 6.2.1; several of them, 7.2.3): poses
// of maximal extension, found as the frames farthest from a neutral pose.
#ifndef MOTIONDB_CORE_SEARCH_CHARACTERISTIC_POINTS_H_
#define MOTIONDB_CORE_SEARCH_CHARACTERISTIC_POINTS_H_

#include <vector>

#include "core/index/coordinate_view.h"
#include "core/search/search_params.h"

namespace motiondb {

// The actions of a query (SearchParams::characteristic_points 0) are its runs of poses farther
// from its first and last poses' mean (where a take starts and ends at rest) than this share of
// the farthest, joined across dips shorter than kMinActionPauseS (a stride's or a wave's turn),
// the shortest pause between two actions. Measured on compound queries
// (bench/notes/2026-12-04-characteristic-points.md): 0.35 missed a shrug beside an arm raise (P@N
// 0.72 where points given one per action reach 0.91), 0.2 finds it; from the query's mean pose
// instead, half of a raise's frames lie far from it on either side and one action gave two points.
inline constexpr double kActionThreshold = 0.2;
inline constexpr double kMinActionPauseS = 0.3;

// The query frame farthest, over the first `dims` coordinates, from the neutral pose.
int FindCharacteristicFrame(CoordinateView query, int dims, NeutralPose neutral);

// `count` frames, increasing: the query cut into `count` parts of equal length (a frame each at
// least), in each the frame farthest from the whole query's neutral pose.
std::vector<int> FindCharacteristicFrames(CoordinateView query, int dims, NeutralPose neutral,
                                          int count);

// One frame per action of the query (see kActionThreshold), its farthest from the first and
// last poses' mean, increasing; at most kMaxCharacteristicPoints, the farthest kept, and at
// least one (a query without an action: its first frame). `rate`: the query's frames per
// second.
std::vector<int> FindActionFrames(CoordinateView query, int dims, double rate);

// The second anchor of a one-point search whose characteristic pose is common
// (SearchParams::second_anchor_scatter): the frame farthest from frame `anchor` over the first
// `dims` coordinates among those at least a quarter of the query (and 2 frames) away; -1 when
// the query is too short to have one.
int FindSecondAnchor(CoordinateView query, int anchor, int dims);

// The frames a search anchors at by SearchParams' rules: characteristic_frames, else
// characteristic_frame, else characteristic_points found (0: one per action,
// FindActionFrames). Assumes the parameters passed PrepareQuery's checks.
std::vector<int> CharacteristicFrames(CoordinateView query, double rate,
                                      const SearchParams& params);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_CHARACTERISTIC_POINTS_H_
