#include "core/search/characteristic_points.h"

#include <algorithm>
#include <cmath>

namespace motiondb {
namespace {

std::vector<double> NeutralCentre(CoordinateView query, int dims, NeutralPose neutral) {
  std::vector<double> centre(dims, 0.0);
  if (neutral == NeutralPose::kQueryMean) {
    for (int64_t f = 0; f < query.rows; ++f) {
      for (int k = 0; k < dims; ++k) centre[k] += query.row(f)[k];
    }
    for (double& c : centre) c /= static_cast<double>(query.rows);
  } else if (neutral == NeutralPose::kBoundaryMean) {
    for (int k = 0; k < dims; ++k) {
      centre[k] = 0.5 * (query.row(0)[k] + query.row(query.rows - 1)[k]);
    }
  }
  return centre;
}

// The squared distance of query frame `f` from `centre` over the centre's dimensions.
double SquaredDistance(CoordinateView query, int64_t f, const std::vector<double>& centre) {
  double sum = 0.0;
  for (size_t k = 0; k < centre.size(); ++k) {
    const double d = query.row(f)[k] - centre[k];
    sum += d * d;
  }
  return sum;
}

// The frame of [first, end) farthest from `centre` (the first of equals).
int FarthestFrame(CoordinateView query, const std::vector<double>& centre, int64_t first,
                  int64_t end) {
  int best = static_cast<int>(first);
  double best_distance = -1.0;
  for (int64_t f = first; f < end; ++f) {
    const double sum = SquaredDistance(query, f, centre);
    if (sum > best_distance) {
      best_distance = sum;
      best = static_cast<int>(f);
    }
  }
  return best;
}

}  // namespace

int FindSecondAnchor(CoordinateView query, int anchor, int dims) {
  const std::vector<double> centre(query.row(anchor), query.row(anchor) + dims);
  const int64_t reach = std::max<int64_t>(2, query.rows / 4);
  const int64_t before_end = anchor - reach + 1, after_first = anchor + reach;
  const int before = before_end > 0 ? FarthestFrame(query, centre, 0, before_end) : -1;
  const int after =
      after_first < query.rows ? FarthestFrame(query, centre, after_first, query.rows) : -1;
  if (before < 0 || after < 0) return std::max(before, after);
  // The first of equals, as FarthestFrame.
  return SquaredDistance(query, after, centre) > SquaredDistance(query, before, centre) ? after
                                                                                        : before;
}

int FindCharacteristicFrame(CoordinateView query, int dims, NeutralPose neutral) {
  return FarthestFrame(query, NeutralCentre(query, dims, neutral), 0, query.rows);
}

std::vector<int> FindCharacteristicFrames(CoordinateView query, int dims, NeutralPose neutral,
                                          int count) {
  count = static_cast<int>(std::clamp<int64_t>(count, 1, query.rows));
  const std::vector<double> centre = NeutralCentre(query, dims, neutral);
  std::vector<int> frames;
  for (int part = 0; part < count; ++part) {
    frames.push_back(
        FarthestFrame(query, centre, query.rows * part / count, query.rows * (part + 1) / count));
  }
  return frames;
}

std::vector<int> FindActionFrames(CoordinateView query, int dims, double rate) {
  const std::vector<double> centre = NeutralCentre(query, dims, NeutralPose::kBoundaryMean);
  std::vector<double> distance(query.rows);
  for (int64_t f = 0; f < query.rows; ++f)
    distance[f] = std::sqrt(SquaredDistance(query, f, centre));
  const double threshold = kActionThreshold * *std::max_element(distance.begin(), distance.end());
  const int64_t min_pause = std::max<int64_t>(1, std::llround(kMinActionPauseS * rate));
  // Runs of frames beyond the threshold, joined across dips shorter than min_pause: one action
  // each, represented by its farthest frame.
  struct Action {
    int64_t last = -1;  // the run's last frame beyond the threshold
    int peak = 0;
  };
  std::vector<Action> actions;
  for (int64_t f = 0; f < query.rows; ++f) {
    if (distance[f] <= threshold) continue;
    if (actions.empty() || f - actions.back().last > min_pause) {
      actions.push_back({f, static_cast<int>(f)});
    }
    Action& action = actions.back();
    action.last = f;
    if (distance[f] > distance[action.peak]) action.peak = static_cast<int>(f);
  }
  // The most prominent, if there are more than a query may have.
  if (actions.size() > kMaxCharacteristicPoints) {
    std::sort(actions.begin(), actions.end(), [&](const Action& a, const Action& b) {
      return distance[a.peak] > distance[b.peak];
    });
    actions.resize(kMaxCharacteristicPoints);
  }
  // A query that never leaves its ends' pose has no action: its one point, as the thesis finds it.
  if (actions.empty()) return {FarthestFrame(query, centre, 0, query.rows)};
  std::vector<int> frames;
  for (const Action& action : actions) frames.push_back(action.peak);
  std::sort(frames.begin(), frames.end());
  return frames;
}

std::vector<int> CharacteristicFrames(CoordinateView query, double rate,
                                      const SearchParams& params) {
  if (!params.characteristic_frames.empty()) return params.characteristic_frames;
  if (params.characteristic_frame >= 0) return {params.characteristic_frame};
  if (params.characteristic_points == 0) {
    return FindActionFrames(query, params.ann_dims, rate);
  }
  return FindCharacteristicFrames(query, params.ann_dims, params.neutral,
                                  params.characteristic_points);
}

}  // namespace motiondb
