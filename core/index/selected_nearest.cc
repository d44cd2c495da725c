#include "core/index/internal/selected_nearest.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace motiondb {

float SelectedNearest::worstDist() const {
  return full() ? kept_.top().first : std::numeric_limits<float>::max();
}

void SelectedNearest::addPoint(float squared, size_t row) {
  if (k_ < 1) return;
  const int64_t number = first_ + static_cast<int64_t>(row) * every_;
  // Farther than the worst kept (or as far and later) cannot take its place: asked first, as
  // the selector's test costs more than the comparison.
  if (full() && std::make_pair(squared, number) >= kept_.top()) return;
  if (!admits_(number)) return;
  kept_.emplace(squared, number);
  if (static_cast<int>(kept_.size()) > k_) kept_.pop();
}

std::vector<Neighbour> SelectedNearest::Take() const {
  std::priority_queue<std::pair<float, int64_t>> kept = kept_;
  std::vector<Neighbour> nearest(kept.size());
  for (auto it = nearest.rbegin(); it != nearest.rend(); ++it, kept.pop()) {
    *it = {kept.top().second, std::sqrt(kept.top().first)};
  }
  return nearest;
}

}  // namespace motiondb
