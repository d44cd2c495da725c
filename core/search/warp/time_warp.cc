#include "core/search/warp/time_warp.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "core/search/warp/internal/dims_major_frames.h"
#include "util/vector_clones.h"

namespace motiondb {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
// A cell of a row on the table's fresh pages counts as this many for a StopPoll, and the row at
// least a page's cells a pause state: the first touch of a page (1024 cells) took about 14 us on
// this machine's virtual memory, against about a nanosecond a cell once touched.
constexpr int64_t kFreshCellWork = 16;
constexpr int64_t kCellsPerPage = 1024;

// A range of offsets, both ends included; empty when first > last.
using OffsetRange = std::pair<int64_t, int64_t>;

struct HalfWarp {
  double cost = 0;               // sum of distances over the half's rows, anchor included
  int64_t end_offset = 0;        // clip frames from the anchor to the end of the half
  std::vector<int64_t> offsets;  // per row, when requested
};

// One half of an anchored warp: query rows query_anchor, query_anchor + direction, ... to the
// query's end, matched to clip frames clip_anchor + direction * offset. At row r the offsets lie
// in the slope band [r / s, s * r] clipped to the clip, [low(r), high(r)]. Row r's cells start at
// row_offsets[r] in the workspace's table: s arrays (one per pause state) of the row's width.
struct HalfBand {
  CoordinateView query;
  int query_anchor = 0;
  int direction = 1;
  int dims = 0;
  int s = 1;               // the slope limit
  int rows = 0;            // query rows in the half, the anchor's included
  int64_t max_offset = 0;  // the clip's end
  int64_t span = 0;        // offsets [0, span): the copied clip frames, all the half can reach

