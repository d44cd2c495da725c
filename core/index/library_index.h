// The searchable library of one space: every clip's projection (pre-scaled so that Euclidean
// distance is the space's pose metric) in a frames x dims block, the map between global frame
// numbers and (clip, frame), and a kd-tree over the first `ann_dims` coordinates that reads the
// coordinates in place.
//
// Clips added with WithClips() go into a second, smaller block with a kd-tree of its own, shared
// with the index they were added to, so that adding a clip costs in proportion to the recent
// additions rather than to the library (an ingest into hours of capture stays fast); once the
// recent additions exceed a sixteenth of the frames, everything is built again as one block.
//
// Immutable once made; thread-safe for any number of concurrent readers.
#ifndef MOTIONDB_CORE_INDEX_LIBRARY_INDEX_H_
#define MOTIONDB_CORE_INDEX_LIBRARY_INDEX_H_

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/functional/function_ref.h"
#include "absl/status/statusor.h"
#include "core/index/coordinate_view.h"
#include "core/motion/matrix.h"

namespace motiondb {

struct LibraryClip {
  int64_t clip_id = 0;
  std::string name;
  std::vector<std::string> tags;
  // frames x dims at the space rate, pre-scaled by the metric; moved into the index.
  RowMatrixXf coordinates;
};

// The seed search's dimensions unless a search says otherwise: the kd-tree's default dimensions
// too, since a search over other dimensions cannot use the tree. The thesis's 10 (Table 6.2)
// ranks seeds by dimensions the warp (5 by default) does not score: on 10 h of synthetic
// capture the exact search's ten best lay up to 1,759th among distinct places by the
// 10-dimensional pose distance and at most 170th by the 5-dimensional one
// (bench/notes/2026-12-02-scale-seeds.md).
inline constexpr int kDefaultAnnDims = 5;

// Seed windows a quarter of a second either side of the frame. Measured by brute force on 10 h
// of real capture (bench/notes/2026-12-04-scale-settle-bound.md; recall@10 against the exact
// search, 20 queries,
// 500 seeds): one pose 0.885, windows of 0.13 s 0.940, 0.27 s 0.950, 0.5 s 0.895.
inline constexpr double kDefaultSeedWindowS = 0.25;
// Longer windows than this span whole actions rather than a pose's motion.
inline constexpr double kMaxSeedWindowS = 2.0;

// The shape windows (LibraryIndex::NearestShapes): library windows at lengths about sqrt(2)
// apart, from kShapeShortestS to kShapeLongestS, each resampled to kShapeSamples poses of the
// first `shape_dims` coordinates; the query's shape is the query resampled alike.
inline constexpr int kShapeSamples = 16;
inline constexpr double kShapeShortestS = 0.5;
inline constexpr double kShapeLongestS = 5.7;  // 0.5 s x sqrt(2)^7, 170 frames at 30 Hz
// Windows start an eighth of their length apart (issue 39's prototype: a stride of L / 8 instead
// of 2 frames halved the index for the same precision).
inline constexpr int kShapeStrideDivisor = 8;

struct LibraryIndexOptions {
  // Dimensions of the kd-tree; searches with another ann_dims fall back to a linear scan.
  int ann_dims = kDefaultAnnDims;
  // Points per kd-tree leaf.
  int leaf_size = 32;
  // The kd-tree holds every n-th frame, n = CoarseFactor(rate) (core/index/coarse_rate.h: 2 at
  // 30 Hz, 8 at 120 Hz): seeds at about 15 Hz, a tree 1/n the size, built n times faster.
  // false: every frame.
  bool coarse_tree = true;
  // Seconds between the three poses of a seed window: a tree frame's pose and the poses this far
  // before and after it (clamped to the clip), in a second kd-tree of 3 x ann_dims dimensions
  // (NearestWindows), built by the first call that needs it, for 3 x ann_dims floats a tree
  // frame. A window tells a take's own motion through a pose from other takes passing the same
  // pose: see kDefaultSeedWindowS. 0: no windows (NearestWindows gives the nearest frames).
  double seed_window_s = kDefaultSeedWindowS;
  // Shape windows: the coordinates sampled (at most the library's), and the dimensions kept of
  // a window's kShapeSamples x shape_dims values, its principal axes (a window of smooth motion
  // is nearly determined by its first few): shape_index_dims floats a window.
  int shape_dims = 10;
  int shape_index_dims = 16;
};

// A library window found by its shape: frames first_frame.. of the clip of index `clip`.
struct ShapeWindow {
  int clip = 0;
  int64_t first_frame = 0;
  int64_t frames = 0;
  float distance = 0;  // between the shapes: about the RMS pose distance of their samples
};

// Which library frames a nearest-neighbour search may return (FAISS's IDSelector): those of the
// allowed clips (by index; empty: every clip) but one range of one clip's frames (clip -1: none),
// a stored query's own. The index tests the frames as its kd-trees meet them, so that the k
// nearest are k admitted frames, found in one search.
struct FrameSelector {
  std::vector<bool> allowed;
  int excluded_clip = -1;
  int64_t excluded_first = 0, excluded_last = -1;

