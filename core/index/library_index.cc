#include "core/index/library_index.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iterator>
#include <limits>
#include <mutex>
#include <tuple>

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>

#include <Eigen/Eigenvalues>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/index/coarse_rate.h"
#include "core/index/internal/distinct_places.h"
#include "core/index/internal/selected_nearest.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

bool Nearer(const Neighbour& a, const Neighbour& b) {
  return a.distance < b.distance || (a.distance == b.distance && a.frame < b.frame);
}

}  // namespace

// A single kd-tree (exact, and the fastest FLANN index at ~10 dimensions) over the first `dims`
// columns of `count` rows `stride` floats apart from `points`, read in place. Its point i is the
// block's row first + i * every.
class LibraryIndex::Tree {
 public:
  Tree(const float* points, int64_t count, int dims, int stride, int leaf_size, int64_t first,
       int every)
      : index_(
            flann::Matrix<float>(const_cast<float*>(points), count, dims, stride * sizeof(float)),
            flann::KDTreeSingleIndexParams(leaf_size, /*reorder=*/false)),
        first_(first),
        every_(every) {
    index_.buildIndex();
  }

  int64_t first() const { return first_; }
  int every() const { return every_; }
  int64_t points() const { return static_cast<int64_t>(index_.size()); }

  // The k nearest, or of those within `within`, as many as there are up to k.
  std::vector<Neighbour> Nearest(const float* point, int dims, int k, float epsilon,
                                 float within = std::numeric_limits<float>::infinity()) const {
    std::vector<float> query(point, point + dims);
    std::vector<size_t> indices(k);
    std::vector<float> squared(k);
    flann::Matrix<size_t> index_matrix(indices.data(), 1, k);
    flann::Matrix<float> squared_matrix(squared.data(), 1, k);
    flann::SearchParams params;
    params.eps = epsilon;
    params.sorted = true;
    params.cores = 1;
    const flann::Matrix<float> query_matrix(query.data(), 1, dims);
    int found = 0;
    if (std::isinf(within)) {
      found = index_.knnSearch(query_matrix, index_matrix, squared_matrix, k, params);
    } else {
      // FLANN's L2 is squared; the slack keeps a neighbour exactly at `within`.
      params.max_neighbors = k;
      found = std::min(k, index_.radiusSearch(query_matrix, index_matrix, squared_matrix,
                                              within * within * 1.0001f, params));
    }
    std::vector<Neighbour> result(found);
    for (int i = 0; i < found; ++i) {
      result[i] = {first_ + static_cast<int64_t>(indices[i]) * every_, std::sqrt(squared[i])};
    }
    return result;
  }

  // Every point nearer than `found`'s worst, offered to it (numbered from 0: point i is row
  // first() + i * every()).
  void Offer(const float* point, float epsilon, flann::ResultSet<float>& found) const {
    flann::SearchParams params;
    params.eps = epsilon;
    index_.findNeighbors(found, point, params);
  }

  // FLANN's own count (node pool and index permutation) plus its row-pointer table.
  int64_t bytes() const {
    return static_cast<int64_t>(index_.usedMemory()) +
           static_cast<int64_t>(index_.size()) * static_cast<int64_t>(sizeof(float*));
  }

 private:
  flann::KDTreeSingleIndex<flann::L2<float>> index_;
  int64_t first_;
  int every_;
};

// A block's seed windows and their kd-tree.
struct LibraryIndex::Windows {
  RowMatrixXf rows;       // per pose-tree point, its window (3 x ann_dims) in `basis`
  Eigen::MatrixXf basis;  // the first block's: the query is turned once for every block
  std::unique_ptr<Tree> tree;
};

// The shape windows of one length: a row a window (its shape turned to the principal axes and
// truncated), the windows of clip c being rows clip_first[c]..clip_first[c + 1] - 1, and their
// kd-tree (none when the length has no window).
struct LibraryIndex::ShapeLevel {
  RowMatrixXf rows;
  std::vector<int32_t> first_frame;  // per window, in its clip
  std::vector<int32_t> frames;       // per window: the length, or a short clip's own
  std::vector<int64_t> clip_first;   // per clip, and one past the last
  std::unique_ptr<Tree> tree;
};

