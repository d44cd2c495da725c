#include "core/index/internal/distinct_places.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace motiondb {

DistinctPlaces::DistinctPlaces(int k, int64_t separation,
                               absl::FunctionRef<std::pair<int, int64_t>(int64_t)> locate,
                               const FrameSelector& selector)
    : k_(k), separation_(std::max<int64_t>(1, separation)), locate_(locate), selector_(selector) {}

float DistinctPlaces::worstDist() const {
  if (!full()) return std::numeric_limits<float>::max();
  PopRemoved();
  return farthest_.top().first;
}

void DistinctPlaces::PopRemoved() const {
  while (!farthest_.empty() && !places_[farthest_.top().second].kept) farthest_.pop();
}

void DistinctPlaces::addPoint(float squared, size_t row) {
  if (k_ < 1 || (full() && squared >= worstDist())) return;
  const int64_t frame = first_frame_ + static_cast<int64_t>(row) * every_;
  const auto [clip, clip_frame] = locate_(frame);
  if (!selector_.Admits(clip, clip_frame)) return;
  // Kept places within `separation` lie in this bucket or the two beside it.
  const int64_t bucket = frame / separation_;
  int farther[3];
  int farther_count = 0;
  for (int64_t b = bucket - 1; b <= bucket + 1; ++b) {
    const auto it = buckets_.find(Bucket{clip, b});
    if (it == buckets_.end()) continue;
    const Place& place = places_[it->second];
    if (std::abs(place.frame - frame) >= separation_) continue;
    if (std::make_pair(place.squared, place.frame) <= std::make_pair(squared, frame)) return;
    farther[farther_count++] = it->second;
  }
  for (int i = 0; i < farther_count; ++i) Remove(farther[i]);
  const int id = static_cast<int>(places_.size());
  places_.push_back({frame, clip, squared, true});
  farthest_.emplace(squared, id);
  buckets_[Bucket{clip, bucket}] = id;
  if (++kept_ > k_) {
    PopRemoved();
    Remove(farthest_.top().second);
  }
}

void DistinctPlaces::Remove(int id) {
  Place& place = places_[id];
  place.kept = false;
  --kept_;
  buckets_.erase(Bucket{place.clip, place.frame / separation_});
}

std::vector<Neighbour> DistinctPlaces::Take() const {
  std::vector<std::pair<float, int64_t>> kept;
  kept.reserve(kept_);
  for (const Place& place : places_) {
    if (place.kept) kept.emplace_back(place.squared, place.frame);
  }
  std::sort(kept.begin(), kept.end());
  std::vector<Neighbour> nearest;
  nearest.reserve(kept.size());
  for (const auto& [squared, frame] : kept) nearest.push_back({frame, std::sqrt(squared)});
  return nearest;
}

}  // namespace motiondb
