#include "core/search/warp_refinement.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace motiondb {
namespace {

// The coarse pass runs at rate / n for the n that brings it nearest this (none below 45 Hz).
constexpr double kCoarseRate = 30.0;
// The band's half-width while it moves: measured on the synthetic set, a seed in a held pose can
// sit 0.8 s from where the best warp passes the characteristic frame, so the band is wide and may
// move several times.
constexpr double kMovingRadiusS = 0.3;
constexpr int kMinRadius = 2;
constexpr int kMaxRounds = 8;

// Banded warps re-centred on their own best path while it beats `score` and touches the band's
// edge; the last one that beat `score`, if any.
std::optional<Warp> Settle(CoordinateView query, CoordinateView clip, std::vector<int64_t> centre,
                           int radius, double score, const WarpConstraints& constraints,
                           BandWorkspace& workspace) {
  std::optional<Warp> best;
  for (int round = 0; round < kMaxRounds; ++round) {
    bool touches_edge = false;
    Warp warp = BandWarp(query, clip, centre, radius, constraints, workspace, &touches_edge);
    if (!(warp.score < score)) break;
    score = warp.score;
    centre = warp.path;
    best = std::move(warp);
    if (!touches_edge) break;
  }
  return best;
}

// A full-rate centre from a coarse path (coarse row j and frame c are fine row and frame
// j * factor and c * factor): linear between the coarse points, rounded down, so each row
// advances at most as many frames as the coarse path did per coarse row; past the last coarse
// row, one frame per row. Inside [0, clip_rows).
std::vector<int64_t> Upsample(const std::vector<int64_t>& coarse, int factor, int64_t rows,
                              int64_t clip_rows) {
  std::vector<int64_t> fine(rows);
  for (int64_t i = 0; i < rows; ++i) {
    const size_t j = static_cast<size_t>(i / factor);
    const int64_t from = coarse[j] * factor;
    const int64_t to = j + 1 < coarse.size() ? coarse[j + 1] * factor : from + factor;
    fine[i] = std::clamp<int64_t>(from + (to - from) * (i % factor) / factor, 0, clip_rows - 1);
  }
  return fine;
}

}  // namespace

void RefineCandidate(CoordinateView query, CoordinateView clip, int anchor, double rate,
                     const WarpConstraints& constraints, BandWorkspace& workspace,
                     SearchResult& candidate) {
  const int factor = std::max(1, static_cast<int>(std::lround(rate / kCoarseRate)));
  const auto radius_at = [](double r) {
    return std::max(kMinRadius, static_cast<int>(std::lround(kMovingRadiusS * r)));
  };
  std::optional<Warp> warp;
  if (factor > 1) {
    const CoordinateView coarse_query{query.data, (query.rows - 1) / factor + 1,
                                      query.stride * factor};
    const CoordinateView coarse_clip{clip.data, (clip.rows - 1) / factor + 1, clip.stride * factor};
    std::vector<int64_t> coarse_centre(coarse_query.rows);
    for (int64_t j = 0; j < coarse_query.rows; ++j) {
      coarse_centre[j] = candidate.path[j * factor] / factor;
    }
    const std::optional<Warp> coarse =
        Settle(coarse_query, coarse_clip, std::move(coarse_centre), radius_at(rate / factor),
               std::numeric_limits<double>::infinity(), constraints, workspace);
    // The coarse path is within about `factor` frames of the best warp near it. When nothing
    // there beats the candidate, neither did a wide full-rate band around the candidate itself
    // (0 of 228 such candidates at 120 Hz), so the candidate stays as it is.
    if (coarse) {
      warp = Settle(query, clip, Upsample(coarse->path, factor, query.rows, clip.rows),
                    std::max(kMinRadius, 2 * factor), candidate.score, constraints, workspace);
    }
  } else {
    warp = Settle(query, clip, candidate.path, radius_at(rate), candidate.score, constraints,
                  workspace);
  }
  if (!warp) return;
  candidate.first_frame = warp->first;
  candidate.last_frame = warp->last;
  candidate.score = warp->score;
  candidate.seed_frame = warp->path[anchor];
  candidate.path = std::move(warp->path);
}

}  // namespace motiondb