  // The clips `allowed` marks, nothing excluded.
  static FrameSelector OfClips(std::vector<bool> allowed) {
    return {.allowed = std::move(allowed),
            .excluded_clip = -1,
            .excluded_first = 0,
            .excluded_last = -1};
  }
  bool AdmitsEvery() const { return allowed.empty() && excluded_clip < 0; }
  bool AdmitsClip(int clip) const { return allowed.empty() || allowed[clip]; }
  // Whether frame `frame` of the clip of index `clip` may be returned.
  bool Admits(int clip, int64_t frame) const { return AdmitsAny(clip, frame, frame); }
  // Whether some frame of first..last of that clip may be.
  bool AdmitsAny(int clip, int64_t first, int64_t last) const {
    return AdmitsClip(clip) &&
           (clip != excluded_clip || first < excluded_first || last > excluded_last);
  }
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

  // This library with `clips` added after its own clips (same rules as Build(); their ids must
  // be new). Shares this index's first block and kd-tree; the second is built anew from the
  // clips added since the last full build and these.
  absl::StatusOr<std::unique_ptr<LibraryIndex>> WithClips(std::vector<LibraryClip> clips) const;
  // This library with one clip's name and tags changed (a rename or re-tag). Shares every
  // coordinate block and kd-tree, copying only the clip entries. NOT_FOUND when the clip is not
  // in the library.
  absl::StatusOr<std::unique_ptr<LibraryIndex>> WithClipInfo(int64_t clip_id, std::string name,
                                                             std::vector<std::string> tags) const;

  double rate() const { return rate_; }
  int dims() const { return dims_; }
  int ann_dims() const { return options_.ann_dims; }
  // The kd-tree holds the global frames that are multiples of tree_every().
  int tree_every() const;
  int64_t total_frames() const { return total_frames_; }
  int clip_count() const { return static_cast<int>(clips_.size()); }
  // 1 after a full build; 2 while recent additions are kept apart.
  int block_count() const { return static_cast<int>(blocks_.size()); }
  const ClipEntry& clip(int index) const { return clips_[index]; }
  // Index of the clip with this id, or -1.
  int FindClip(int64_t clip_id) const;
  // The clip holding a global frame, and the frame's number within it.
  std::pair<int, int64_t> Locate(int64_t global_frame) const;
  CoordinateView clip_coordinates(int index) const;
  // A copy of clip_coordinates(index), all dims.
  RowMatrixXf CopyClipCoordinates(int index) const;

  // The k frames `selector` admits nearest to `point` over its first `dims` coordinates, nearest
  // first. Uses the kd-tree, and so only its frames (every tree_every()-th), when dims ==
  // ann_dims() and the allowed clips hold at least half the frames; otherwise an exact linear
  // scan over every frame of the allowed clips.
  std::vector<Neighbour> Nearest(const float* point, int dims, int k, float epsilon,
                                 const FrameSelector& selector) const;

  // The frame of clip `clip` within `reach` frames of its frame `frame` nearest to `point` over
  // its first `dims` coordinates (the earliest of equals), and its distance: a frame the kd-tree
  // found (one in tree_every()) moved to the nearest at the full rate.
  std::pair<int64_t, float> NearestFrameAround(const float* point, int dims, int clip,
                                               int64_t frame, int64_t reach) const;

  // The k nearest *places*: frames near `point` (over its first `dims` coordinates) of which
  // no two of one clip lie within `separation` frames, nearest first; a frame is kept unless a
  // nearer kept frame lies within `separation`, and drops the farther ones there (so a long
  // valley of the distance over time gives a place every `separation` frames, not one a frame).
  // Which frames are kept can depend on the order they are met in, so the kd-tree (used when
  // dims == ann_dims() and the allowed clips hold at least half the frames) and the linear
  // scan may differ where such chains meet.
  std::vector<Neighbour> NearestPlaces(const float* point, int dims, int k, int64_t separation,
                                       float epsilon, const FrameSelector& selector) const;

