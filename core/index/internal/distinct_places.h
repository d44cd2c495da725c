// A FLANN result set that keeps the k nearest *places* rather than the k nearest frames: a
// frame is kept only when no nearer kept frame of its clip lies within `separation` frames, and
// a kept frame drops the farther ones around it. Adjacent frames of one held pose are near
// duplicates; without this, the k nearest pile up in the few instances that hold the pose
// longest (issue 11: 1000 seeds formed 24 clusters in 10 h at 120 Hz).
//
// Not thread-safe: one per search.
#ifndef MOTIONDB_CORE_INDEX_INTERNAL_DISTINCT_PLACES_H_
#define MOTIONDB_CORE_INDEX_INTERNAL_DISTINCT_PLACES_H_

#include <cstdint>
#include <queue>
#include <utility>
#include <vector>

#include <flann/util/result_set.h>

#include "absl/container/flat_hash_map.h"
#include "absl/functional/function_ref.h"
#include "core/index/library_index.h"

namespace motiondb {

class DistinctPlaces final : public flann::ResultSet<float> {
 public:
  // `locate` gives a global frame's clip and frame in it (LibraryIndex::Locate); frames that
  // `selector` does not admit are ignored. Both must outlive this.
  DistinctPlaces(int k, int64_t separation,
                 absl::FunctionRef<std::pair<int, int64_t>(int64_t)> locate,
                 const FrameSelector& selector);

  // The rows the next addPoint() calls name: row r is global frame first_frame + r * every.
  void set_rows(int64_t first_frame, int every) {
    first_frame_ = first_frame;
    every_ = every;
  }

  // flann::ResultSet: distances are squared; `row` as set_rows() says.
  bool full() const override { return kept_ == k_; }
  float worstDist() const override;
  void addPoint(float squared, size_t row) override;

  // The kept places, nearest first, with their (not squared) distances.
  std::vector<Neighbour> Take() const;

 private:
  struct Place {
    int64_t frame;
    int clip;
    float squared;
    bool kept;
  };
  using Bucket = std::pair<int, int64_t>;  // (clip, frame / separation)

  // Drops kept places from the top of the heap.
  void PopRemoved() const;
  void Remove(int id);

  int k_;
  int64_t separation_;
  absl::FunctionRef<std::pair<int, int64_t>(int64_t)> locate_;
  const FrameSelector& selector_;
  int64_t first_frame_ = 0;
  int every_ = 1;
  int kept_ = 0;
  std::vector<Place> places_;  // by id; removed ones stay, marked
  // (squared, id), farthest on top; removed places leave lazily.
  mutable std::priority_queue<std::pair<float, int>> farthest_;
  // The kept place of each time bucket: frames of one bucket are closer than `separation`, so
  // a bucket holds one at most.
  absl::flat_hash_map<Bucket, int> buckets_;
};

}  // namespace motiondb

#endif  // MOTIONDB_CORE_INDEX_INTERNAL_DISTINCT_PLACES_H_
