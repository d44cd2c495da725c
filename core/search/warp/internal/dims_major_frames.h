// Clip frames copied dims-major (all first coordinates, then all second ones, ...), so that the
// distances from one query frame to a run of consecutive clip frames are contiguous loops the
// compiler vectorises. The time warps fill their rows this way.
#ifndef MOTIONDB_CORE_SEARCH_WARP_INTERNAL_DIMS_MAJOR_FRAMES_H_
#define MOTIONDB_CORE_SEARCH_WARP_INTERNAL_DIMS_MAJOR_FRAMES_H_

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/index/coordinate_view.h"

namespace motiondb {

// out[k * span + o] = clip frame (first + direction * o), coordinate k, for o in [0, span).
inline void CopyDimsMajor(CoordinateView clip, int64_t first, int direction, int64_t span, int dims,
                          std::vector<float>& out) {
  out.resize(static_cast<size_t>(span) * dims);
  for (int64_t o = 0; o < span; ++o) {
    const float* x = clip.row(first + direction * o);
    for (int k = 0; k < dims; ++k) out[k * span + o] = x[k];
  }
}

// out[i] = distance from `q` to the copied frame at offset first + i, for i in [0, count).
inline void DistancesToCopied(const float* q, const std::vector<float>& frames, int64_t span,
                              int dims, int64_t first, int64_t count, float* out) {
  std::fill(out, out + count, 0.0f);
  for (int k = 0; k < dims; ++k) {
    const float* x = frames.data() + k * span + first;
    const float qk = q[k];
    for (int64_t i = 0; i < count; ++i) {
      const float d = qk - x[i];
      out[i] += d * d;
    }
  }
  for (int64_t i = 0; i < count; ++i) out[i] = std::sqrt(out[i]);
}

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_WARP_INTERNAL_DIMS_MAJOR_FRAMES_H_
