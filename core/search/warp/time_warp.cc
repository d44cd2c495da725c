#include "core/search/warp/time_warp.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/search/warp/internal/dims_major_frames.h"
#include "util/vector_clones.h"

namespace motiondb {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

struct HalfWarp {
  double cost = 0;               // sum of distances over the half's rows, anchor included
  int64_t end_offset = 0;        // clip frames from the anchor to the end of the half
  std::vector<int64_t> offsets;  // per row, when requested
};

// One half of an anchored warp: query rows query_anchor, query_anchor + direction, ... to the
// query's end, matched to clip frames clip_anchor + direction * offset. At row r the offsets lie
// in the slope band [r / s, s * r], clipped to the clip. Costs are kept per row and pause state
// z (state-major, so each row is a few passes of plain array arithmetic):
//   cost[z = 0][o] = d[o] + min over advance 1..s and any z' of cost_prev[z'][o - advance]
//   cost[z > 0][o] = d[o] + cost_prev[z - 1][o]      (a pause: the clip frame repeats)
// Cells reaching `budget` are dropped (early abandoning); nullopt when a whole row is.
MOTIONDB_VECTOR_CLONES std::optional<HalfWarp> WarpHalf(
    CoordinateView query, CoordinateView clip, int query_anchor, int64_t clip_anchor, int direction,
    const WarpConstraints& constraints, bool with_path, float budget, WarpWorkspace& ws) {
  const int s = constraints.slope_limit;
  const int rows = direction > 0 ? static_cast<int>(query.rows) - query_anchor : query_anchor + 1;
  const int64_t max_offset = direction > 0 ? clip.rows - 1 - clip_anchor : clip_anchor;
  if ((rows - 1) / s > max_offset) return std::nullopt;  // the clip ends before the query does

  // Row r's cells start at row_start[r] in the table: s arrays of the row's band width.
  auto low = [s](int64_t r) { return r / s; };
  auto high = [s, max_offset](int64_t r) { return std::min<int64_t>(s * r, max_offset); };
  ws.row_offsets.resize(rows + 1);
  ws.row_offsets[0] = 0;
  for (int r = 0; r < rows; ++r) {
    ws.row_offsets[r + 1] = ws.row_offsets[r] + (high(r) - low(r) + 1) * s;
  }
  std::vector<float>& table = ws.cost[0];
  std::vector<float>& best = ws.best_of_cell;  // per previous-row cell: min over its states
  std::vector<float>& distances = ws.cost[1];
  const int64_t span = high(rows - 1) + 1;
  CopyDimsMajor(clip, clip_anchor, direction, span, constraints.dims, ws.frames);
  // Any valid path bounds the optimum, and no cell at or above its cost can lead to a better
  // half (costs only grow). The greedy path, taking the cheapest allowed step on every row,
  // follows the valley closely, so the cells that survive hug the best paths, and each row only
  // computes the offsets the previous row's survivors can reach.
  float bound = budget;
  {
    float greedy = Distance(query.row(query_anchor), clip.row(clip_anchor), constraints.dims);
    int64_t o = 0;
    int pauses = 0;
    for (int r = 1; r < rows && greedy < bound; ++r) {
      const float* q = query.row(query_anchor + direction * r);
      float step_best = kInfinity;
      int step_advance = 0;
      for (int advance = pauses + 1 < s ? 0 : 1; advance <= s; ++advance) {
        if (o + advance > max_offset || o + advance < low(r)) continue;
        float d = 0.0f;
        for (int k = 0; k < constraints.dims; ++k) {
          const float diff = q[k] - ws.frames[k * span + o + advance];
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
    bound = std::min(bound, std::nextafter(greedy, kInfinity));
  }
  // Only each row's computed range [computed[r].first, .second] is initialised; every cell
  // outside it is infinite.
  table.resize(ws.row_offsets[rows]);
  std::vector<std::pair<int64_t, int64_t>>& computed = ws.computed;
  computed.assign(rows, {0, -1});
  std::fill(table.begin(), table.begin() + s, kInfinity);
  table[0] = Distance(query.row(query_anchor), clip.row(clip_anchor), constraints.dims);
  computed[0] = {0, 0};
  if (table[0] >= bound) return std::nullopt;
  int64_t alive_first = 0, alive_last = 0;  // offsets with a finite cell in the previous row

  for (int r = 1; r < rows; ++r) {
    const int64_t prev_low = low(r - 1), prev_width = high(r - 1) - prev_low + 1;
    const int64_t row_low = low(r), width = high(r) - row_low + 1;
    const float* prev = table.data() + ws.row_offsets[r - 1];
    float* row = table.data() + ws.row_offsets[r];
    // best[s + i] is the previous row's offset prev_low + i, padded with s infinities on both
    // sides so that every advance of 1..s indexes it without a bounds check.
    best.resize(prev_width + 2 * s);
    {
      // Infinities around the survivors, as far as any advance reads.
      const int64_t from = std::max<int64_t>(0, alive_first - prev_low);
      const int64_t to = std::min<int64_t>(prev_width + 2 * s, alive_last - prev_low + 2 * s + 1);
      std::fill(best.begin() + from, best.begin() + to, kInfinity);
    }
    {
      const int64_t from = alive_first - prev_low, count = alive_last - alive_first + 1;
      float* out = best.data() + s + from;
      std::copy(prev + from, prev + from + count, out);
      for (int z = 1; z < s; ++z) {
        const float* state = prev + z * prev_width + from;
        for (int64_t i = 0; i < count; ++i) out[i] = std::min(out[i], state[i]);
      }
    }
    // Reachable now: a pause stays on an offset, an advance moves up to s further.
    const int64_t first = std::max(row_low, alive_first);
    const int64_t last = std::min(row_low + width - 1, alive_last + s);
    if (first > last) return std::nullopt;
    const int64_t count = last - first + 1;
    computed[r] = {first, last};
    for (int z = 1; z < s; ++z) {
      std::fill(row + z * width + (first - row_low), row + z * width + (last - row_low) + 1,
                kInfinity);
    }
    distances.resize(count);
    DistancesToCopied(query.row(query_anchor + direction * r), ws.frames, span, constraints.dims,
                      first, count, distances.data());
    // Advance 1..s, from any state, ends in state 0: row[o] = d[o] + min_a best[o - a].
    float* cells = row + (first - row_low);
    const float* base = best.data() + (first - prev_low + s);
    std::copy(base - 1, base - 1 + count, cells);
    for (int advance = 2; advance <= s; ++advance) {
      const float* from = base - advance;
      for (int64_t o = 0; o < count; ++o) cells[o] = std::min(cells[o], from[o]);
    }
    for (int64_t o = 0; o < count; ++o) {
      const float c = cells[o] + distances[o];
      cells[o] = c < bound ? c : kInfinity;
    }
    // A pause keeps the offset and adds one to the pause count.
    for (int z = 1; z < s; ++z) {
      float* paused = row + z * width;
      const float* from = prev + (z - 1) * prev_width;
      const int64_t stop = std::min(last, std::min(prev_low + prev_width - 1, alive_last));
      for (int64_t o = first; o <= stop; ++o) {
        const float c = from[o - prev_low] + distances[o - first];
        paused[o - row_low] = c < bound ? c : kInfinity;
      }
    }
    // The survivors' range, for the next row: scanned inwards from both ends, which stops at
    // once in the usual case of survivors at the edges.
    const auto alive = [&](int64_t o) {
      for (int z = 0; z < s; ++z) {
        if (row[z * width + (o - row_low)] < kInfinity) return true;
      }
      return false;
    };
    alive_first = first;
    while (alive_first <= last && !alive(alive_first)) ++alive_first;
    alive_last = last;
    while (alive_last >= alive_first && !alive(alive_last)) --alive_last;
    if (alive_first > alive_last) return std::nullopt;
  }

  // The best end on the query's boundary row.
  const int64_t last_low = low(rows - 1), last_width = high(rows - 1) - last_low + 1;
  const float* last = table.data() + ws.row_offsets[rows - 1];
  float end_cost = kInfinity;
  int64_t end_offset = 0;
  int end_state = 0;
  for (int z = 0; z < s; ++z) {
    for (int64_t o = computed[rows - 1].first; o <= computed[rows - 1].second; ++o) {
      const float c = last[z * last_width + (o - last_low)];
      if (c < end_cost) {
        end_cost = c;
        end_offset = o;
        end_state = z;
      }
    }
  }
  if (end_cost == kInfinity) return std::nullopt;
  HalfWarp half{end_cost, end_offset, {}};
  if (with_path) {
    // Walk back through the table, re-deriving each step from the stored costs.
    half.offsets.resize(rows);
    int64_t o = half.end_offset;
    int z = end_state;
    for (int r = rows - 1; r > 0; --r) {
      half.offsets[r] = o;
      const int64_t prev_low = low(r - 1), prev_width = high(r - 1) - prev_low + 1;
      const float* prev = table.data() + ws.row_offsets[r - 1];
      if (z > 0) {
        --z;  // the pause: same offset, one pause fewer
        continue;
      }
      float m = kInfinity;
      int64_t best_o = o;
      int best_z = 0;
      for (int advance = 1; advance <= s; ++advance) {
        const int64_t i = o - advance - prev_low;
        if (o - advance < computed[r - 1].first || o - advance > computed[r - 1].second) continue;
        for (int state = 0; state < s; ++state) {
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
    half.offsets[0] = 0;
  }
  return half;
}

}  // namespace

std::optional<Warp> AnchoredWarp(CoordinateView query, CoordinateView clip, int query_anchor,
                                 int64_t clip_anchor, const WarpConstraints& constraints,
                                 bool with_path, WarpWorkspace& workspace, float abandon_at) {
  // The whole warp costs at least its forward half; the backward half then has what is left,
  // plus the anchor cell that both halves count.
  const std::optional<HalfWarp> forward = WarpHalf(query, clip, query_anchor, clip_anchor, +1,
                                                   constraints, with_path, abandon_at, workspace);
  if (!forward) return std::nullopt;
  const float anchor = Distance(query.row(query_anchor), clip.row(clip_anchor), constraints.dims);
  const std::optional<HalfWarp> backward =
      WarpHalf(query, clip, query_anchor, clip_anchor, -1, constraints, with_path,
               abandon_at - static_cast<float>(forward->cost) + anchor, workspace);
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
