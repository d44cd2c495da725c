// The rate, about 15 Hz, at which the fast search finds and warps its seeds: adjacent frames of
// a held pose are near duplicates that take the seed budget (at 120 Hz, 1000 nearest frames
// piled up in 9 of 75 instances), and a warp's cells grow with the square of the rate, while
// refinement settles the kept candidates at the full rate anyway. Measured
// (bench/notes/2026-12-02-scale-seeds.md; recall@10 against the exact search): 15 Hz against 30 Hz
// gave 0.98 against 0.90 on Bandai and 1.0 against 0.95 at 1 h, the same 0.95 at 10 h, in about the
// same time.
#ifndef MOTIONDB_CORE_INDEX_COARSE_RATE_H_
#define MOTIONDB_CORE_INDEX_COARSE_RATE_H_

#include <algorithm>
#include <cmath>

namespace motiondb {

inline constexpr double kCoarseRate = 15.0;

// Library frames per coarse frame at `rate` frames per second: the n that brings rate / n
// nearest 15 Hz (1 below 22.5 Hz, 2 at 30 Hz, 8 at 120 Hz).
inline int CoarseFactor(double rate) {
  return std::max(1, static_cast<int>(std::lround(rate / kCoarseRate)));
}

}  // namespace motiondb

#endif  // MOTIONDB_CORE_INDEX_COARSE_RATE_H_
