// A Motion Curve space (thesis 3.2-3.3, SPEC §3): the weighted-PCA basis of the pose vectors of
// some training clips. Poses project to points, clips to curves; the first dimensions carry the
// most (weighted) variance, and the Euclidean distance in the space is a weighted joint-angle
// distance.
//
// With per-joint weights w (3 numbers per joint, plus the yaw-rate weight), the training mean m
// of the weighted pose vectors and the orthonormal basis B (one column per dimension, by
// decreasing eigenvalue): projection p = (v .* w - m) B, unprojection v = (p B^T + m) ./ w.
// Every dimension is kept; callers truncate.
//
// Immutable once built; thread-safe for concurrent use.
#ifndef MOTIONDB_CORE_SPACE_MOTION_SPACE_H_
#define MOTIONDB_CORE_SPACE_MOTION_SPACE_H_

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "absl/base/attributes.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/motion/clip.h"
#include "core/motion/matrix.h"
#include "core/space/canonical_pose.h"
#include "core/space/joint_weights.h"
#include "core/space/pose_encoder.h"

namespace motiondb {

// Eq. 3.4: d(p, q) = sqrt(sum_{i < n} s_i^2 (p_i - q_i)^2).
enum class SpaceMetric {
  kUnit,              // s_i = 1: plain Euclidean, a weighted joint-angle distance
  kEigenvalueScaled,  // s_i = eigenvalue i, as the thesis writes it
};

// The fastest rate a new space may sample at, frames per second. Capture for animation runs at
// 30-480 Hz and a space sampled faster than its clips holds only interpolated frames, while
// every frame costs memory and time: at the earlier bound, 10000 Hz, a request resampled 30 Hz
// clips 333 times over (a 10 h library to 360M frames) and a space over the request fuzzer's
// three short clips took 10-14 s to build, uncancellable. Spaces stored before keep loading up to
// kMaxResampleRate.
inline constexpr double kMaxSpaceRate = 1000.0;

// The dimension counts a space's build report gives its reconstruction error at.
inline constexpr int kErrorReportDims[] = {3, 5, 10, 20};

struct SpaceOptions {
  // Frames per second at which training clips, and every clip projected later, are sampled; in
  // (0, kMaxSpaceRate].
  double sample_rate = 30.0;
  // Facing removal and yaw-rate smoothing.
  PoseOptions pose = {};
  // Per-joint weights: preset and overrides.
  JointWeightOptions weights = {};
  // Weight of the yaw-rate dimension (rad/s): 0.5 makes a turn at 1 rad/s count like a joint
  // of weight 1 bent by 0.5 rad. Measured best of 0.03-2 at telling walks from left and right
  // turns (bandai2-normal, leave-one-out nearest clip). Finite and positive; unused when the
  // facing is kept.
  double yaw_rate_weight = 0.5;
  // Weight of the two root-velocity dimensions (leg lengths/s; pose.root_velocity): 0.5 makes a
  // walk at two leg lengths a second count like a joint of weight 1 bent by 1 rad. Measured of
  // 0.2-2: 0.5 raised bandai1's leave-style-out precision@5 from 0.360 to 0.648 and keeps
  // bandai2-normal's leave-one-out 0.988 and recall 0.972; 1 and more cost that recall (0.945)
  // (bench/notes/2026-12-06-across-styles.md). Finite and positive; unused without it.
  double root_velocity_weight = 0.5;
  // The metric the space's distances use.
  SpaceMetric metric = SpaceMetric::kUnit;
  // What the pose vectors hold. kCanonicalBones (canonical_pose.h) lets the training clips be of
  // several skeletons, each mapped by `map_of`; its bones weigh 1 each (`weights` is for joint
  // rotations only) and it needs the facing removed.
  SpaceRepresentation representation = SpaceRepresentation::kJointRotations;
  // kCanonicalBones only: each training clip's skeleton's map; unset, MapHumanoid without
  // overrides.
  HumanoidMapper map_of = {};
};

// A clip, or a range of its frames, for training or for the error report.
struct TrainingClip {
  std::string source;  // where it came from (a file name); recorded in the space
  Clip clip;
  std::optional<FrameRange> frames;  // at the clip's own rate; nullopt for the whole clip
};

// Training clips fetched one at a time. Build and RepresentationalError fetch each clip once
// a pass and keep none, so that a space over a large library holds one clip at a time (Build
// fetches the first once more for its skeleton, then makes two passes: the mean orientations,
// then the basis). A braced `{}` argument is ambiguous between this and a vector: spell out
// the type.
struct TrainingSet {
  size_t count = 0;
  // The i-th clip, i < count.
  std::function<absl::StatusOr<TrainingClip>(size_t i)> fetch;