struct LibraryIndex::Shapes {
  Eigen::MatrixXf basis;  // kShapeSamples x shape_dims values -> shape_index_dims axes
  int dims = 0;           // the coordinates sampled
  std::vector<ShapeLevel> levels;
};

struct LibraryIndex::Block {
  RowMatrixXf coordinates;
  int64_t first_frame = 0;  // global number of row 0
  std::unique_ptr<Tree> pose_tree;
  // The seed windows of the pose tree's points, built by the first search that asks
  // (WindowsOf): most searches never do, and they take 3 x ann_dims floats a tree point and a
  // second kd-tree build.
  mutable std::once_flag windows_built;
  mutable std::atomic<bool> windows_ready{false};  // set once `windows` holds a tree
  mutable Windows windows;
};

namespace {

// Recent additions beyond 1 / kFullBuildShare of the frames make WithClips() build everything
// anew. Measured on Bandai (55k frames): with a tenth of the frames in the second tree, searches
// took 10% longer (p50 1.87 -> 2.07 ms); a sixteenth costs less at search and still spreads each
// full build over a sixteenth of the library added clip by clip.
constexpr int64_t kFullBuildShare = 16;

absl::Status ValidateClips(const std::vector<LibraryClip>& clips, Eigen::Index dims) {
  for (const LibraryClip& clip : clips) {
    if (clip.coordinates.cols() != dims || clip.coordinates.rows() == 0) {
      return absl::InvalidArgumentError(absl::StrCat(
          "clip ", clip.clip_id, " ('", clip.name, "') has ", clip.coordinates.rows(), " x ",
          clip.coordinates.cols(), " coordinates; expected at least one frame of ", dims));
    }
    if (!clip.coordinates.allFinite()) {
      return absl::InvalidArgumentError(
          absl::StrCat("clip ", clip.clip_id, " ('", clip.name, "') has non-finite coordinates"));
    }
  }
  return absl::OkStatus();
}

// Writes the seed window of `rows` at `frame` (LibraryIndex::NearestWindows) to `out`, 3 x dims.
void WriteWindow(CoordinateView rows, int64_t frame, int offset, int dims, float* out) {
  for (const int64_t at : {frame - offset, frame, frame + offset}) {
    const float* pose = rows.row(std::clamp<int64_t>(at, 0, rows.rows - 1));
    out = std::copy(pose, pose + dims, out);
  }
}

// Writes the shape of rows first..first + frames - 1 of `rows`: kShapeSamples poses evenly
// spaced from its first row to its last, linearly interpolated, over the first `dims`
// coordinates, scaled by 1 / sqrt(kShapeSamples) so that the distance between two shapes is the
// root mean square of their samples' pose distances. kShapeSamples x dims values.
void WriteShape(CoordinateView rows, int64_t first, int64_t frames, int dims, float* out) {
  const float scale = 1.0f / std::sqrt(static_cast<float>(kShapeSamples));
  const int64_t last = first + frames - 1;
  for (int i = 0; i < kShapeSamples; ++i) {
    const double at =
        static_cast<double>(first) + static_cast<double>(frames - 1) * i / (kShapeSamples - 1);
    const int64_t below = std::min(last, static_cast<int64_t>(at));
    const int64_t above = std::min(last, below + 1);
    const float w = static_cast<float>(at - static_cast<double>(below));
    const float* a = rows.row(below);
    const float* b = rows.row(above);
    for (int k = 0; k < dims; ++k) *out++ = scale * ((1.0f - w) * a[k] + w * b[k]);
  }
}

// Rows taken at once by PrincipalAxes and TurnRows: a copy of millions of rows would double the
// build's memory for nothing.
constexpr Eigen::Index kRowChunk = 4096;

// The eigenvectors of the rows' covariance, by decreasing eigenvalue: an orthonormal basis.
Eigen::MatrixXf PrincipalAxes(const RowMatrixXf& rows) {
  const Eigen::Index n = rows.rows(), d = rows.cols();
  Eigen::RowVectorXd sum = Eigen::RowVectorXd::Zero(d);
  Eigen::MatrixXd products = Eigen::MatrixXd::Zero(d, d);
  for (Eigen::Index first = 0; first < n; first += kRowChunk) {
    const Eigen::MatrixXd chunk =
        rows.middleRows(first, std::min(kRowChunk, n - first)).cast<double>();
    sum += chunk.colwise().sum();
    products.noalias() += chunk.transpose() * chunk;
  }
  const Eigen::RowVectorXd mean = sum / static_cast<double>(std::max<Eigen::Index>(1, n));
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(
      products - static_cast<double>(n) * mean.transpose() * mean);
  return solver.eigenvectors().rowwise().reverse().cast<float>();
}

// rows = rows * basis, a chunk at a time.
void TurnRows(RowMatrixXf& rows, const Eigen::MatrixXf& basis) {
  for (Eigen::Index first = 0; first < rows.rows(); first += kRowChunk) {
    auto chunk = rows.middleRows(first, std::min(kRowChunk, rows.rows() - first));
    chunk = (chunk * basis).eval();
  }
}

}  // namespace

