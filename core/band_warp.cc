#include "core/band_warp.h"

#include <algorithm>
#include <limits>

#include "core/dims_major_frames.h"
#include "core/vector_clones.h"

namespace motiondb {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

}  // namespace

// Row i's cells are the clip frames row_first[i] + k, k in [0, width), stored state-major with
// s infinite cells of padding on both sides, so that no step needs a bounds check:
// cost[(i * s + z) * padded + s + k]. Frames outside the clip are infinite. As the centre
// advances 0..s frames per row, so does the band: a step of `advance` from the previous row's
// cell k + shift - advance lands on cell k (shift: how far the band moved), a pause from k + shift.
MOTIONDB_VECTOR_CLONES Warp BandWarp(CoordinateView query, CoordinateView clip,
                                     const std::vector<int64_t>& centre, int radius,
                                     const WarpConstraints& constraints, BandWorkspace& ws,
                                     bool* touches_edge) {
  const int s = constraints.slope_limit;
  const int64_t m = query.rows, width = 2 * radius + 1, padded = width + 2 * s;
  ws.row_first.resize(m);
  for (int64_t i = 0; i < m; ++i) ws.row_first[i] = centre[i] - radius;
  // Every band cell is written below; only the padding, and row 0's pause states, start infinite.
  ws.cost.resize(m * s * padded);
  for (int64_t row = 0; row < m * s; ++row) {
    float* cells = ws.cost.data() + row * padded;
    std::fill(cells, cells + s, kInfinity);
    std::fill(cells + s + width, cells + padded, kInfinity);
  }
  ws.best_of_cell.assign(padded, kInfinity);
  ws.distances.resize(width);
  const auto cell = [&](int64_t i, int z) { return ws.cost.data() + (i * s + z) * padded + s; };
  // The clip frames the band covers, copied dims-major.
  const int64_t span_first = std::max<int64_t>(0, ws.row_first[0]);
  const int64_t span_last = std::min<int64_t>(clip.rows - 1, ws.row_first[m - 1] + width - 1);
  const int64_t span = span_last - span_first + 1;
  CopyDimsMajor(clip, span_first, 1, span, constraints.dims, ws.frames);
  const auto row_distances = [&](int64_t i) {
    // Cells [lo, hi) lie inside the clip.
    const int64_t lo = std::clamp<int64_t>(span_first - ws.row_first[i], 0, width);
    const int64_t hi = std::clamp<int64_t>(span_last + 1 - ws.row_first[i], lo, width);
    std::fill(ws.distances.begin(), ws.distances.begin() + lo, kInfinity);
    std::fill(ws.distances.begin() + hi, ws.distances.end(), kInfinity);
    DistancesToCopied(query.row(i), ws.frames, span, constraints.dims,
                      ws.row_first[i] + lo - span_first, hi - lo, ws.distances.data() + lo);
  };

  row_distances(0);
  std::copy(ws.distances.begin(), ws.distances.end(), cell(0, 0));
  for (int z = 1; z < s; ++z) std::fill(cell(0, z), cell(0, z) + width, kInfinity);
  float* best = ws.best_of_cell.data() + s;
  for (int64_t i = 1; i < m; ++i) {
    const int64_t shift = ws.row_first[i] - ws.row_first[i - 1];
    std::copy(cell(i - 1, 0), cell(i - 1, 0) + width, best);
    for (int z = 1; z < s; ++z) {
      const float* state = cell(i - 1, z);
      for (int64_t k = 0; k < width; ++k) best[k] = std::min(best[k], state[k]);
    }
    row_distances(i);
    const float* d = ws.distances.data();
    float* advanced = cell(i, 0);
    std::copy(best + shift - 1, best + shift - 1 + width, advanced);
    for (int advance = 2; advance <= s; ++advance) {
      const float* from = best + shift - advance;
      for (int64_t k = 0; k < width; ++k) advanced[k] = std::min(advanced[k], from[k]);
    }
    for (int64_t k = 0; k < width; ++k) advanced[k] += d[k];
    for (int z = 1; z < s; ++z) {
      const float* from = cell(i - 1, z - 1) + shift;  // the pause: same frame, one more pause
      float* paused = cell(i, z);
      for (int64_t k = 0; k < width; ++k) paused[k] = from[k] + d[k];
    }
  }

  // The best end, then the path back from it, re-deriving each step from the stored costs.
  float end_cost = kInfinity;
  int64_t k = 0;
  int z = 0;
  for (int state = 0; state < s; ++state) {
    for (int64_t c = 0; c < width; ++c) {
      if (cell(m - 1, state)[c] < end_cost) {
        end_cost = cell(m - 1, state)[c];
        k = c;
        z = state;
      }
    }
  }
  Warp warp;
  warp.score = end_cost / static_cast<double>(m);
  warp.path.resize(m);
  *touches_edge = false;
  for (int64_t i = m - 1; i >= 0; --i) {
    const int64_t frame = ws.row_first[i] + k;
    warp.path[i] = frame;
    if ((k == 0 && frame > 0) || (k == width - 1 && frame < clip.rows - 1)) *touches_edge = true;
    if (i == 0) break;
    const int64_t shift = ws.row_first[i] - ws.row_first[i - 1];
    if (z > 0) {
      k += shift;
      --z;
      continue;
    }
    float best = kInfinity;
    int64_t best_k = 0;
    int best_z = 0;
    for (int advance = 1; advance <= s; ++advance) {
      const int64_t from = k + shift - advance;  // inside the padding at worst
      for (int state = 0; state < s; ++state) {
        if (cell(i - 1, state)[from] < best) {
          best = cell(i - 1, state)[from];
          best_k = from;
          best_z = state;
        }
      }
    }
    k = best_k;
    z = best_z;
  }
  warp.first = warp.path.front();
  warp.last = warp.path.back();
  return warp;
}

}  // namespace motiondb