  // The clips of `clips`, which must outlive the set; each fetch copies one.
  static TrainingSet Of(const std::vector<TrainingClip>& clips ABSL_ATTRIBUTE_LIFETIME_BOUND);
};

// Where a space's training frames came from.
struct TrainingSource {
  std::string source;
  FrameRange frames;  // at the source clip's own rate
};

// Everything a space is made of: what serialisation stores.
struct SpaceData {
  // With kCanonicalBones, the first training clip's: the space's own skeleton for what needs one
  // (listings, exports), not a constraint on its clips.
  std::shared_ptr<const Skeleton> skeleton;
  SpaceRepresentation representation = SpaceRepresentation::kJointRotations;
  // As built, from SpaceOptions (no defaults here: a space has them all set).
  double sample_rate = 0.0;
  PoseOptions pose = {};
  double yaw_rate_weight = 0.0;
  double root_velocity_weight = 0.0;  // 0 without the root velocity
  SpaceMetric metric = SpaceMetric::kUnit;
  Eigen::VectorXd joint_weights;  // one per joint (per canonical bone), positive
  RowMatrixXd references;  // joints x 4: each joint's mean orientation, w, x, y, z; 0 x 4 for bones
  Eigen::VectorXd mean;    // dims: mean weighted training pose vector
  RowMatrixXd basis;       // dims x dims, orthonormal; column i is dimension i
  Eigen::VectorXd eigenvalues;  // dims, decreasing: the weighted variance along each column
  std::vector<TrainingSource> training;
  // dims x dims, invertible, or empty: a learned metric (core/space/learned_metric.h) that search
  // coordinates are multiplied by (core/space/search_coordinates.h).
  RowMatrixXd search_transform;
};

// Joint-angle error (radians, over every joint of every frame) of a reconstruction from the
// first `dims` dimensions; in a kCanonicalBones space, the angle between each bone's direction
// and its rebuilt one.
struct ReconstructionError {
  int dims = 0;
  double mean_rad = 0.0;
  double max_rad = 0.0;
};

// The per-dimension factors s_i of `metric` for the first `dims` dimensions of a space with
// these eigenvalues. Coordinates multiplied by them make plain L2 distance the metric.
Eigen::VectorXd MetricScales(SpaceMetric metric, const Eigen::VectorXd& eigenvalues, int dims);

class MotionSpace {
 public:
  // Builds a space from training clips or ranges, which must share one skeleton topology. Each
  // is cut to its range, resampled to options.sample_rate, freed of its facing (unless
  // options.pose.remove_heading is false) and linearised about the per-joint mean orientation
  // of all training frames (thesis Algorithm 2). `should_stop`, when set, is asked between
  // training clips: CANCELLED when it says so.
  static absl::StatusOr<MotionSpace> Build(const std::vector<TrainingClip>& training,
                                           const SpaceOptions& options = {},
                                           const std::function<bool()>& should_stop = {});
  static absl::StatusOr<MotionSpace> Build(const TrainingSet& training,
                                           const SpaceOptions& options = {},
                                           const std::function<bool()>& should_stop = {});
  // Checks that the parts are consistent (shapes, finite values, positive weights, orthonormal
  // basis), e.g. after reading them from storage.
  static absl::StatusOr<MotionSpace> FromData(SpaceData data);
  // This space with its search coordinates multiplied by `transform` (dims() x dims(), finite,
  // invertible): a learned metric, core/space/learned_metric.h. Projections are unchanged.
  absl::StatusOr<MotionSpace> WithSearchTransform(RowMatrixXd transform) const;

  const SpaceData& data() const { return data_; }
  const Skeleton& skeleton() const { return *data_.skeleton; }
  SpaceRepresentation representation() const { return data_.representation; }
  bool canonical() const { return data_.representation == SpaceRepresentation::kCanonicalBones; }
  // What the pose vectors' first numbers describe, 3 numbers each, with a weight each: the
  // skeleton's joints, or a canonical space's bones (named by CanonicalBoneName).
  int part_count() const;
  std::string part_name(int part) const;
  double sample_rate() const { return data_.sample_rate; }
  int dims() const { return static_cast<int>(data_.mean.size()); }
  // The weight of each pose-vector number: joint weights repeated 3 times, then the yaw rate's.
  const Eigen::VectorXd& pose_weights() const { return pose_weights_; }
  // The inverse of data().search_transform (empty without one): search coordinates times it are
  // the metric-scaled projection.
  const RowMatrixXd& search_transform_inverse() const { return search_transform_inverse_; }
  // Fraction of the training variance along each dimension; sums to 1.
  Eigen::VectorXd ExplainedVariance() const;