LibraryIndex::LibraryIndex(double rate, const LibraryIndexOptions& options, int dims)
    : rate_(rate),
      options_(options),
      dims_(dims),
      // Capped: only a rate beyond any capture's could reach it.
      window_frames_(static_cast<int>(std::lround(std::min(options.seed_window_s * rate, 1e9)))) {
  // Lengths sqrt(2) apart in seconds; at a low rate, lengths that round alike are one.
  for (double seconds = kShapeShortestS; seconds <= kShapeLongestS * 1.001;
       seconds *= std::sqrt(2.0)) {
    const int64_t frames = std::max<int64_t>(2, std::llround(std::min(seconds * rate, 1e9)));
    if (shape_lengths_.empty() || frames > shape_lengths_.back()) shape_lengths_.push_back(frames);
  }
}

LibraryIndex::~LibraryIndex() = default;

absl::StatusOr<std::unique_ptr<LibraryIndex>> LibraryIndex::Build(
    std::vector<LibraryClip> clips, double rate, const LibraryIndexOptions& options) {
  if (!std::isfinite(rate) || rate <= 0.0) {
    return absl::InvalidArgumentError(absl::StrCat("library rate must be positive, got ", rate));
  }
  if (options.ann_dims < 1 || options.leaf_size < 1 || options.shape_dims < 1 ||
      options.shape_index_dims < 1) {
    return absl::InvalidArgumentError(
        "ann_dims, leaf_size, shape_dims and shape_index_dims must be at least 1");
  }
  if (!(options.seed_window_s >= 0.0 && options.seed_window_s <= kMaxSeedWindowS)) {
    return absl::InvalidArgumentError(absl::StrCat("seed_window_s must be in [0, ", kMaxSeedWindowS,
                                                   "], got ", options.seed_window_s));
  }
  if (clips.empty()) return absl::InvalidArgumentError("library has no clips");
  const Eigen::Index dims = clips[0].coordinates.cols();
  if (dims < options.ann_dims) {
    return absl::InvalidArgumentError(
        absl::StrCat("library has ", dims, " dimensions, fewer than ann_dims ", options.ann_dims));
  }
  MOTIONDB_RETURN_IF_ERROR(ValidateClips(clips, dims));
  std::unique_ptr<LibraryIndex> index(new LibraryIndex(rate, options, static_cast<int>(dims)));
  index->AddBlock(std::move(clips), 0);
  return index;
}

absl::StatusOr<std::unique_ptr<LibraryIndex>> LibraryIndex::WithClips(
    std::vector<LibraryClip> clips) const {
  if (clips.empty()) return absl::InvalidArgumentError("no clips to add");
  MOTIONDB_RETURN_IF_ERROR(ValidateClips(clips, dims_));
  int64_t added = 0;
  for (size_t i = 0; i < clips.size(); ++i) {
    const bool repeated = std::any_of(clips.begin(), clips.begin() + i, [&](const LibraryClip& c) {
      return c.clip_id == clips[i].clip_id;
    });
    if (FindClip(clips[i].clip_id) >= 0 || repeated) {
      return absl::AlreadyExistsError(
          absl::StrCat("clip ", clips[i].clip_id, " is in the library already"));
    }
    added += clips[i].coordinates.rows();
  }
  const int64_t base_frames = blocks_[0]->coordinates.rows();
  const int64_t recent_frames = total_frames_ - base_frames;
  // Every clip but those of the base block is copied into the new block (or all of them, when
  // the recent additions have grown too large to keep apart).
  const bool full_build = (recent_frames + added) * kFullBuildShare > total_frames_ + added;
  std::vector<LibraryClip> block;
  for (int c = 0; c < clip_count(); ++c) {
    if (!full_build && clip_block_[c] == 0) continue;
    block.push_back({clips_[c].clip_id, clips_[c].name, clips_[c].tags, CopyClipCoordinates(c)});
  }
  std::move(clips.begin(), clips.end(), std::back_inserter(block));
  if (full_build) return Build(std::move(block), rate_, options_);
  std::unique_ptr<LibraryIndex> index(new LibraryIndex(rate_, options_, dims_));
  index->blocks_.push_back(blocks_[0]);
  for (int c = 0; c < clip_count() && clip_block_[c] == 0; ++c) {
    index->AddEntry(clips_[c], 0);
  }
  index->total_frames_ = base_frames;
  index->AddBlock(std::move(block), base_frames);
  return index;
}

