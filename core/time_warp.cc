#include "core/time_warp.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace motiondb {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

// A step into a cell: the clip advance (0..slope_limit) and the pause count it came from.
uint8_t PackStep(int advance, int from_state) {
  return static_cast<uint8_t>(advance << 4 | from_state);
}
int StepAdvance(uint8_t step) { return step >> 4; }
int StepState(uint8_t step) { return step & 15; }

struct HalfWarp {
  double cost = 0;               // sum of distances over the half's rows, anchor included
  int64_t end_offset = 0;        // clip frames from the anchor to the end of the half
  std::vector<int64_t> offsets;  // per row, when requested
};

// One half of an anchored warp: query rows query_anchor, query_anchor + direction, ... to the
// query's end, matched to clip frames clip_anchor + direction * offset. Cells are (row, offset,
// pauses): offsets at row r lie in [r / s, s * r] (the slope band), clipped to the clip.
// Cells whose cost reaches `budget` are dropped; nullopt when a whole row does.
std::optional<HalfWarp> WarpHalf(CoordinateView query, CoordinateView clip, int query_anchor,
                                 int64_t clip_anchor, int direction,
                                 const WarpConstraints& constraints, bool with_path, float budget,
                                 WarpWorkspace& ws) {
  const int s = constraints.slope_limit;
  const int dims = constraints.dims;
  const int rows = direction > 0 ? static_cast<int>(query.rows) - query_anchor : query_anchor + 1;
  const int64_t max_offset = direction > 0 ? clip.rows - 1 - clip_anchor : clip_anchor;
  if ((rows - 1) / s > max_offset) return std::nullopt;  // the clip ends before the query does

  auto band_low = [s](int64_t r) { return r / s; };
  auto band_high = [s, max_offset](int64_t r) { return std::min<int64_t>(s * r, max_offset); };
  if (with_path) {
    ws.row_offsets.assign(rows + 1, 0);
    for (int r = 0; r < rows; ++r) {
      ws.row_offsets[r + 1] = ws.row_offsets[r] + (band_high(r) - band_low(r) + 1) * s;
    }
    ws.steps.resize(ws.row_offsets[rows]);
  }
  std::vector<float>* previous = &ws.cost[0];
  std::vector<float>* current = &ws.cost[1];
  std::vector<float>& best_of_cell = ws.best_of_cell;
  std::vector<uint8_t>& best_state = ws.best_state;
  previous->assign(s, kInfinity);
  (*previous)[0] = Distance(query.row(query_anchor), clip.row(clip_anchor), dims);
  if ((*previous)[0] >= budget) return std::nullopt;
  for (int r = 1; r < rows; ++r) {
    const int64_t prev_low = band_low(r - 1), prev_high = band_high(r - 1);
    const int64_t low = band_low(r), high = band_high(r);
    best_of_cell.assign(prev_high - prev_low + 1, kInfinity);
    best_state.assign(prev_high - prev_low + 1, 0);
    for (int64_t o = prev_low; o <= prev_high; ++o) {
      const float* cell = previous->data() + (o - prev_low) * s;
      for (int z = 0; z < s; ++z) {
        if (cell[z] < best_of_cell[o - prev_low]) {
          best_of_cell[o - prev_low] = cell[z];
          best_state[o - prev_low] = static_cast<uint8_t>(z);
        }
      }
    }
    current->assign((high - low + 1) * s, kInfinity);
    const float* q = query.row(query_anchor + direction * r);
    uint8_t* steps = with_path ? ws.steps.data() + ws.row_offsets[r] : nullptr;
    bool any = false;
    for (int64_t o = low; o <= high; ++o) {
      float* cell = current->data() + (o - low) * s;
      // Advance 1..s clip frames from any pause state, ending with no pause.
      float best = kInfinity;
      int best_advance = 0;
      for (int advance = 1; advance <= s; ++advance) {
        const int64_t from = o - advance;
        if (from < prev_low || from > prev_high) continue;
        if (best_of_cell[from - prev_low] < best) {
          best = best_of_cell[from - prev_low];
          best_advance = advance;
        }
      }
      // Pause: stay on the same clip frame, one more pause in a row.
      const bool can_pause = o >= prev_low && o <= prev_high;
      const float* stay = can_pause ? previous->data() + (o - prev_low) * s : nullptr;
      if (best == kInfinity &&
          (!can_pause || std::all_of(stay, stay + s - 1, [](float c) { return c == kInfinity; }))) {
        continue;
      }
      const float d = Distance(q, clip.row(clip_anchor + direction * o), dims);
      if (best + d < budget) {
        cell[0] = best + d;
        any = true;
        if (steps) {
          steps[(o - low) * s] = PackStep(best_advance, best_state[o - best_advance - prev_low]);
        }
      }
      for (int z = 1; z < s && can_pause; ++z) {
        if (stay[z - 1] + d >= budget) continue;
        cell[z] = stay[z - 1] + d;
        any = true;
        if (steps) steps[(o - low) * s + z] = PackStep(0, z - 1);
      }
    }
    if (!any) return std::nullopt;
    std::swap(previous, current);
  }
  // The best end on the query's boundary row.
  const int64_t low = band_low(rows - 1), high = band_high(rows - 1);
  float best = kInfinity;
  int64_t best_offset = 0;
  int best_z = 0;
  for (int64_t o = low; o <= high; ++o) {
    for (int z = 0; z < s; ++z) {
      const float c = (*previous)[(o - low) * s + z];
      if (c < best) {
        best = c;
        best_offset = o;
        best_z = z;
      }
    }
  }
  if (best == kInfinity) return std::nullopt;
  HalfWarp half{best, best_offset, {}};
  if (with_path) {
    half.offsets.resize(rows);
    int64_t o = best_offset;
    int z = best_z;
    for (int r = rows - 1; r > 0; --r) {
      half.offsets[r] = o;
      const uint8_t step = ws.steps[ws.row_offsets[r] + (o - band_low(r)) * s + z];
      o -= StepAdvance(step);
      z = StepState(step);
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