  const float* query_row(int r) const { return query.row(query_anchor + direction * r); }
  int64_t low(int64_t r) const { return r / s; }
  int64_t high(int64_t r) const { return std::min<int64_t>(s * r, max_offset); }
  int64_t width(int64_t r) const { return high(r) - low(r) + 1; }
};

// The pieces of WarpHalf below are always inlined into it: WarpHalf is compiled once per
// MOTIONDB_VECTOR_CLONES target, and an out-of-line piece would run the baseline build in the
// AVX2 clone too.

// Any valid path bounds the optimum, and no cell at or above its cost can lead to a better
// half (costs only grow). The greedy path, taking the cheapest allowed step on every row,
// follows the valley closely, so the cells that survive hug the best paths. Returns the bound
// for the cells: `budget`, or just above the greedy path's cost when that is lower.
[[gnu::always_inline]] inline float GreedyBound(const HalfBand& band,
                                                const std::vector<float>& frames,
                                                float anchor_distance, float budget) {
  float greedy = anchor_distance;
  int64_t o = 0;
  int pauses = 0;
  for (int r = 1; r < band.rows && greedy < budget; ++r) {
    const float* q = band.query_row(r);
    float step_best = kInfinity;
    int step_advance = 0;
    for (int advance = pauses + 1 < band.s ? 0 : 1; advance <= band.s; ++advance) {
      if (o + advance > band.max_offset || o + advance < band.low(r)) continue;
      float d = 0.0f;
      for (int k = 0; k < band.dims; ++k) {
        const float diff = q[k] - frames[k * band.span + o + advance];
        d += diff * diff;
      }
      if (d < step_best) {
        step_best = d;
        step_advance = advance;
      }
    }
    if (step_best == kInfinity) {
      greedy = kInfinity;  // the greedy path ran out of clip
      break;
    }
    o += step_advance;
    pauses = step_advance == 0 ? pauses + 1 : 0;
    greedy += std::sqrt(step_best);
  }
  return std::min(budget, std::nextafter(greedy, kInfinity));
}

// The element-wise passes of a row. The arrays of one call do not overlap unless said so, and
// __restrict lets the vectoriser rely on that instead of checking on every call.

// out[i] = min(out[i], in[i]).
[[gnu::always_inline]] inline void MinInto(const float* __restrict in, int64_t count,
                                           float* __restrict out) {
  for (int64_t i = 0; i < count; ++i) out[i] = std::min(out[i], in[i]);
}

// out[i] = in[i] + d[i], made infinite when it reaches `bound`; `in` may be `out`.
[[gnu::always_inline]] inline void AddBelow(const float* in, const float* __restrict d,
                                            int64_t count, float bound, float* out) {
  for (int64_t i = 0; i < count; ++i) {
    const float c = in[i] + d[i];
    out[i] = c < bound ? c : kInfinity;
  }
}

// best[s + i] = the cheapest pause state of the previous row's offset prev_low + i, for the
// survivors `alive`, padded with s infinities on both sides so that every advance of 1..s
// indexes it without a bounds check. Only as much is written as the advances will read.
[[gnu::always_inline]] inline void BestOfCells(const float* prev, int64_t prev_low,
                                               int64_t prev_width, int s, OffsetRange alive,
                                               std::vector<float>& best) {
  best.resize(prev_width + 2 * s);
  {
    const int64_t from = std::max<int64_t>(0, alive.first - prev_low);
    const int64_t to = std::min<int64_t>(prev_width + 2 * s, alive.second - prev_low + 2 * s + 1);
    std::fill(best.begin() + from, best.begin() + to, kInfinity);
  }
  const int64_t from = alive.first - prev_low, count = alive.second - alive.first + 1;
  float* out = best.data() + s + from;
  std::copy(prev + from, prev + from + count, out);
  for (int z = 1; z < s; ++z) MinInto(prev + z * prev_width + from, count, out);
}

// Row r of the table from row r - 1, whose finite cells lie on the offsets `alive`: fills the
// offsets those can reach and returns them (empty: none can), every cell that reaches `bound`
// made infinite (early abandoning). Costs are kept per pause state z (state-major, so that the
// row is a few passes of plain array arithmetic):
//   row[z = 0][o] = d[o] + min over advance 1..s and any z' of prev[z'][o - advance]
//   row[z > 0][o] = d[o] + prev[z - 1][o]      (a pause: the clip frame repeats)
[[gnu::always_inline]] inline OffsetRange StepRow(const HalfBand& band, int r, OffsetRange alive,
                                                  float bound, WarpWorkspace& ws) {
  const int s = band.s;
  const int64_t prev_low = band.low(r - 1), prev_width = band.width(r - 1);
  const int64_t row_low = band.low(r), width = band.width(r);
  const float* prev = ws.cost[0].data() + ws.row_offsets[r - 1];
  float* row = ws.cost[0].data() + ws.row_offsets[r];
  BestOfCells(prev, prev_low, prev_width, s, alive, ws.best_of_cell);
  // Reachable now: a pause stays on an offset, an advance moves up to s further.
  const int64_t first = std::max(row_low, alive.first);
  const int64_t last = std::min(row_low + width - 1, alive.second + s);
  if (first > last) return {first, last};
  const int64_t count = last - first + 1;
  for (int z = 1; z < s; ++z) {
    std::fill(row + z * width + (first - row_low), row + z * width + (last - row_low) + 1,
              kInfinity);
  }
  WarpCells& distances = ws.cost[1];
  distances.resize(count);
  DistancesToCopied(band.query_row(r), ws.frames, band.span, band.dims, first, count,
                    distances.data());
  float* cells = row + (first - row_low);
  const float* base = ws.best_of_cell.data() + (first - prev_low + s);
  std::copy(base - 1, base - 1 + count, cells);
  for (int advance = 2; advance <= s; ++advance) MinInto(base - advance, count, cells);
  AddBelow(cells, distances.data(), count, bound, cells);
  // Pauses reach only the offsets where the previous row has cells.
  const int64_t paused =
      std::min(last, std::min(prev_low + prev_width - 1, alive.second)) - first + 1;
  for (int z = 1; z < s; ++z) {
    AddBelow(prev + (z - 1) * prev_width + (first - prev_low), distances.data(), paused, bound,
             row + z * width + (first - row_low));
  }
  return {first, last};
}

// The offsets of row r (`row`, filled over `computed`) with a finite cell in some state (empty:
// none). Scanned inwards from both ends, which stops at once in the usual case of survivors at
// the edges.
[[gnu::always_inline]] inline OffsetRange SurvivorRange(const HalfBand& band, int r,
                                                        const float* row, OffsetRange computed) {
  const int64_t row_low = band.low(r), width = band.width(r);
  const auto alive = [&](int64_t o) {
    for (int z = 0; z < band.s; ++z) {
      if (row[z * width + (o - row_low)] < kInfinity) return true;
    }
    return false;
  };
  int64_t first = computed.first;
  while (first <= computed.second && !alive(first)) ++first;
  int64_t last = computed.second;
  while (last >= first && !alive(last)) --last;
  return {first, last};
}

struct HalfEnd {
  float cost = kInfinity;
  int64_t offset = 0;
  int state = 0;  // pause state
};

// The cheapest cell on the half's last row, the query's boundary.
[[gnu::always_inline]] inline HalfEnd BestEnd(const HalfBand& band, const WarpWorkspace& ws) {
  const int r = band.rows - 1;
  const int64_t row_low = band.low(r), width = band.width(r);
  const float* row = ws.cost[0].data() + ws.row_offsets[r];
  HalfEnd end;
  for (int z = 0; z < band.s; ++z) {
    for (int64_t o = ws.computed[r].first; o <= ws.computed[r].second; ++o) {
      const float c = row[z * width + (o - row_low)];
      if (c < end.cost) end = {c, o, z};
    }
  }
  return end;
}

// The offset of every row on the best path to `end`, walking back through the table and
// re-deriving each step from the stored costs.
[[gnu::always_inline]] inline void Backtrack(const HalfBand& band, const WarpWorkspace& ws,
                                             const HalfEnd& end, std::vector<int64_t>& offsets) {
  offsets.resize(band.rows);
  int64_t o = end.offset;
  int z = end.state;
  for (int r = band.rows - 1; r > 0; --r) {
    offsets[r] = o;
    if (z > 0) {
      --z;  // the pause: same offset, one pause fewer
      continue;
    }
    const int64_t prev_low = band.low(r - 1), prev_width = band.width(r - 1);
    const float* prev = ws.cost[0].data() + ws.row_offsets[r - 1];
    const OffsetRange computed = ws.computed[r - 1];
    float m = kInfinity;
    int64_t best_o = o;
    int best_z = 0;
    for (int advance = 1; advance <= band.s; ++advance) {
      if (o - advance < computed.first || o - advance > computed.second) continue;
      const int64_t i = o - advance - prev_low;
      for (int state = 0; state < band.s; ++state) {
        if (prev[state * prev_width + i] < m) {
          m = prev[state * prev_width + i];
          best_o = o - advance;
          best_z = state;
        }
      }
    }
    o = best_o;
    z = best_z;
  }
  offsets[0] = 0;
}

// One half of an anchored warp (see HalfBand), row by row from the anchor. Cells reaching
// `budget` are dropped (early abandoning); nullopt when a whole row is, when the clip ends
// before the query does, or when `stop` (if any) says stop.
MOTIONDB_VECTOR_CLONES std::optional<HalfWarp> WarpHalf(CoordinateView query, CoordinateView clip,
                                                        int query_anchor, int64_t clip_anchor,
                                                        int direction,
                                                        const WarpConstraints& constraints,
                                                        bool with_path, float budget,
                                                        WarpWorkspace& ws, StopPoll* stop) {
  HalfBand band;
  band.query = query;
  band.query_anchor = query_anchor;
  band.direction = direction;
  band.dims = constraints.dims;
  band.s = constraints.slope_limit;
  band.rows = direction > 0 ? static_cast<int>(query.rows) - query_anchor : query_anchor + 1;
  band.max_offset = direction > 0 ? clip.rows - 1 - clip_anchor : clip_anchor;
  if ((band.rows - 1) / band.s > band.max_offset) return std::nullopt;  // the clip ends first
  band.span = band.high(band.rows - 1) + 1;
  ws.row_offsets.resize(band.rows + 1);
  ws.row_offsets[0] = 0;
  for (int r = 0; r < band.rows; ++r) {
    ws.row_offsets[r + 1] = ws.row_offsets[r] + band.width(r) * band.s;
  }
  CopyDimsMajor(clip, clip_anchor, direction, band.span, band.dims, ws.frames);
  const float anchor = Distance(query.row(query_anchor), clip.row(clip_anchor), band.dims);
  const float bound = GreedyBound(band, ws.frames, anchor, budget);

  // Only each row's computed range is initialised; every cell outside it is infinite. Cleared
  // first, so that a table that grows is not copied (its cells are the previous half's).
  WarpCells& table = ws.cost[0];
  if (table.capacity() < static_cast<size_t>(ws.row_offsets[band.rows])) ws.touched = 0;
  table.clear();
  table.resize(ws.row_offsets[band.rows]);
  ws.computed.assign(band.rows, {0, -1});
  std::fill(table.begin(), table.begin() + band.s, kInfinity);
  table[0] = anchor;
  ws.computed[0] = {0, 0};
  if (table[0] >= bound) return std::nullopt;
  OffsetRange alive = {0, 0};  // offsets with a finite cell in the previous row
  for (int r = 1; r < band.rows; ++r) {
    const OffsetRange computed = StepRow(band, r, alive, bound, ws);
    if (computed.first > computed.second) return std::nullopt;
    if (stop != nullptr) {
      const int64_t cells = (computed.second - computed.first + 1) * band.s;
      const bool fresh = ws.row_offsets[r + 1] > ws.touched;
      if (stop->Done(fresh ? kFreshCellWork * (cells + kCellsPerPage * band.s) : cells)) {
        return std::nullopt;
      }
    }
    ws.touched = std::max(ws.touched, ws.row_offsets[r + 1]);
    ws.computed[r] = computed;
    alive = SurvivorRange(band, r, table.data() + ws.row_offsets[r], computed);
    if (alive.first > alive.second) return std::nullopt;
  }

  const HalfEnd end = BestEnd(band, ws);
  if (end.cost == kInfinity) return std::nullopt;
  HalfWarp half{end.cost, end.offset, {}};
  if (with_path) Backtrack(band, ws, end, half.offsets);
  return half;
}

}  // namespace