absl::StatusOr<std::unique_ptr<LibraryIndex>> LibraryIndex::WithClipInfo(
    int64_t clip_id, std::string name, std::vector<std::string> tags) const {
  const int c = FindClip(clip_id);
  if (c < 0) return absl::NotFoundError(absl::StrCat("clip ", clip_id, " is not in the library"));
  std::unique_ptr<LibraryIndex> index(new LibraryIndex(rate_, options_, dims_));
  index->total_frames_ = total_frames_;
  index->blocks_ = blocks_;
  index->clips_ = clips_;
  index->clip_block_ = clip_block_;
  index->index_of_id_ = index_of_id_;
  index->clips_[c].name = std::move(name);
  index->clips_[c].tags = std::move(tags);
  return index;
}

void LibraryIndex::AddBlock(std::vector<LibraryClip> clips, int64_t first_frame) {
  auto block = std::make_shared<Block>();
  block->first_frame = first_frame;
  int64_t rows = 0;
  for (const LibraryClip& clip : clips) rows += clip.coordinates.rows();
  block->coordinates.resize(rows, dims_);
  int64_t next = 0;
  for (LibraryClip& clip : clips) {
    block->coordinates.middleRows(next, clip.coordinates.rows()) = clip.coordinates;
    AddEntry({clip.clip_id, std::move(clip.name), std::move(clip.tags), first_frame + next,
              clip.coordinates.rows()},
             static_cast<int>(blocks_.size()));
    next += clip.coordinates.rows();
    clip.coordinates = RowMatrixXf();  // release each copy as soon as it is in the block
  }
  // The tree's frames are the global frames that are multiples of tree_every(), whatever the
  // blocks: a library grown clip by clip seeds as one built at once.
  // A block shorter than the gap to its first such frame has none, and no tree.
  const int every = tree_every();
  const int64_t first_tree_row = (every - first_frame % every) % every;
  const int ann_dims = options_.ann_dims;
  if (first_tree_row < rows) {
    const int64_t points = (rows - first_tree_row + every - 1) / every;
    block->pose_tree =
        std::make_unique<Tree>(block->coordinates.row(first_tree_row).data(), points, ann_dims,
                               every * dims_, options_.leaf_size, first_tree_row, every);
  }
  blocks_.push_back(std::move(block));
  total_frames_ += rows;
}

const LibraryIndex::Windows& LibraryIndex::WindowsOf(int b) const {
  const Block& block = *blocks_[b];
  std::call_once(block.windows_built, [&] {
    if (!block.pose_tree) return;
    const Tree& poses = *block.pose_tree;
    const int dims = options_.ann_dims;
    RowMatrixXf& rows = block.windows.rows;
    rows.resize(poses.points(), 3 * dims);
    for (int c = 0; c < clip_count(); ++c) {
      if (clip_block_[c] != b) continue;
      const CoordinateView clip = clip_coordinates(c);
      const int64_t clip_row = clips_[c].first_frame - block.first_frame;
      // The clip's first tree row, then every every()-th.
      int64_t row = poses.first() +
                    (clip_row - poses.first() + poses.every() - 1) / poses.every() * poses.every();
      for (; row < clip_row + clip.rows; row += poses.every()) {
        WriteWindow(clip, row - clip_row, window_frames_, dims,
                    rows.row((row - poses.first()) / poses.every()).data());
      }
    }
    // The windows' principal axes: distances are the same, but the kd-tree, which splits one
    // axis at a time, then separates windows of correlated poses in fewer levels (10 h of real
    // capture, 500 seeds: 2.65 -> 2.04 ms).
    block.windows.basis = b == 0 ? PrincipalAxes(rows) : WindowsOf(0).basis;
    TurnRows(rows, block.windows.basis);
    block.windows.tree = std::make_unique<Tree>(rows.data(), rows.rows(), 3 * dims, 3 * dims,
                                                options_.leaf_size, poses.first(), poses.every());
    block.windows_ready.store(true, std::memory_order_release);
  });
  return block.windows;
}

