#include "tests/search_test_data.h"

#include <cmath>
#include <numbers>
#include <random>

#include "core/index/coordinate_view.h"

namespace motiondb::testing {

RowMatrixXf SmoothNoise(int64_t frames, int dims, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> step(0.0f, 0.15f);
  RowMatrixXf curve(frames, dims);
  std::vector<float> value(dims, 0.0f), velocity(dims, 0.0f);
  for (int64_t f = 0; f < frames; ++f) {
    for (int k = 0; k < dims; ++k) {
      velocity[k] = 0.9f * velocity[k] + step(rng);
      value[k] = 0.95f * value[k] + 0.1f * velocity[k];
      curve(f, k) = value[k];
    }
  }
  return curve;
}

RowMatrixXf Pattern(int frames, int dims) {
  RowMatrixXf pattern(frames, dims);
  for (int f = 0; f < frames; ++f) {
    const double t = frames > 1 ? static_cast<double>(f) / (frames - 1) : 0.0;
    for (int k = 0; k < dims; ++k) {
      // A raise-and-return shape, different in each dimension.
      pattern(f, k) =
          static_cast<float>(3.0 * std::sin(std::numbers::pi * t) * std::cos(0.7 * k + 2.0 * t));
    }
  }
  return pattern;
}

RowMatrixXf HeldPattern(int frames, int hold, int dims) {
  const RowMatrixXf pattern = Pattern(frames, dims);
  RowMatrixXf held(frames + hold, dims);
  held.topRows(frames / 2) = pattern.topRows(frames / 2);
  held.middleRows(frames / 2, hold).rowwise() = pattern.row(frames / 2);
  held.bottomRows(frames - frames / 2) = pattern.bottomRows(frames - frames / 2);
  return held;
}

std::vector<LibraryClip> HeldPoseClips(int dims) {
  const RowMatrixXf held = HeldPattern(240, 480, dims);
  std::vector<LibraryClip> clips;
  for (int c = 0; c < 8; ++c) {
    RowMatrixXf curve = SmoothNoise(3000, dims, 7 + c);
    if (c < 6) Plant(curve, held, 300 + 200 * c);
    clips.push_back({c, "held", {}, std::move(curve)});
  }
  return clips;
}

void Plant(RowMatrixXf& curve, const RowMatrixXf& pattern, int64_t at) {
  curve.middleRows(at, pattern.rows()) = pattern;
}

double MeanPathDistance(const RowMatrixXf& query, const RowMatrixXf& clip,
                        const std::vector<int64_t>& path, int dims) {
  double sum = 0;
  for (int64_t i = 0; i < query.rows(); ++i) {
    sum += Distance(query.row(i).data(), clip.row(path[i]).data(), dims);
  }
  return sum / static_cast<double>(query.rows());
}

}  // namespace motiondb::testing