  // Pose vectors (n x dims()) to their first `dims` coordinates (n x dims; -1 for all).
  absl::StatusOr<RowMatrixXd> Project(const Eigen::Ref<const RowMatrixXd>& poses,
                                      int dims = -1) const;
  // Coordinates in the first k <= dims() dimensions (n x k) to pose vectors (n x dims()); the
  // dimensions beyond k are taken at the training mean.
  absl::StatusOr<RowMatrixXd> Unproject(const Eigen::Ref<const RowMatrixXd>& coordinates) const;
  // A clip of the space's skeleton, sampled at the space rate, as pose vectors (n x dims()). In a
  // kCanonicalBones space a clip of any skeleton whose map passes CheckCanonicalMap: `map` when
  // given (the skeleton's, with its stored overrides), else MapHumanoid's without overrides.
  absl::StatusOr<RowMatrixXd> EncodeClip(const Clip& clip, const HumanoidMap* map = nullptr) const;
  // The same, projected to its first `dims` coordinates (-1 for all): the clip's motion curve.
  absl::StatusOr<RowMatrixXd> ProjectClip(const Clip& clip, int dims = -1,
                                          const HumanoidMap* map = nullptr) const;
  // Joint rotations (n x 4 * joints) of the poses at `coordinates` (n x k, k <= dims()), as
  // the pose describes them: facing-free when the space removes the facing. `should_stop` is
  // asked about every millisecond of work (a long curve takes seconds): CANCELLED once it says
  // stop. FAILED_PRECONDITION in a kCanonicalBones space: bone directions hold no rotations.
  absl::StatusOr<RowMatrixXd> Reconstruct(const Eigen::Ref<const RowMatrixXd>& coordinates,
                                          const std::function<bool()>& should_stop = {}) const;

  // The space's metric scales for the first `dims` dimensions (-1 for all; MetricScales above).
  absl::StatusOr<Eigen::VectorXd> MetricScales(int dims = -1) const;
  // The metric between two points of equal size, over their first p.size() dimensions.
  absl::StatusOr<double> Distance(const Eigen::Ref<const Eigen::RowVectorXd>& p,
                                  const Eigen::Ref<const Eigen::RowVectorXd>& q) const;

  // Thesis 3.3.4: the joint-angle error when the clips' poses are reconstructed from each of
  // `dims` (sorted, capped at dims(); all dimensions are always reported last). `should_stop`
  // as for Build.
  absl::StatusOr<std::vector<ReconstructionError>> RepresentationalError(
      const std::vector<TrainingClip>& clips, absl::Span<const int> dims = kErrorReportDims,
      const std::function<bool()>& should_stop = {}) const;
  // `map_of` maps the clips' skeletons in a kCanonicalBones space (unset: without overrides).
  absl::StatusOr<std::vector<ReconstructionError>> RepresentationalError(
      const TrainingSet& clips, absl::Span<const int> dims = kErrorReportDims,
      const std::function<bool()>& should_stop = {}, const HumanoidMapper& map_of = {}) const;

 private:
  explicit MotionSpace(SpaceData data);
  // Build's second half for kCanonicalBones: `data` has the options set.
  static absl::StatusOr<MotionSpace> BuildCanonical(const TrainingSet& training,
                                                    const SpaceOptions& options,
                                                    const std::function<bool()>& should_stop,
                                                    SpaceData data);
  // `dims` checked against the space, -1 meaning all.
  absl::StatusOr<int> ResolveDims(int dims) const;
  // The dimensions of points with `columns` coordinates, at most dims().
  absl::StatusOr<int> CoordinateDims(Eigen::Index columns) const;

  SpaceData data_;
  Eigen::VectorXd pose_weights_;
  // Projection and unprojection with the weights and mean folded in, so that each is one
  // matrix product plus a row offset: p = v * project_ + project_offset_,
  // v = p * unproject_ + unproject_offset_.
  RowMatrixXd project_;
  Eigen::RowVectorXd project_offset_;
  RowMatrixXd unproject_;
  Eigen::RowVectorXd unproject_offset_;
  RowMatrixXd search_transform_inverse_;
};

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SPACE_MOTION_SPACE_H_