const LibraryIndex::Shapes& LibraryIndex::ShapesOf() const {
  std::call_once(shapes_built_, [&] {
    auto shapes = std::make_unique<Shapes>();
    shapes->dims = std::min(options_.shape_dims, dims_);
    const int values = kShapeSamples * shapes->dims;
    const int kept = std::min(options_.shape_index_dims, values);
    // Every window of one length, clip by clip: calls `window(first_frame, frames)`.
    const auto for_each_window = [&](int c, int64_t length, auto&& window) {
      const int64_t frames = clips_[c].frame_count;
      if (frames < length) {
        if (frames * 4 >= length) window(int64_t{0}, frames);
        return;
      }
      const int64_t stride = std::max<int64_t>(1, length / kShapeStrideDivisor);
      for (int64_t first = 0; first + length <= frames; first += stride) window(first, length);
      // The clip's end, when the strides pass over it.
      if ((frames - length) % stride != 0) window(frames - length, length);
    };
    // The principal axes of a sample of the windows (of every length): a full pass would cost
    // values^2 multiplications a window.
    int64_t windows = 0;
    for (const int64_t length : shape_lengths_) {
      for (int c = 0; c < clip_count(); ++c) {
        for_each_window(c, length, [&](int64_t, int64_t) { ++windows; });
      }
    }
    constexpr int64_t kBasisSample = 50'000;
    const int64_t every = std::max<int64_t>(1, windows / kBasisSample);
    RowMatrixXf sample((windows + every - 1) / every, values);
    int64_t seen = 0, taken = 0;
    for (const int64_t length : shape_lengths_) {
      for (int c = 0; c < clip_count(); ++c) {
        const CoordinateView clip = clip_coordinates(c);
        for_each_window(c, length, [&](int64_t first, int64_t frames) {
          if (seen++ % every == 0 && taken < sample.rows()) {
            WriteShape(clip, first, frames, shapes->dims, sample.row(taken++).data());
          }
        });
      }
    }
    shapes->basis = PrincipalAxes(sample.topRows(taken)).leftCols(kept);
    Eigen::RowVectorXf shape(values);
    for (const int64_t length : shape_lengths_) {
      ShapeLevel& level = shapes->levels.emplace_back();
      int64_t count = 0;
      for (int c = 0; c < clip_count(); ++c) {
        for_each_window(c, length, [&](int64_t, int64_t) { ++count; });
      }
      level.rows.resize(count, kept);
      level.first_frame.reserve(count);
      level.frames.reserve(count);
      level.clip_first.reserve(clip_count() + 1);
      int64_t row = 0;
      for (int c = 0; c < clip_count(); ++c) {
        level.clip_first.push_back(row);
        const CoordinateView clip = clip_coordinates(c);
        for_each_window(c, length, [&](int64_t first, int64_t frames) {
          WriteShape(clip, first, frames, shapes->dims, shape.data());
          level.rows.row(row++) = shape * shapes->basis;
          level.first_frame.push_back(static_cast<int32_t>(first));
          level.frames.push_back(static_cast<int32_t>(frames));
        });
      }
      level.clip_first.push_back(row);
      if (count > 0) {
        level.tree = std::make_unique<Tree>(level.rows.data(), count, kept, kept,
                                            options_.leaf_size, /*first=*/0, /*every=*/1);
      }
    }
    shapes_ = std::move(shapes);
    shapes_ready_.store(true, std::memory_order_release);
  });
  return *shapes_;
}

int LibraryIndex::ShapeLengthNearest(int64_t frames) const {
  int best = 0;
  double best_ratio = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < shape_lengths_.size(); ++i) {
    const double ratio = std::abs(std::log(static_cast<double>(shape_lengths_[i]) /
                                           static_cast<double>(std::max<int64_t>(1, frames))));
    if (ratio < best_ratio) {
      best_ratio = ratio;
      best = static_cast<int>(i);
    }
  }
  return best;
}

