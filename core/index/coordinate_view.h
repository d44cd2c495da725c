// A read-only view of row-major float coordinates (one row per frame), possibly a block of a
// wider matrix: the index and the time warps read projections in place, without copies.
#ifndef MOTIONDB_CORE_INDEX_COORDINATE_VIEW_H_
#define MOTIONDB_CORE_INDEX_COORDINATE_VIEW_H_

#include <cstdint>

#include "core/motion/matrix.h"

namespace motiondb {

struct CoordinateView {
  const float* data = nullptr;
  int64_t rows = 0;
  int stride = 0;  // floats from one row to the next (>= the dimensions used)

  const float* row(int64_t i) const { return data + i * stride; }
  CoordinateView middle_rows(int64_t first, int64_t count) const {
    return {data + first * stride, count, stride};
  }
  static CoordinateView Of(const RowMatrixXf& m) {
    return {m.data(), m.rows(), static_cast<int>(m.cols())};
  }
};

// Euclidean distance over the first `dims` coordinates.
inline float Distance(const float* a, const float* b, int dims) {
  float sum = 0.0f;
  for (int k = 0; k < dims; ++k) {
    const float d = a[k] - b[k];
    sum += d * d;
  }
  return __builtin_sqrtf(sum);
}

}  // namespace motiondb

#endif  // MOTIONDB_CORE_INDEX_COORDINATE_VIEW_H_