int64_t AnchoredWarpTableBytes(int64_t rows, int slope_limit) {
  HalfBand band;
  band.s = slope_limit;
  band.max_offset = std::numeric_limits<int64_t>::max();
  int64_t cells = 0;
  for (int64_t r = 0; r < rows; ++r) cells += band.width(r) * band.s;
  return cells * static_cast<int64_t>(sizeof(float));
}

std::optional<Warp> AnchoredWarp(CoordinateView query, CoordinateView clip, int query_anchor,
                                 int64_t clip_anchor, const WarpConstraints& constraints,
                                 bool with_path, WarpWorkspace& workspace, float abandon_at,
                                 StopPoll* stop) {
  // The whole warp costs at least its forward half; the backward half then has what is left,
  // plus the anchor cell that both halves count.
  const std::optional<HalfWarp> forward =
      WarpHalf(query, clip, query_anchor, clip_anchor, +1, constraints, with_path, abandon_at,
               workspace, stop);
  if (!forward) return std::nullopt;
  const float anchor = Distance(query.row(query_anchor), clip.row(clip_anchor), constraints.dims);
  const std::optional<HalfWarp> backward =
      WarpHalf(query, clip, query_anchor, clip_anchor, -1, constraints, with_path,
               abandon_at - static_cast<float>(forward->cost) + anchor, workspace, stop);
  if (!backward) return std::nullopt;
  Warp warp;
  warp.first = clip_anchor - backward->end_offset;
  warp.last = clip_anchor + forward->end_offset;
  warp.score = (forward->cost + backward->cost - anchor) / static_cast<double>(query.rows);
  if (with_path) {
    warp.path.resize(query.rows);
    for (int r = 0; r <= query_anchor; ++r) {
      warp.path[query_anchor - r] = clip_anchor - backward->offsets[r];
    }
    for (size_t r = 0; r < forward->offsets.size(); ++r) {
      warp.path[query_anchor + r] = clip_anchor + forward->offsets[r];
    }
  }
  return warp;
}

}  // namespace motiondb
