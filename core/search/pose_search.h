// A pose query (issue 12): one frame in, the library's nearest distinct places to it out, with
// no warp: "find this pose" for an asset browser. Search() answers a one-frame query so
// (core/search/internal/pose_search.h).
#ifndef MOTIONDB_CORE_SEARCH_POSE_SEARCH_H_
#define MOTIONDB_CORE_SEARCH_POSE_SEARCH_H_

namespace motiondb {

// Places held apart in time, in seconds: a pose held for a second gives at most two results.
inline constexpr double kPoseSeparationS = 0.5;

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_POSE_SEARCH_H_