std::vector<ShapeWindow> LibraryIndex::NearestShapes(CoordinateView query, int length, int k,
                                                     float epsilon,
                                                     const FrameSelector& selector) const {
  const Shapes& shapes = ShapesOf();
  const ShapeLevel& level = shapes.levels[length];
  const int64_t count = level.rows.rows();
  if (count == 0 || k <= 0) return {};
  Eigen::RowVectorXf shape(kShapeSamples * shapes.dims);
  WriteShape(query, 0, query.rows, shapes.dims, shape.data());
  const Eigen::RowVectorXf point = shape * shapes.basis;
  const int dims = static_cast<int>(point.size());
  const auto window_of = [&](int clip, int64_t row, float distance) {
    return ShapeWindow{clip, level.first_frame[row], level.frames[row], distance};
  };
  const auto clip_of_row = [&](int64_t row) {
    return static_cast<int>(
        std::upper_bound(level.clip_first.begin(), level.clip_first.end(), row) -
        level.clip_first.begin() - 1);
  };
  const auto admits = [&](int clip, int64_t row) {
    return selector.AdmitsAny(clip, level.first_frame[row],
                              level.first_frame[row] + level.frames[row] - 1);
  };
  int64_t allowed = count;
  if (!selector.allowed.empty()) {
    allowed = 0;
    for (int c = 0; c < clip_count(); ++c) {
      if (selector.allowed[c]) allowed += level.clip_first[c + 1] - level.clip_first[c];
    }
  }
  std::vector<ShapeWindow> found;
  if (allowed * 2 >= count) {
    // As FilteredNearest: the selector tested as the tree meets the windows.
    const auto admits_row = [&](int64_t row) { return admits(clip_of_row(row), row); };
    SelectedNearest nearest(k, admits_row);
    level.tree->Offer(point.data(), epsilon, nearest);
    for (const Neighbour& n : nearest.Take()) {
      found.push_back(window_of(clip_of_row(n.frame), n.frame, n.distance));
    }
    return found;
  }
  for (int c = 0; c < clip_count(); ++c) {
    if (!selector.AdmitsClip(c)) continue;
    for (int64_t row = level.clip_first[c]; row < level.clip_first[c + 1]; ++row) {
      if (!admits(c, row)) continue;
      found.push_back(window_of(c, row, Distance(point.data(), level.rows.row(row).data(), dims)));
    }
  }
  const size_t keep = std::min<size_t>(k, found.size());
  std::partial_sort(found.begin(), found.begin() + keep, found.end(),
                    [](const ShapeWindow& a, const ShapeWindow& b) {
                      return a.distance < b.distance ||
                             (a.distance == b.distance &&
                              std::tie(a.clip, a.first_frame) < std::tie(b.clip, b.first_frame));
                    });
  found.resize(keep);
  return found;
}

CoordinateView LibraryIndex::clip_coordinates(int index) const {
  const Block& block = *blocks_[clip_block_[index]];
  return CoordinateView::Of(block.coordinates)
      .middle_rows(clips_[index].first_frame - block.first_frame, clips_[index].frame_count);
}

RowMatrixXf LibraryIndex::CopyClipCoordinates(int index) const {
  const CoordinateView view = clip_coordinates(index);
  RowMatrixXf copy(view.rows, dims_);
  for (int64_t r = 0; r < view.rows; ++r) {
    std::copy(view.row(r), view.row(r) + dims_, copy.row(r).data());
  }
  return copy;
}

