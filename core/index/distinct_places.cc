#include "core/index/internal/distinct_places.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace motiondb {

DistinctPlaces::DistinctPlaces(int k, int64_t separation, absl::FunctionRef<int(int64_t)> clip_of,
                               const std::vector<bool>& allowed)
    : k_(k), separation_(std::max<int64_t>(1, separation)), clip_of_(clip_of), allowed_(allowed) {}

float DistinctPlaces::worstDist() const {
  return full() ? by_distance_.rbegin()->first : std::numeric_limits<float>::max();
}

void DistinctPlaces::addPoint(float squared, size_t row) {
  if (k_ < 1 || (full() && squared >= worstDist())) return;
  const int64_t frame = first_frame_ + static_cast<int64_t>(row);
  const int clip = clip_of_(frame);
  if (!allowed_.empty() && !allowed_[clip]) return;
  // Kept places within `separation` lie in this bucket or the two beside it.
  const int64_t bucket = frame / separation_;
  std::vector<int> farther;
  for (int64_t b = bucket - 1; b <= bucket + 1; ++b) {
    const auto it = buckets_.find(Bucket{clip, b});
    if (it == buckets_.end()) continue;
    for (int id : it->second) {
      const Place& place = places_[id];
      if (std::abs(place.frame - frame) >= separation_) continue;
      if (std::make_pair(place.squared, place.frame) <= std::make_pair(squared, frame)) return;
      farther.push_back(id);
    }
  }
  for (int id : farther) Remove(id);
  const int id = static_cast<int>(places_.size());
  places_.push_back({frame, clip, squared});
  by_distance_.emplace(squared, id);
  buckets_[Bucket{clip, bucket}].push_back(id);
  if (static_cast<int>(by_distance_.size()) > k_) Remove(by_distance_.rbegin()->second);
}

void DistinctPlaces::Remove(int id) {
  const Place& place = places_[id];
  by_distance_.erase({place.squared, id});
  const auto it = buckets_.find(Bucket{place.clip, place.frame / separation_});
  std::erase(it->second, id);
  if (it->second.empty()) buckets_.erase(it);
}

std::vector<Neighbour> DistinctPlaces::Take() const {
  std::vector<Neighbour> nearest;
  nearest.reserve(by_distance_.size());
  for (const auto& [squared, id] : by_distance_) {
    nearest.push_back({places_[id].frame, std::sqrt(squared)});
  }
  return nearest;
}

}  // namespace motiondb
