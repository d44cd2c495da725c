#include "bench/window_vector_baseline.h"

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_index.h>
#include <flann/algorithms/kmeans_index.h>
#include <flann/algorithms/linear_index.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace motiondb::bench {

struct WindowVectorBaseline::Scale {
  int64_t frames = 0;  // the window's length
  std::vector<Window> windows;
  std::vector<float> vectors;  // windows x vector_size()
  std::unique_ptr<flann::NNIndex<flann::L2<float>>> index;
};

const char* WindowIndexKindName(WindowIndexKind kind) {
  switch (kind) {
    case WindowIndexKind::kKdForest:
      return "kd-forest";
    case WindowIndexKind::kKMeans:
      return "k-means";
    case WindowIndexKind::kLinear:
      return "linear";
  }
  return "?";
}

WindowVectorBaseline::WindowVectorBaseline(const LibraryIndex& library,
                                           const WindowBaselineOptions& options)
    : library_(library),
      options_(options),
      samples_(options.samples),
      dims_(std::min(options.dims, library.dims())) {}

WindowVectorBaseline::~WindowVectorBaseline() = default;

absl::StatusOr<std::unique_ptr<WindowVectorBaseline>> WindowVectorBaseline::Build(
    const LibraryIndex& library, const WindowBaselineOptions& options) {
  if (options.window_s.empty() || options.samples < 2 || options.dims < 1 ||
      options.stride_divisor < 1 || options.checks < 1 || options.first_windows < 1) {
    return absl::InvalidArgumentError(
        "window baseline: window lengths, samples >= 2, dims, stride, checks and first windows "
        "must be set");
  }
  if (library.clip_count() == 0) return absl::InvalidArgumentError("window baseline: no clips");
  std::unique_ptr<WindowVectorBaseline> baseline(new WindowVectorBaseline(library, options));
  const int size = baseline->vector_size();
  for (double seconds : options.window_s) {
    auto scale = std::make_unique<Scale>();
    scale->frames = std::max<int64_t>(2, std::llround(seconds * library.rate()));
    const int64_t stride = std::max<int64_t>(1, scale->frames / options.stride_divisor);
    for (int c = 0; c < library.clip_count(); ++c) {
      const int64_t frames = library.clip(c).frame_count;
      if (frames <= scale->frames) {
        scale->windows.push_back({c, 0, frames - 1});
        continue;
      }
      for (int64_t first = 0;; first += stride) {
        const int64_t last_start = frames - scale->frames;
        first = std::min(first, last_start);
        scale->windows.push_back({c, first, first + scale->frames - 1});
        if (first == last_start) break;
      }
    }
    scale->vectors.resize(scale->windows.size() * size);
    for (size_t w = 0; w < scale->windows.size(); ++w) {
      const Window& window = scale->windows[w];
      baseline->Resample(library.clip_coordinates(window.clip), window.first_frame,
                         window.last_frame - window.first_frame + 1, &scale->vectors[w * size]);
    }
    const flann::Matrix<float> points(scale->vectors.data(), scale->windows.size(), size);
    switch (options.kind) {
      case WindowIndexKind::kKdForest:
        scale->index = std::make_unique<flann::KDTreeIndex<flann::L2<float>>>(
            points, flann::KDTreeIndexParams(options.trees));
        break;
      case WindowIndexKind::kKMeans:
        scale->index = std::make_unique<flann::KMeansIndex<flann::L2<float>>>(
            points, flann::KMeansIndexParams(options.branching, options.iterations));
        break;
      case WindowIndexKind::kLinear:
        scale->index = std::make_unique<flann::LinearIndex<flann::L2<float>>>(points);
        break;
    }
    scale->index->buildIndex();
    baseline->scales_.push_back(std::move(scale));
  }
  return baseline;
}

void WindowVectorBaseline::Resample(CoordinateView rows, int64_t first, int64_t count,
                                    float* out) const {
  for (int s = 0; s < samples_; ++s) {
    const double t = count > 1 ? static_cast<double>(s) * (count - 1) / (samples_ - 1) : 0.0;
    const int64_t lower = std::min<int64_t>(static_cast<int64_t>(t), count - 1);
    const int64_t upper = std::min<int64_t>(lower + 1, count - 1);
    const float w = static_cast<float>(t - lower);
    const float* a = rows.row(first + lower);
    const float* b = rows.row(first + upper);
    for (int d = 0; d < dims_; ++d) out[s * dims_ + d] = a[d] + w * (b[d] - a[d]);
  }
}

int WindowVectorBaseline::ScaleFor(int64_t frames) const {
  int best = 0;
  double best_gap = HUGE_VAL;
  for (int s = 0; s < scale_count(); ++s) {
    const double gap = std::abs(std::log(static_cast<double>(std::max<int64_t>(frames, 1)) /
                                         static_cast<double>(scales_[s]->frames)));
    if (gap < best_gap) best = s, best_gap = gap;
  }
  return best;
}

int64_t WindowVectorBaseline::window_frames(int scale) const { return scales_[scale]->frames; }