std::vector<Neighbour> LibraryIndex::TreeNearest(absl::FunctionRef<const Tree*(int block)> tree_of,
                                                 const float* point, int dims, int k, float epsilon,
                                                 const FrameSelector& selector) const {
  if (!selector.AdmitsEvery()) {
    const auto admits = [&](int64_t frame) {
      const auto [clip, clip_frame] = Locate(frame);
      return selector.Admits(clip, clip_frame);
    };
    SelectedNearest nearest(k, admits);
    for (int b = 0; b < block_count(); ++b) {
      const Tree* tree = tree_of(b);
      if (!tree) continue;
      nearest.set_rows(blocks_[b]->first_frame + tree->first(), tree->every());
      tree->Offer(point, epsilon, nearest);
    }
    return nearest.Take();
  }
  const Tree& base = *tree_of(0);  // the first block starts at frame 0, a tree frame
  std::vector<Neighbour> all =
      base.Nearest(point, dims, static_cast<int>(std::min<int64_t>(k, base.points())), epsilon);
  const Tree* added = blocks_.size() > 1 ? tree_of(1) : nullptr;
  if (!added) return all;
  // The recent additions' tree is asked only for frames nearer than the base's k-th nearest:
  // with k in the thousands, that is most of the cost of a second tree saved.
  const float within = static_cast<int>(all.size()) == k ? all.back().distance
                                                         : std::numeric_limits<float>::infinity();
  for (Neighbour n : added->Nearest(
           point, dims, static_cast<int>(std::min<int64_t>(k, added->points())), epsilon, within)) {
    n.frame += blocks_[1]->first_frame;
    all.push_back(n);
  }
  const size_t keep = std::min<size_t>(k, all.size());
  std::partial_sort(all.begin(), all.begin() + keep, all.end(), Nearer);
  all.resize(keep);
  return all;
}

void LibraryIndex::AddEntry(ClipEntry entry, int block) {
  index_of_id_.try_emplace(entry.clip_id, clip_count());  // the first clip of an id wins
  clips_.push_back(std::move(entry));
  clip_block_.push_back(block);
}

int LibraryIndex::FindClip(int64_t clip_id) const {
  const auto it = index_of_id_.find(clip_id);
  return it == index_of_id_.end() ? -1 : it->second;
}

std::pair<int, int64_t> LibraryIndex::Locate(int64_t global_frame) const {
  const auto it = std::upper_bound(
      clips_.begin(), clips_.end(), global_frame,
      [](int64_t frame, const ClipEntry& clip) { return frame < clip.first_frame; });
  const int clip = static_cast<int>(it - clips_.begin()) - 1;
  return {clip, global_frame - clips_[clip].first_frame};
}

int LibraryIndex::tree_every() const { return options_.coarse_tree ? CoarseFactor(rate_) : 1; }

std::vector<Neighbour> LibraryIndex::FilteredNearest(
    int k, const FrameSelector& selector, bool tree_usable,
    absl::FunctionRef<std::vector<Neighbour>(int k)> tree_nearest,
    absl::FunctionRef<float(int clip, int64_t frame)> distance) const {
  k = static_cast<int>(std::min<int64_t>(k, total_frames()));
  // The tree meets the frames of the clips left out too: worth it while they are few.
  if (tree_usable && AllowedFrames(selector) * 2 >= total_frames()) return tree_nearest(k);
  std::vector<Neighbour> all;
  for (int c = 0; c < clip_count(); ++c) {
    if (!selector.AdmitsClip(c)) continue;
    for (int64_t f = 0; f < clips_[c].frame_count; ++f) {
      if (selector.Admits(c, f)) all.push_back({clips_[c].first_frame + f, distance(c, f)});
    }
  }
  const size_t keep = std::min<size_t>(k, all.size());
  std::partial_sort(all.begin(), all.begin() + keep, all.end(), Nearer);
  all.resize(keep);
  return all;
}

std::vector<Neighbour> LibraryIndex::Nearest(const float* point, int dims, int k, float epsilon,
                                             const FrameSelector& selector) const {
  return FilteredNearest(
      k, selector, dims == options_.ann_dims,
      [&](int wanted) {
        return TreeNearest([&](int b) { return blocks_[b]->pose_tree.get(); }, point, dims, wanted,
                           epsilon, selector);
      },
      [&](int clip, int64_t frame) {
        return Distance(point, clip_coordinates(clip).row(frame), dims);
      });
}

std::pair<int64_t, float> LibraryIndex::NearestFrameAround(const float* point, int dims, int clip,
                                                           int64_t frame, int64_t reach) const {
  const CoordinateView coordinates = clip_coordinates(clip);
  std::pair<int64_t, float> best{frame, std::numeric_limits<float>::infinity()};
  const int64_t last = std::min(coordinates.rows - 1, frame + reach);
  for (int64_t f = std::max<int64_t>(0, frame - reach); f <= last; ++f) {
    const float distance = Distance(point, coordinates.row(f), dims);
    if (distance < best.second) best = {f, distance};
  }
  return best;
}