  // Frames between the poses of a seed window (LibraryIndexOptions::seed_window_s at rate()),
  // 0 when the index has no window tree.
  int window_frames() const { return window_frames_; }
  // The k frames whose seed windows are nearest to `rows`' window at `frame` (its poses at
  // frame - window_frames(), frame and frame + window_frames(), each clamped to its own rows,
  // over their first `dims` coordinates), nearest first, with the window distance. Tree and
  // scan as Nearest() does, over the window tree; window_frames() 0: Nearest() at `frame`.
  // `frame` must be one of `rows`' (0 <= frame < rows.rows), as the search's anchors are.
  std::vector<Neighbour> NearestWindows(CoordinateView rows, int64_t frame, int dims, int k,
                                        float epsilon, const FrameSelector& selector) const;

  // The shape windows' lengths in frames, increasing (about sqrt(2) apart; kShapeShortestS to
  // kShapeLongestS at rate()).
  const std::vector<int64_t>& shape_lengths() const { return shape_lengths_; }
  // The index of the shape length nearest `frames` (by ratio).
  int ShapeLengthNearest(int64_t frames) const;
  // The k windows of length shape_lengths()[length] nearest `query`'s shape (the query resampled
  // to kShapeSamples poses), nearest first, of which `selector` admits a frame (a window inside
  // the excluded range would take a place for results it cannot give). A clip shorter
  // than a length but at least a quarter of it is one window of that length, whole (resampled
  // alike). The windows and their kd-trees are built by the first call (thread-safe): about
  // 1.8 windows a frame at 30 Hz, shape_index_dims floats each (shape_bytes()).
  std::vector<ShapeWindow> NearestShapes(CoordinateView query, int length, int k, float epsilon,
                                         const FrameSelector& selector) const;

  // Bytes held: the coordinate blocks; the kd-trees and the seed windows they index; the shape
  // windows and their kd-trees (0 until a search asks for them).
  int64_t coordinate_bytes() const;
  int64_t tree_bytes() const;
  int64_t shape_bytes() const;

 private:
  class Tree;
  struct Windows;
  struct ShapeLevel;
  struct Shapes;
  struct Block;
  LibraryIndex(double rate, const LibraryIndexOptions& options, int dims);
  // A block of `clips` (validated) after `first_frame` global frames, with its kd-tree; appends
  // their entries.
  void AddBlock(std::vector<LibraryClip> clips, int64_t first_frame);
  void AddEntry(ClipEntry entry, int block);
  // Frames of the clips `selector` allows.
  int64_t AllowedFrames(const FrameSelector& selector) const;
  // Block b's seed windows, built on first use (thread-safe).
  const Windows& WindowsOf(int b) const;
  // The shape windows of every block, built on first use (thread-safe).
  const Shapes& ShapesOf() const;
  // The k nearest frames `selector` admits over one kd-tree of every block (tree_of(b): block
  // b's, null if none); the first block's must exist.
  std::vector<Neighbour> TreeNearest(absl::FunctionRef<const Tree*(int block)> tree_of,
                                     const float* point, int dims, int k, float epsilon,
                                     const FrameSelector& selector) const;
  // The k nearest frames `selector` admits by `distance` (frame of a clip, by index): through
  // `tree_nearest` (TreeNearest with the selector) when `tree_usable` and the allowed clips hold
  // most frames, else by a scan.
  std::vector<Neighbour> FilteredNearest(
      int k, const FrameSelector& selector, bool tree_usable,
      absl::FunctionRef<std::vector<Neighbour>(int k)> tree_nearest,
      absl::FunctionRef<float(int clip, int64_t frame)> distance) const;

  double rate_;
  LibraryIndexOptions options_;
  int dims_;
  int window_frames_;
  std::vector<int64_t> shape_lengths_;
  int64_t total_frames_ = 0;
  // The first block holds the clips of the last full build; a second one, if any, those added
  // since. Clips are numbered across blocks in order.
  std::vector<std::shared_ptr<const Block>> blocks_;
  std::vector<ClipEntry> clips_;
  std::vector<int> clip_block_;  // per clip: its block
  // Clip id -> index: searches filtered by clip ids look up every id.
  absl::flat_hash_map<int64_t, int> index_of_id_;
  // The shape windows of this snapshot, built by the first search that asks (ShapesOf).
  mutable std::once_flag shapes_built_;
  mutable std::atomic<bool> shapes_ready_{false};
  mutable std::unique_ptr<Shapes> shapes_;
};

}  // namespace motiondb

#endif  // MOTIONDB_CORE_INDEX_LIBRARY_INDEX_H_
