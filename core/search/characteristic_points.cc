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

// The frame of [first, end) farthest from `centre` (the first of equals).
int FarthestFrame(CoordinateView query, const std::vector<double>& centre, int64_t first,
                  int64_t end) {
  int best = static_cast<int>(first);
  double best_distance = -1.0;
  for (int64_t f = first; f < end; ++f) {
    double sum = 0.0;
    for (size_t k = 0; k < centre.size(); ++k) {
      const double d = query.row(f)[k] - centre[k];
      sum += d * d;
    }
    if (sum > best_distance) {
      best_distance = sum;
      best = static_cast<int>(f);
    }
  }
  return best;
}

}  // namespace

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

std::vector<int> CharacteristicFrames(CoordinateView query, double rate,
                                      const SearchParams& params) {
  if (!params.characteristic_frames.empty()) return params.characteristic_frames;
  if (params.characteristic_frame >= 0) return {params.characteristic_frame};
  int count = params.characteristic_points;
  if (count == 0) {
    const double seconds = static_cast<double>(query.rows) / rate;
    count = std::clamp(static_cast<int>(seconds / kSecondsPerCharacteristicPoint), 1,
                       kMaxCharacteristicPoints);
  }
  return FindCharacteristicFrames(query, params.ann_dims, params.neutral, count);
}

}  // namespace motiondb
