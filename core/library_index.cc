#include "core/library_index.h"

#include <algorithm>
#include <cmath>

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace motiondb {

// A single kd-tree (exact, and the fastest FLANN index at ~10 dimensions) over the first
// ann_dims columns of the coordinate block, read in place through the row stride.
class LibraryIndex::Tree {
 public:
  Tree(const RowMatrixXf& coordinates, int ann_dims, int leaf_size)
      : index_(flann::Matrix<float>(const_cast<float*>(coordinates.data()), coordinates.rows(),
                                    ann_dims, coordinates.cols() * sizeof(float)),
               flann::KDTreeSingleIndexParams(leaf_size, /*reorder=*/false)) {
    index_.buildIndex();
  }

  std::vector<Neighbour> Nearest(const float* point, int dims, int k, float epsilon) const {
    std::vector<float> query(point, point + dims);
    std::vector<size_t> indices(k);
    std::vector<float> squared(k);
    flann::Matrix<size_t> index_matrix(indices.data(), 1, k);
    flann::Matrix<float> squared_matrix(squared.data(), 1, k);
    flann::SearchParams params;
    params.eps = epsilon;
    params.sorted = true;
    params.cores = 1;
    const int found = index_.knnSearch(flann::Matrix<float>(query.data(), 1, dims), index_matrix,
                                       squared_matrix, k, params);
    std::vector<Neighbour> result(found);
    for (int i = 0; i < found; ++i) {
      result[i] = {static_cast<int64_t>(indices[i]), std::sqrt(squared[i])};
    }
    return result;
  }

  // FLANN's own count (node pool and index permutation) plus its row-pointer table.
  int64_t bytes() const {
    return static_cast<int64_t>(index_.usedMemory()) +
           static_cast<int64_t>(index_.size()) * static_cast<int64_t>(sizeof(float*));
  }

 private:
  flann::KDTreeSingleIndex<flann::L2<float>> index_;
};

LibraryIndex::LibraryIndex(double rate, const LibraryIndexOptions& options)
    : rate_(rate), options_(options) {}

LibraryIndex::~LibraryIndex() = default;

absl::StatusOr<std::unique_ptr<LibraryIndex>> LibraryIndex::Build(
    std::vector<LibraryClip> clips, double rate, const LibraryIndexOptions& options) {
  if (!std::isfinite(rate) || rate <= 0.0) {
    return absl::InvalidArgumentError(absl::StrCat("library rate must be positive, got ", rate));
  }
  if (options.ann_dims < 1 || options.leaf_size < 1) {
    return absl::InvalidArgumentError("ann_dims and leaf_size must be at least 1");
  }
  if (clips.empty()) return absl::InvalidArgumentError("library has no clips");
  const Eigen::Index dims = clips[0].coordinates.cols();
  if (dims < options.ann_dims) {
    return absl::InvalidArgumentError(
        absl::StrCat("library has ", dims, " dimensions, fewer than ann_dims ", options.ann_dims));
  }
  int64_t total = 0;
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
    total += clip.coordinates.rows();
  }
  std::unique_ptr<LibraryIndex> index(new LibraryIndex(rate, options));
  index->coordinates_.resize(total, dims);
  index->clips_.reserve(clips.size());
  int64_t next = 0;
  for (LibraryClip& clip : clips) {
    index->coordinates_.middleRows(next, clip.coordinates.rows()) = clip.coordinates;
    index->clips_.push_back(
        {clip.clip_id, std::move(clip.name), std::move(clip.tags), next, clip.coordinates.rows()});
    next += clip.coordinates.rows();
    clip.coordinates = RowMatrixXf();  // release each copy as soon as it is in the block
  }
  index->tree_ = std::make_unique<Tree>(index->coordinates_, options.ann_dims, options.leaf_size);
  return index;
}

int LibraryIndex::FindClip(int64_t clip_id) const {
  for (size_t i = 0; i < clips_.size(); ++i) {
    if (clips_[i].clip_id == clip_id) return static_cast<int>(i);
  }
  return -1;
}

std::pair<int, int64_t> LibraryIndex::Locate(int64_t global_frame) const {
  const auto it = std::upper_bound(
      clips_.begin(), clips_.end(), global_frame,
      [](int64_t frame, const ClipEntry& clip) { return frame < clip.first_frame; });
  const int clip = static_cast<int>(it - clips_.begin()) - 1;
  return {clip, global_frame - clips_[clip].first_frame};
}

std::vector<Neighbour> LibraryIndex::Nearest(const float* point, int dims, int k, float epsilon,
                                             const std::vector<bool>& allowed_clips) const {
  k = static_cast<int>(std::min<int64_t>(k, total_frames()));
  if (dims == options_.ann_dims) {
    if (allowed_clips.empty()) return tree_->Nearest(point, dims, k, epsilon);
    // When the filter keeps most frames, ask the tree for enough extra neighbours to cover the
    // filtered-out ones (doubling a few times), and scan only if that is not enough.
    int64_t allowed_frames = 0;
    for (int c = 0; c < clip_count(); ++c) {
      if (allowed_clips[c]) allowed_frames += clips_[c].frame_count;
    }
    int64_t wanted =
        k + (k * (total_frames() - allowed_frames)) / std::max<int64_t>(1, allowed_frames) + 16;
    for (int attempt = 0; allowed_frames * 2 >= total_frames() && attempt < 4; ++attempt) {
      wanted = std::min(wanted, total_frames());
      std::vector<Neighbour> found = tree_->Nearest(point, dims, static_cast<int>(wanted), epsilon);
      std::erase_if(found,
                    [&](const Neighbour& n) { return !allowed_clips[Locate(n.frame).first]; });
      if (static_cast<int64_t>(found.size()) >= k || wanted == total_frames()) {
        found.resize(std::min<size_t>(found.size(), k));
        return found;
      }
      wanted *= 2;
    }
  }
  std::vector<Neighbour> all;
  for (int c = 0; c < clip_count(); ++c) {
    if (!allowed_clips.empty() && !allowed_clips[c]) continue;
    const CoordinateView view = clip_coordinates(c);
    for (int64_t f = 0; f < view.rows; ++f) {
      all.push_back({clips_[c].first_frame + f, Distance(point, view.row(f), dims)});
    }
  }
  const auto nearer = [](const Neighbour& a, const Neighbour& b) {
    return a.distance < b.distance || (a.distance == b.distance && a.frame < b.frame);
  };
  const size_t keep = std::min<size_t>(k, all.size());
  std::partial_sort(all.begin(), all.begin() + keep, all.end(), nearer);
  all.resize(keep);
  return all;
}

int64_t LibraryIndex::coordinate_bytes() const {
  return coordinates_.size() * static_cast<int64_t>(sizeof(float));
}

int64_t LibraryIndex::tree_bytes() const { return tree_->bytes(); }

}  // namespace motiondb
