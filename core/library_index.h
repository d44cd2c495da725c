// The searchable library of one space: every clip's projection (pre-scaled so that Euclidean
// distance is the space's pose metric) in one frames x dims block, the map between global frame
// numbers and (clip, frame), and a kd-tree over the first `ann_dims` coordinates that reads the
// coordinates in place.
//
// Immutable after Build(); thread-safe for any number of concurrent readers. Not movable: the
// kd-tree points into the coordinate block.
#ifndef MOTIONDB_CORE_LIBRARY_INDEX_H_
#define MOTIONDB_CORE_LIBRARY_INDEX_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/coordinate_view.h"
#include "core/matrix.h"

namespace motiondb {

struct LibraryClip {
  int64_t clip_id = 0;
  std::string name;
  std::vector<std::string> tags;
  // frames x dims at the space rate, pre-scaled by the metric; moved into the index.
  RowMatrixXf coordinates;
};

struct LibraryIndexOptions {
  // Dimensions of the kd-tree; searches with another ann_dims fall back to a linear scan.
  int ann_dims = 10;
  // Points per kd-tree leaf.
  int leaf_size = 32;
};

struct Neighbour {
  int64_t frame;   // global frame number
  float distance;  // pose distance over the searched dimensions
};

class LibraryIndex {
 public:
  struct ClipEntry {
    int64_t clip_id;
    std::string name;
    std::vector<std::string> tags;
    int64_t first_frame;  // global number of the clip's frame 0
    int64_t frame_count;
  };

  // Clips must all have the same number of columns (at least ann_dims), at least one frame, and
  // finite coordinates; `rate` is the space's sample rate in frames per second.
  static absl::StatusOr<std::unique_ptr<LibraryIndex>> Build(std::vector<LibraryClip> clips,
                                                             double rate,
                                                             const LibraryIndexOptions& options);
  ~LibraryIndex();
  LibraryIndex(const LibraryIndex&) = delete;
  LibraryIndex& operator=(const LibraryIndex&) = delete;

  double rate() const { return rate_; }
  int dims() const { return static_cast<int>(coordinates_.cols()); }
  int ann_dims() const { return options_.ann_dims; }
  int64_t total_frames() const { return coordinates_.rows(); }
  int clip_count() const { return static_cast<int>(clips_.size()); }
  const ClipEntry& clip(int index) const { return clips_[index]; }
  // Index of the clip with this id, or -1.
  int FindClip(int64_t clip_id) const;
  // The clip holding a global frame, and the frame's number within it.
  std::pair<int, int64_t> Locate(int64_t global_frame) const;
  CoordinateView coordinates() const { return CoordinateView::Of(coordinates_); }
  CoordinateView clip_coordinates(int index) const {
    return coordinates().middle_rows(clips_[index].first_frame, clips_[index].frame_count);
  }

  // The k frames nearest to `point` over its first `dims` coordinates, nearest first. Uses the
  // kd-tree when dims == ann_dims() and every clip is allowed; otherwise an exact linear scan
  // over the allowed clips (`allowed_clips` empty: all).
  std::vector<Neighbour> Nearest(const float* point, int dims, int k, float epsilon,
                                 const std::vector<bool>& allowed_clips) const;

  // Bytes held: the coordinate block and the kd-tree.
  int64_t coordinate_bytes() const;
  int64_t tree_bytes() const;

 private:
  class Tree;
  LibraryIndex(double rate, const LibraryIndexOptions& options);

  double rate_;
  LibraryIndexOptions options_;
  RowMatrixXf coordinates_;
  std::vector<ClipEntry> clips_;
  std::unique_ptr<Tree> tree_;
};

}  // namespace motiondb

#endif  // MOTIONDB_CORE_LIBRARY_INDEX_H_