int64_t WindowVectorBaseline::window_count(int scale) const {
  return static_cast<int64_t>(scales_[scale]->windows.size());
}

const WindowVectorBaseline::Window& WindowVectorBaseline::window(int scale, int64_t i) const {
  return scales_[scale]->windows[i];
}

const float* WindowVectorBaseline::window_vector(int scale, int64_t i) const {
  return &scales_[scale]->vectors[i * vector_size()];
}

int64_t WindowVectorBaseline::memory_bytes() const {
  int64_t bytes = 0;
  for (const auto& scale : scales_) {
    bytes += static_cast<int64_t>(scale->vectors.size() * sizeof(float) +
                                  scale->windows.size() * sizeof(Window));
    bytes += scale->index->usedMemory();
  }
  return bytes;
}

std::vector<std::pair<int64_t, float>> WindowVectorBaseline::NearestWindows(const Scale& scale,
                                                                            const float* vector,
                                                                            int k,
                                                                            bool exact) const {
  const int64_t n = static_cast<int64_t>(scale.windows.size());
  k = static_cast<int>(std::min<int64_t>(k, n));
  std::vector<std::pair<int64_t, float>> nearest;
  if (exact) {
    const int size = vector_size();
    nearest.reserve(n);
    for (int64_t w = 0; w < n; ++w) {
      const float* v = &scale.vectors[w * size];
      float sum = 0;
      for (int i = 0; i < size; ++i) sum += (v[i] - vector[i]) * (v[i] - vector[i]);
      nearest.emplace_back(w, sum);
    }
    std::partial_sort(nearest.begin(), nearest.begin() + k, nearest.end(),
                      [](const auto& a, const auto& b) {
                        return a.second < b.second || (a.second == b.second && a.first < b.first);
                      });
    nearest.resize(k);
    return nearest;
  }
  std::vector<size_t> indices(k);
  std::vector<float> squared(k);
  flann::Matrix<size_t> index_matrix(indices.data(), 1, k);
  flann::Matrix<float> squared_matrix(squared.data(), 1, k);
  const flann::Matrix<float> query(const_cast<float*>(vector), 1, vector_size());
  const int found = scale.index->knnSearch(query, index_matrix, squared_matrix, k,
                                           flann::SearchParams(std::max(options_.checks, k)));
  for (int i = 0; i < found; ++i)
    nearest.emplace_back(static_cast<int64_t>(indices[i]), squared[i]);
  return nearest;
}

std::vector<SearchResult> WindowVectorBaseline::Search(CoordinateView query, int max_results,
                                                       const std::vector<bool>& allowed_clips,
                                                       bool exact) const {
  std::vector<SearchResult> results;
  if (query.rows < 1 || max_results < 1) return results;
  const Scale& scale = *scales_[ScaleFor(query.rows)];
  std::vector<float> vector(vector_size());
  Resample(query, 0, query.rows, vector.data());
  const int64_t n = static_cast<int64_t>(scale.windows.size());
  for (int64_t k = options_.first_windows;; k *= 4) {
    results.clear();
    std::vector<bool> seen(library_.clip_count(), false);
    for (const auto& [w, squared] :
         NearestWindows(scale, vector.data(), static_cast<int>(k), exact)) {
      const Window& window = scale.windows[w];
      if (seen[window.clip] || (!allowed_clips.empty() && !allowed_clips[window.clip])) continue;
      seen[window.clip] = true;
      const LibraryIndex::ClipEntry& clip = library_.clip(window.clip);
      SearchResult& result = results.emplace_back();
      result.clip_index = window.clip;
      result.clip_id = clip.clip_id;
      result.clip_name = clip.name;
      result.first_frame = window.first_frame;
      result.last_frame = window.last_frame;
      result.start_s = window.first_frame / library_.rate();
      result.end_s = window.last_frame / library_.rate();
      result.score = std::sqrt(std::max(squared, 0.0f) / samples_);
      if (static_cast<int>(results.size()) == max_results) return results;
    }
    if (k >= n) return results;
  }
}

double WindowVectorBaseline::WindowRecall(CoordinateView query, int k) const {
  if (query.rows < 1) return 0;
  const Scale& scale = *scales_[ScaleFor(query.rows)];
  std::vector<float> vector(vector_size());
  Resample(query, 0, query.rows, vector.data());
  const auto exact = NearestWindows(scale, vector.data(), k, true);
  const auto approximate = NearestWindows(scale, vector.data(), k, false);
  if (exact.empty()) return 1;
  // Ties at the k-th distance may be broken either way: a window as near as the k-th counts
  // (FLANN sums the squares in another order: a relative 1e-5 either way).
  const float kth = exact.back().second * (1 + 1e-5f);
  int found = 0;
  for (const auto& [w, squared] : approximate) {
    found += squared <= kth || std::any_of(exact.begin(), exact.end(),
                                           [w = w](const auto& e) { return e.first == w; });
  }
  return static_cast<double>(std::min<int>(found, exact.size())) / exact.size();
}

}  // namespace motiondb::bench