std::vector<Neighbour> LibraryIndex::NearestWindows(CoordinateView rows, int64_t frame, int dims,
                                                    int k, float epsilon,
                                                    const FrameSelector& selector) const {
  if (window_frames_ == 0) return Nearest(rows.row(frame), dims, k, epsilon, selector);
  Eigen::RowVectorXf window(3 * dims);
  WriteWindow(rows, frame, window_frames_, dims, window.data());
  Eigen::RowVectorXf scanned(3 * dims);  // a scanned frame's window
  return FilteredNearest(
      k, selector, dims == options_.ann_dims,
      [&](int wanted) {
        // Only here, where the trees are asked, are they built.
        const Eigen::RowVectorXf turned = window * WindowsOf(0).basis;
        return TreeNearest([&](int b) { return WindowsOf(b).tree.get(); }, turned.data(), 3 * dims,
                           wanted, epsilon, selector);
      },
      [&](int clip, int64_t clip_frame) {
        WriteWindow(clip_coordinates(clip), clip_frame, window_frames_, dims, scanned.data());
        return Distance(window.data(), scanned.data(), 3 * dims);
      });
}

int64_t LibraryIndex::AllowedFrames(const FrameSelector& selector) const {
  if (selector.allowed.empty()) return total_frames_;
  int64_t frames = 0;
  for (int c = 0; c < clip_count(); ++c) {
    if (selector.allowed[c]) frames += clips_[c].frame_count;
  }
  return frames;
}

std::vector<Neighbour> LibraryIndex::NearestPlaces(const float* point, int dims, int k,
                                                   int64_t separation, float epsilon,
                                                   const FrameSelector& selector) const {
  const auto locate = [this](int64_t frame) { return Locate(frame); };
  DistinctPlaces places(k, separation, locate, selector);
  if (dims == options_.ann_dims && AllowedFrames(selector) * 2 >= total_frames_) {
    for (const auto& block : blocks_) {
      if (!block->pose_tree) continue;
      places.set_rows(block->first_frame + block->pose_tree->first(), block->pose_tree->every());
      block->pose_tree->Offer(point, epsilon, places);
    }
    return places.Take();
  }
  for (int c = 0; c < clip_count(); ++c) {
    if (!selector.AdmitsClip(c)) continue;
    const CoordinateView view = clip_coordinates(c);
    places.set_rows(clips_[c].first_frame, 1);
    for (int64_t f = 0; f < view.rows; ++f) {
      const float distance = Distance(point, view.row(f), dims);
      places.addPoint(distance * distance, static_cast<size_t>(f));
    }
  }
  return places.Take();
}

int64_t LibraryIndex::coordinate_bytes() const {
  int64_t bytes = 0;
  for (const auto& block : blocks_) {
    bytes += block->coordinates.size() * static_cast<int64_t>(sizeof(float));
  }
  return bytes;
}

int64_t LibraryIndex::shape_bytes() const {
  if (!shapes_ready_.load(std::memory_order_acquire)) return 0;
  int64_t bytes = shapes_->basis.size() * static_cast<int64_t>(sizeof(float));
  for (const ShapeLevel& level : shapes_->levels) {
    bytes += level.rows.size() * static_cast<int64_t>(sizeof(float)) +
             static_cast<int64_t>(level.first_frame.size() + level.frames.size()) *
                 static_cast<int64_t>(sizeof(int32_t)) +
             static_cast<int64_t>(level.clip_first.size() * sizeof(int64_t)) +
             (level.tree ? level.tree->bytes() : 0);
  }
  return bytes;
}

int64_t LibraryIndex::tree_bytes() const {
  int64_t bytes = 0;
  for (const auto& block : blocks_) {
    bytes += block->pose_tree ? block->pose_tree->bytes() : 0;
    // The flag, not the once_flag, says whether the windows are built: a build under way must not
    // be waited for here (its release store makes the windows visible to this acquire load).
    if (block->windows_ready.load(std::memory_order_acquire)) {
      bytes += block->windows.tree->bytes() +
               block->windows.rows.size() * static_cast<int64_t>(sizeof(float));
    }
  }
  return bytes;
}

}  // namespace motiondb
