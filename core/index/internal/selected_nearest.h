// A FLANN result set that keeps the k nearest points a FrameSelector admits (FAISS's IDSelector):
// the kd-tree meets the points as ever, and one refused never takes a place, so that the k kept
// are k admitted ones and the search runs once, however many it refuses.
//
// Not thread-safe: one per search.
#ifndef MOTIONDB_CORE_INDEX_INTERNAL_SELECTED_NEAREST_H_
#define MOTIONDB_CORE_INDEX_INTERNAL_SELECTED_NEAREST_H_

#include <cstdint>
#include <queue>
#include <utility>
#include <vector>

#include <flann/util/result_set.h>

#include "absl/functional/function_ref.h"
#include "core/index/library_index.h"

namespace motiondb {

class SelectedNearest final : public flann::ResultSet<float> {
 public:
  // `admits` says whether the point of a number (as set_rows() numbers them) may be kept; it
  // must outlive this (a named function object, not a temporary).
  SelectedNearest(int k, absl::FunctionRef<bool(int64_t number)> admits) : k_(k), admits_(admits) {}

  // The rows the next addPoint() calls name: row r is number first + r * every.
  void set_rows(int64_t first, int every) {
    first_ = first;
    every_ = every;
  }

  // flann::ResultSet: distances are squared; `row` as set_rows() says.
  bool full() const override { return static_cast<int>(kept_.size()) == k_; }
  float worstDist() const override;
  void addPoint(float squared, size_t row) override;

  // The kept points, nearest first (equals by number), with their (not squared) distances.
  std::vector<Neighbour> Take() const;

 private:
  int k_;
  absl::FunctionRef<bool(int64_t)> admits_;
  int64_t first_ = 0;
  int every_ = 1;
  std::priority_queue<std::pair<float, int64_t>> kept_;  // (squared, number), farthest on top
};

}  // namespace motiondb

#endif  // MOTIONDB_CORE_INDEX_INTERNAL_SELECTED_NEAREST_H_
