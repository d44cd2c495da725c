// What each member of a search's thread team (util/thread_team.h, SearchParams::threads) keeps
// for itself, so that no two threads share a stop poll or a warp's scratch.
#ifndef MOTIONDB_CORE_SEARCH_INTERNAL_MEMBER_STATE_H_
#define MOTIONDB_CORE_SEARCH_INTERNAL_MEMBER_STATE_H_

#include "core/search/warp/band_warp.h"
#include "core/search/warp/time_warp.h"
#include "util/stop_poll.h"

namespace motiondb {

struct MemberState {
  StopPoll stop;
  WarpWorkspace warps;
  BandWorkspace bands;
};

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_INTERNAL_MEMBER_STATE_H_
