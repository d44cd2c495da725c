#include "core/search/warp_refinement.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace motiondb {
namespace {

// The band's half-width while it moves: measured on the synthetic set, a seed in a held pose can
// sit 0.8 s from where the best warp passes the characteristic frame, so the band is wide and may
// move several times.
constexpr double kMovingRadiusS = 0.3;
constexpr int kMinRadius = 2;
constexpr int kMaxRounds = 8;

// Banded warps re-centred on their own best path while it beats `score` and touches the band's
// edge; the last one that beat `score`, if any. Warps scoring over `abandon_score` are
// abandoned as they go.
std::optional<Warp> Settle(CoordinateView query, CoordinateView clip, std::vector<int64_t> centre,
                           int radius, double score, double abandon_score,
                           const WarpConstraints& constraints, BandWorkspace& workspace,
                           StopPoll* stop) {
  std::optional<Warp> best;
  for (int round = 0; round < kMaxRounds; ++round) {
    bool touches_edge = false;
    // Loosened a little, so that float rounding never abandons a warp that would be kept.
    const float abandon_at = static_cast<float>(std::min(score, abandon_score) *
                                                static_cast<double>(query.rows) * (1 + 1e-5));
    std::optional<Warp> warp = BandWarp(query, clip, centre, radius, constraints, workspace,
                                        &touches_edge, abandon_at, stop);
    if (!warp || !(warp->score < score)) break;
    score = warp->score;
    centre = warp->path;
    best = std::move(warp);
    if (!touches_edge) break;
  }
  return best;
}

// A full-rate centre from a coarse path (the clip frame of every factor-th query row, row j
// being fine row j * factor): linear between the coarse points, rounded down, so each row
// advances at most as many frames as the coarse path did per coarse row; past the last coarse
// row, one frame per row. Inside [0, clip_rows).
std::vector<int64_t> Upsample(const std::vector<int64_t>& coarse, int factor, int64_t rows,
                              int64_t clip_rows) {
  std::vector<int64_t> fine(rows);
  for (int64_t i = 0; i < rows; ++i) {
    const size_t j = static_cast<size_t>(i / factor);
    const int64_t from = coarse[j];
    const int64_t to = j + 1 < coarse.size() ? coarse[j + 1] : from + factor;
    fine[i] = std::clamp<int64_t>(from + (to - from) * (i % factor) / factor, 0, clip_rows - 1);
  }
  return fine;
}

void Adopt(Warp warp, int anchor, SearchResult& candidate) {
  candidate.first_frame = warp.first;
  candidate.last_frame = warp.last;
  candidate.score = warp.score;
  candidate.seed_frame = warp.path[anchor];
  candidate.path = std::move(warp.path);
}

}  // namespace

void ToClipFrames(int factor, int64_t phase, SearchResult& candidate) {
  const auto scale = [&](int64_t& frame) { frame = frame * factor + phase; };
  scale(candidate.first_frame);
  scale(candidate.last_frame);
  scale(candidate.seed_frame);
  for (int64_t& frame : candidate.path) scale(frame);
}
void ToCoarseFrames(int factor, int64_t phase, SearchResult& candidate) {
  const auto unscale = [&](int64_t& frame) { frame = (frame - phase) / factor; };
  unscale(candidate.first_frame);
  unscale(candidate.last_frame);
  unscale(candidate.seed_frame);
  for (int64_t& frame : candidate.path) unscale(frame);
}

void RefineCandidate(CoordinateView query, CoordinateView clip, int anchor, double rate,
                     const WarpConstraints& constraints, BandWorkspace& workspace,
                     SearchResult& candidate, StopPoll* stop) {
  const int radius = std::max(kMinRadius, static_cast<int>(std::lround(kMovingRadiusS * rate)));
  // Its own score bounds every band already.
  std::optional<Warp> warp =
      Settle(query, clip, candidate.path, radius, candidate.score,
             std::numeric_limits<double>::infinity(), constraints, workspace, stop);
  if (warp) Adopt(*std::move(warp), anchor, candidate);
}

bool RefineFromCoarse(CoordinateView query, CoordinateView clip, int anchor, int factor,
                      const WarpConstraints& constraints, double abandon_score,
                      BandWorkspace& workspace, SearchResult& candidate, StopPoll* stop) {
  // The coarse path is within about `factor` frames of the best warp near it; a band that
  // narrow re-centres when the best path touches its edge (2 * factor: the same results at
  // 10 h / 120 Hz, a third more time).
  std::optional<Warp> warp =
      Settle(query, clip, Upsample(candidate.path, factor, query.rows, clip.rows),
             std::max(kMinRadius, factor), std::numeric_limits<double>::infinity(), abandon_score,
             constraints, workspace, stop);
  if (!warp) return false;
  Adopt(*std::move(warp), anchor, candidate);
  return true;
}

}  // namespace motiondb
