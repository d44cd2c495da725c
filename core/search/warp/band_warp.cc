#include "core/search/warp/band_warp.h"

#include <algorithm>
#include <limits>
#include <utility>

#include "core/search/warp/internal/dims_major_frames.h"
#include "util/vector_clones.h"

namespace motiondb {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
// Rows between looks at whether a band warp can still end under its bound. A look costs about
// half a row's step at the default slope limit: looking at every row, and also without a bound,
// took 70 s at 120 Hz from 0.88 to 1.13 ms a search (bench/notes/2026-12-04-scale-settle-bound.md).
constexpr int64_t kRowsPerAbandonLook = 4;

// One row of the band from the previous one, padding included: `prev` and `row` point at state
// 0's first cell, state z lies `padded` floats further, `d` holds the row's distances. S, the slope
// limit, is fixed at compile time so that every step unrolls and the loop over the cells
// vectorises.
template <int S>
MOTIONDB_VECTOR_CLONES void StepRow(const float* __restrict prev, int64_t padded, int64_t shift,
                                    const float* __restrict d, int64_t width,
                                    float* __restrict row) {
  for (int64_t k = 0; k < width; ++k) {
    // An advance of 1..S from any state ends in state 0; a pause from state z - 1 on the same
    // frame ends in state z.
    float best = kInfinity;
    for (int advance = 1; advance <= S; ++advance) {
      for (int z = 0; z < S; ++z) best = std::min(best, prev[z * padded + k + shift - advance]);
    }
    row[k] = best + d[k];
    for (int z = 1; z < S; ++z) row[z * padded + k] = prev[(z - 1) * padded + k + shift] + d[k];
  }
  for (int z = 0; z < S; ++z) {
    for (int p = 1; p <= S; ++p) row[z * padded - p] = row[z * padded + width - 1 + p] = kInfinity;
  }
}

using StepRowFn = void (*)(const float*, int64_t, int64_t, const float*, int64_t, float*);

template <int... S>
StepRowFn StepRowFor(int slope_limit, std::integer_sequence<int, S...>) {
  StepRowFn step = nullptr;
  ((slope_limit == S + 1 ? (step = &StepRow<S + 1>, 0) : 0), ...);
  return step;
}

}  // namespace

// Row i's cells are the clip frames row_first[i] + k, k in [0, width), stored state-major with
// s infinite cells of padding on both sides, so that no step needs a bounds check:
// cost[(i * s + z) * padded + s + k]. Frames outside the clip are infinite. As the centre
// advances 0..s frames per row, so does the band: a step of `advance` from the previous row's
// cell k + shift - advance lands on cell k (shift: how far the band moved), a pause from k + shift.
MOTIONDB_VECTOR_CLONES std::optional<Warp> BandWarp(CoordinateView query, CoordinateView clip,
                                                    const std::vector<int64_t>& centre, int radius,
                                                    const WarpConstraints& constraints,
                                                    BandWorkspace& ws, bool* touches_edge,
                                                    float abandon_at, StopPoll* stop) {
  const int s = constraints.slope_limit;
  const int64_t m = query.rows, width = 2 * radius + 1, padded = width + 2 * s;
  ws.row_first.resize(m);
  for (int64_t i = 0; i < m; ++i) ws.row_first[i] = centre[i] - radius;
  // Every cell of rows 1.. is written by StepRow; row 0 starts infinite but for its distances.
  ws.cost.resize(m * s * padded);
  std::fill(ws.cost.begin(), ws.cost.begin() + s * padded, kInfinity);
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

  // Distances are not negative, so no path through row i costs less than its cheapest cell.
  const bool may_abandon = abandon_at < kInfinity;
  const auto row_exceeds = [&](int64_t i) {
    float cheapest = kInfinity;
    for (int z = 0; z < s; ++z) {
      cheapest = std::min(cheapest, *std::min_element(cell(i, z), cell(i, z) + width));
    }
    return cheapest > abandon_at;
  };
  row_distances(0);
  std::copy(ws.distances.begin(), ws.distances.end(), cell(0, 0));
  const StepRowFn step = StepRowFor(s, std::make_integer_sequence<int, kMaxSlopeLimit>());
  for (int64_t i = 1; i < m; ++i) {
    if (stop != nullptr && stop->Done(width * s)) return std::nullopt;
    row_distances(i);
    step(cell(i - 1, 0), padded, ws.row_first[i] - ws.row_first[i - 1], ws.distances.data(), width,
         cell(i, 0));
    if (may_abandon && i % kRowsPerAbandonLook == 0 && row_exceeds(i)) return std::nullopt;
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
  if (end_cost > abandon_at) return std::nullopt;
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
