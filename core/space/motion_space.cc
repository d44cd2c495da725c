#include "core/space/motion_space.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/motion/resample.h"
#include "core/space/root_velocity.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb {
namespace {

// Tolerance for the unit length of stored references and the orthonormality of a stored basis.
constexpr double kStoredTolerance = 1e-6;

// The range's frames sampled at `rate`, with errors naming the source.
absl::StatusOr<Clip> SampleRange(const TrainingClip& range, double rate) {
  absl::StatusOr<Clip> cut = range.frames ? range.clip.Slice(*range.frames) : range.clip;
  if (!cut.ok()) return Prefixed(range.source, cut.status());
  absl::StatusOr<Clip> sampled = Resample(*cut, rate);
  if (!sampled.ok()) return Prefixed(range.source, sampled.status());
  if (sampled->frame_count() == 0) {
    return absl::InvalidArgumentError(absl::StrCat(range.source, ": the clip has no frames"));
  }
  return sampled;
}

absl::Status CheckSampleRate(double rate, double max_rate) {
  if (!std::isfinite(rate) || rate <= 0.0 || rate > max_rate) {
    return absl::InvalidArgumentError(absl::StrCat("space sample rate must be in (0, ", max_rate,
                                                   "] frames per second, got ", rate));
  }
  return absl::OkStatus();
}

// Rows reconstructed between two polls of a stop function: about a millisecond's at 31 joints.
constexpr Eigen::Index kRowsPerStopPoll = 1024;

absl::Status CheckStop(const std::function<bool()>& should_stop) {
  if (should_stop && should_stop()) {
    return absl::CancelledError("stopped by its caller between training clips");
  }
  return absl::OkStatus();
}

absl::Status CheckDimensionWeight(absl::string_view what, double weight) {
  if (!std::isfinite(weight) || weight <= 0.0) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, " weight must be finite and positive, got ", weight));
  }
  return absl::OkStatus();
}

// The weights of the dimensions that are not joints, for the options that have them.
absl::Status CheckExtraWeights(const PoseOptions& pose, double yaw_rate_weight,
                               double root_velocity_weight) {
  MOTIONDB_RETURN_IF_ERROR(CheckDimensionWeight("yaw-rate", yaw_rate_weight));
  if (!pose.remove_heading || !pose.root_velocity) return absl::OkStatus();
  return CheckDimensionWeight("root-velocity", root_velocity_weight);
}

absl::Status CheckShape(absl::string_view what, Eigen::Index rows, Eigen::Index cols,
                        Eigen::Index want_rows, Eigen::Index want_cols) {
  if (rows != want_rows || cols != want_cols) {
    return absl::InvalidArgumentError(absl::StrCat("space ", what, " is ", rows, " x ", cols,
                                                   ", expected ", want_rows, " x ", want_cols));
  }
  return absl::OkStatus();
}

bool IsCanonical(const SpaceData& data) {
  return data.representation == SpaceRepresentation::kCanonicalBones;
}

// The numbers a pose vector of the space holds.
int DimsOf(const SpaceData& data) {
  return IsCanonical(data) ? CanonicalPoseDims(data.pose)
                           : PoseDims(data.skeleton->joint_count(), data.pose);
}

absl::Status CheckCanonicalOptions(const PoseOptions& pose) {
  if (!pose.remove_heading) {
    return absl::InvalidArgumentError(
        "a canonical-bones space removes the facing: its directions are told in the heading frame");
  }
  return absl::OkStatus();
}

absl::Status CheckData(const SpaceData& data) {
  if (data.skeleton == nullptr) return absl::InvalidArgumentError("space has no skeleton");
  MOTIONDB_RETURN_IF_ERROR(CheckSampleRate(data.sample_rate, kMaxResampleRate));
  MOTIONDB_RETURN_IF_ERROR(ValidatePoseOptions(data.pose));
  if (IsCanonical(data)) MOTIONDB_RETURN_IF_ERROR(CheckCanonicalOptions(data.pose));
  MOTIONDB_RETURN_IF_ERROR(
      CheckExtraWeights(data.pose, data.yaw_rate_weight, data.root_velocity_weight));
  // Rotations have a weight and a reference per joint, bones a weight each and no reference.
  const int joints = IsCanonical(data) ? kCanonicalBoneCount : data.skeleton->joint_count();
  const int dims = DimsOf(data);
  MOTIONDB_RETURN_IF_ERROR(CheckShape("joint weights", data.joint_weights.size(), 1, joints, 1));
  MOTIONDB_RETURN_IF_ERROR(CheckShape("references", data.references.rows(), data.references.cols(),
                                      IsCanonical(data) ? 0 : joints, 4));
  MOTIONDB_RETURN_IF_ERROR(CheckShape("mean", data.mean.size(), 1, dims, 1));
  MOTIONDB_RETURN_IF_ERROR(CheckShape("basis", data.basis.rows(), data.basis.cols(), dims, dims));
  MOTIONDB_RETURN_IF_ERROR(CheckShape("eigenvalues", data.eigenvalues.size(), 1, dims, 1));
  if (!data.joint_weights.allFinite() || (data.joint_weights.array() <= 0.0).any()) {
    return absl::InvalidArgumentError("space joint weights must be finite and positive");
  }
  if (!data.references.allFinite() ||
      ((data.references.rowwise().norm().array() - 1.0).abs() > kStoredTolerance).any()) {
    return absl::InvalidArgumentError("space references must be unit quaternions");
  }
  if (!data.mean.allFinite() || !data.basis.allFinite() || !data.eigenvalues.allFinite()) {
    return absl::InvalidArgumentError("space contains NaN or infinite values");
  }
  if ((data.eigenvalues.array() < 0.0).any() ||
      (dims > 1 &&
       (data.eigenvalues.tail(dims - 1).array() > data.eigenvalues.head(dims - 1).array()).any())) {
    return absl::InvalidArgumentError("space eigenvalues must be non-negative and decreasing");
  }
  const RowMatrixXd gram = data.basis.transpose() * data.basis;
  if (!gram.isIdentity(kStoredTolerance)) {
    return absl::InvalidArgumentError("space basis is not orthonormal");
  }
  if (data.search_transform.size() > 0) {
    MOTIONDB_RETURN_IF_ERROR(CheckShape("search transform", data.search_transform.rows(),
                                        data.search_transform.cols(), dims, dims));
    if (!data.search_transform.allFinite() ||
        Eigen::FullPivLU<RowMatrixXd>(data.search_transform).rank() < dims) {
      return absl::InvalidArgumentError("space search transform must be finite and invertible");
    }
  }
  for (const TrainingSource& source : data.training) {
    if (source.frames.first < 0 || source.frames.last < source.frames.first) {
      return absl::InvalidArgumentError(
          absl::StrCat("space training range of '", source.source, "' is not a frame range"));
    }
  }
  return absl::OkStatus();
}

// Calls `visit` with each of `training`'s clips, fetched a clip at a time, until it fails or
// `should_stop` says so.
absl::Status ForEachTrainingClip(const TrainingSet& training,
                                 const std::function<bool()>& should_stop,
                                 const std::function<absl::Status(const TrainingClip&)>& visit) {
  for (size_t i = 0; i < training.count; ++i) {
    MOTIONDB_RETURN_IF_ERROR(CheckStop(should_stop));
    MOTIONDB_ASSIGN_OR_RETURN(const TrainingClip range, training.fetch(i));
    MOTIONDB_RETURN_IF_ERROR(visit(range));
  }
  return absl::OkStatus();
}

// The poses of a set of training clips, a clip at a time: each is fetched, checked against the
// skeleton, cut to its range, sampled at the rate and turned into pose rotations.
struct TrainingPoses {
  const TrainingSet& training;
  const Skeleton& skeleton;
  std::string skeleton_owner;  // whose skeleton the clips must match, for the error
  double rate;
  const PoseOptions& pose;
  const std::function<bool()>& should_stop;

  absl::Status ForEach(
      const std::function<absl::Status(const TrainingClip&, const PoseRotations&)>& use) const {
    return ForEachTrainingClip(
        training, should_stop, [&](const TrainingClip& range) -> absl::Status {
          if (!range.clip.skeleton().SameTopology(skeleton)) {
            return absl::InvalidArgumentError(
                absl::StrCat(range.source, ": skeleton differs from ", skeleton_owner,
                             ": joint names or parents do not match"));
          }
          MOTIONDB_ASSIGN_OR_RETURN(const Clip sampled, SampleRange(range, rate));
          return use(range, ComputePoseRotations(sampled, pose));
        });
  }
};

// The canonical poses of a set of training clips of any mapped skeletons, a clip at a time.
struct CanonicalTrainingPoses {
  const TrainingSet& training;
  const HumanoidMapper& map_of;  // unset: MapHumanoid without overrides
  double rate;
  const PoseOptions& pose;
  const std::function<bool()>& should_stop;

  absl::Status ForEach(
      const std::function<absl::Status(const TrainingClip&, const RowMatrixXd&)>& use) const {
    return ForEachTrainingClip(
        training, should_stop, [&](const TrainingClip& range) -> absl::Status {
          absl::StatusOr<HumanoidMap> map =
              map_of ? map_of(range.clip.skeleton()) : MapHumanoid(range.clip.skeleton());
          if (!map.ok()) return Prefixed(range.source, map.status());
          MOTIONDB_RETURN_IF_ERROR(CheckCanonicalMap(*map, absl::StrCat("of ", range.source)));
          MOTIONDB_ASSIGN_OR_RETURN(const Clip sampled, SampleRange(range, rate));
          return use(range, CanonicalPoses(sampled, *map, pose));
        });
  }
};

// Adds the angle between each bone's direction (frames x 3 * bones, unit or zero rows) and its
// rebuilt one to the level's sum (mean_rad until divided) and maximum.
void AddDirectionErrors(const RowMatrixXd& original, const RowMatrixXd& rebuilt,
                        ReconstructionError* level) {
  for (Eigen::Index f = 0; f < original.rows(); ++f) {
    for (Eigen::Index c = 0; c < 3 * kCanonicalBoneCount; c += 3) {
      const Eigen::Vector3d a = original.block<1, 3>(f, c).transpose();
      const Eigen::Vector3d b = rebuilt.block<1, 3>(f, c).transpose();
      const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
      level->mean_rad += angle;
      level->max_rad = std::max(level->max_rad, angle);
    }
  }
}

// Adds the angle between each joint's original and rebuilt rotation (frames x 4 * joints, w, x,
// y, z) to the level's sum (mean_rad until divided) and maximum.
void AddAngleErrors(const RowMatrixXd& original, const RowMatrixXd& rebuilt,
                    ReconstructionError* level) {
  for (Eigen::Index f = 0; f < rebuilt.rows(); ++f) {
    for (Eigen::Index c = 0; c < rebuilt.cols(); c += 4) {
      const auto a = original.block<1, 4>(f, c);
      const auto b = rebuilt.block<1, 4>(f, c);
      const double angle = AngleBetween(Quat(a[0], a[1], a[2], a[3]), Quat(b[0], b[1], b[2], b[3]));
      level->mean_rad += angle;
      level->max_rad = std::max(level->max_rad, angle);
    }
  }
}

// The mean and covariance of rows added a batch at a time. The sums are taken about the first
// row rather than about zero, so that the covariance of poses far from the origin does not
// come from the difference of two large numbers.
class PoseMoments {
 public:
  explicit PoseMoments(Eigen::Index dims)
      : sum_(Eigen::VectorXd::Zero(dims)), scatter_(Eigen::MatrixXd::Zero(dims, dims)) {}

  void Add(RowMatrixXd rows) {
    if (rows.rows() == 0) return;
    if (count_ == 0) shift_ = rows.row(0).transpose();
    rows.rowwise() -= shift_.transpose();
    sum_ += rows.colwise().sum().transpose();
    scatter_.noalias() += rows.transpose() * rows;
    count_ += rows.rows();
  }
  // Mean and Covariance need a row added: Build adds every training clip's, and SampleRange
  // refuses a clip without frames.
  Eigen::VectorXd Mean() const { return shift_ + sum_ / static_cast<double>(count_); }
  Eigen::MatrixXd Covariance() const {
    const Eigen::VectorXd offset = sum_ / static_cast<double>(count_);
    return scatter_ / static_cast<double>(count_) - offset * offset.transpose();
  }

 private:
  Eigen::Index count_ = 0;
  Eigen::VectorXd shift_;
  Eigen::VectorXd sum_;
  Eigen::MatrixXd scatter_;
};

// The eigen-decomposition of the weighted covariance, by decreasing eigenvalue. Each column's
// sign makes its largest entry positive, so that rebuilding a space gives the same axes.
void SolveBasis(const Eigen::MatrixXd& covariance, SpaceData* data) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(covariance);
  const Eigen::Index dims = covariance.rows();
  data->basis.resize(dims, dims);
  data->eigenvalues.resize(dims);
  for (Eigen::Index i = 0; i < dims; ++i) {
    const Eigen::Index source = dims - 1 - i;  // the solver's eigenvalues ascend
    Eigen::VectorXd column = solver.eigenvectors().col(source);
    Eigen::Index largest = 0;
    column.cwiseAbs().maxCoeff(&largest);
    if (column[largest] < 0.0) column = -column;
    data->basis.col(i) = column;
    data->eigenvalues[i] = std::max(solver.eigenvalues()[source], 0.0);
  }
}

// The mean and basis of the weighted training poses.
absl::Status SolveMoments(const PoseMoments& moments, SpaceData* data) {
  data->mean = moments.Mean();
  SolveBasis(moments.Covariance(), data);
  if (data->eigenvalues.sum() <= 0.0) {
    return absl::InvalidArgumentError(
        "the training poses do not vary: a space needs at least two different poses");
  }
  return absl::OkStatus();
}

// The weight of each pose-vector number: each joint's three, then the yaw rate's and the root
// velocity's.
Eigen::VectorXd PoseWeights(const SpaceData& data) {
  const Eigen::Index joints = data.joint_weights.size();
  Eigen::VectorXd weights(DimsOf(data));
  for (Eigen::Index j = 0; j < joints; ++j) {
    weights.segment<3>(3 * j).setConstant(data.joint_weights[j]);
  }
  if (data.pose.remove_heading) weights[3 * joints] = data.yaw_rate_weight;
  if (data.pose.remove_heading && data.pose.root_velocity) {
    weights.tail<kRootVelocityDims>().setConstant(data.root_velocity_weight);
  }
  return weights;
}

}  // namespace

Eigen::VectorXd MetricScales(SpaceMetric metric, const Eigen::VectorXd& eigenvalues, int dims) {
  if (metric == SpaceMetric::kEigenvalueScaled) return eigenvalues.head(dims);
  return Eigen::VectorXd::Ones(dims);
}

TrainingSet TrainingSet::Of(const std::vector<TrainingClip>& clips) {
  return {clips.size(), [&clips](size_t i) -> absl::StatusOr<TrainingClip> { return clips[i]; }};
}

absl::StatusOr<MotionSpace> MotionSpace::Build(const std::vector<TrainingClip>& training,
                                               const SpaceOptions& options,
                                               const std::function<bool()>& should_stop) {
  return Build(TrainingSet::Of(training), options, should_stop);
}

absl::StatusOr<MotionSpace> MotionSpace::Build(const TrainingSet& training,
                                               const SpaceOptions& options,
                                               const std::function<bool()>& should_stop) {
  if (training.count == 0) return absl::InvalidArgumentError("a space needs training clips");
  MOTIONDB_RETURN_IF_ERROR(CheckSampleRate(options.sample_rate, kMaxSpaceRate));
  MOTIONDB_RETURN_IF_ERROR(ValidatePoseOptions(options.pose));
  MOTIONDB_RETURN_IF_ERROR(
      CheckExtraWeights(options.pose, options.yaw_rate_weight, options.root_velocity_weight));
  SpaceData data;
  std::string first_source;
  {  // Not kept: the passes below hold one clip at a time.
    MOTIONDB_ASSIGN_OR_RETURN(const TrainingClip first, training.fetch(0));
    data.skeleton = first.clip.shared_skeleton();
    first_source = first.source;
  }
  data.sample_rate = options.sample_rate;
  data.pose = options.pose;
  data.pose.root_velocity = options.pose.remove_heading && options.pose.root_velocity;
  data.yaw_rate_weight = options.yaw_rate_weight;
  data.root_velocity_weight = data.pose.root_velocity ? options.root_velocity_weight : 0.0;
  data.metric = options.metric;
  if (options.representation == SpaceRepresentation::kCanonicalBones) {
    return BuildCanonical(training, options, should_stop, std::move(data));
  }
  MOTIONDB_ASSIGN_OR_RETURN(data.joint_weights,
                            ComputeJointWeights(*data.skeleton, options.weights));
  const TrainingPoses poses{training,
                            *data.skeleton,
                            absl::StrCat("the first training clip's (", first_source, ")"),
                            data.sample_rate,
                            data.pose,
                            should_stop};

  // Two passes, each holding one clip's poses at a time: the mean orientations, then the mean
  // and covariance of the poses linearised about them.
  const int joints = data.skeleton->joint_count();
  std::vector<Eigen::Matrix4d> scatter(joints, Eigen::Matrix4d::Zero());
  MOTIONDB_RETURN_IF_ERROR(poses.ForEach([&](const TrainingClip& range, const PoseRotations& pose) {
    for (int j = 0; j < joints; ++j) {
      const auto wxyz = pose.rotations.middleCols(4 * j, 4);
      scatter[j] += wxyz.transpose() * wxyz;
    }
    const FrameRange all{0, range.clip.frame_count() - 1};
    data.training.push_back({range.source, range.frames.value_or(all)});
    return absl::OkStatus();
  }));
  data.references.resize(joints, 4);
  for (int j = 0; j < joints; ++j) {
    MOTIONDB_ASSIGN_OR_RETURN(const Quat mean, MeanQuaternionOfScatter(scatter[j]));
    data.references.row(j) << mean.w(), mean.x(), mean.y(), mean.z();
  }

  const Eigen::VectorXd pose_weights = PoseWeights(data);
  PoseMoments moments(pose_weights.size());
  MOTIONDB_RETURN_IF_ERROR(poses.ForEach([&](const TrainingClip&, const PoseRotations& pose) {
    moments.Add(EncodePoses(pose, data.references) * pose_weights.asDiagonal());
    return absl::OkStatus();
  }));
  MOTIONDB_RETURN_IF_ERROR(SolveMoments(moments, &data));
  return MotionSpace(std::move(data));
}

absl::StatusOr<MotionSpace> MotionSpace::BuildCanonical(const TrainingSet& training,
                                                        const SpaceOptions& options,
                                                        const std::function<bool()>& should_stop,
                                                        SpaceData data) {
  MOTIONDB_RETURN_IF_ERROR(CheckCanonicalOptions(data.pose));
  data.representation = SpaceRepresentation::kCanonicalBones;
  data.joint_weights = Eigen::VectorXd::Ones(kCanonicalBoneCount);
  data.references.resize(0, 4);
  const Eigen::VectorXd pose_weights = PoseWeights(data);
  PoseMoments moments(pose_weights.size());
  // One pass: bones need no references.
  const CanonicalTrainingPoses poses{training, options.map_of, data.sample_rate, data.pose,
                                     should_stop};
  MOTIONDB_RETURN_IF_ERROR(poses.ForEach([&](const TrainingClip& range, const RowMatrixXd& pose) {
    moments.Add(pose * pose_weights.asDiagonal());
    const FrameRange all{0, range.clip.frame_count() - 1};
    data.training.push_back({range.source, range.frames.value_or(all)});
    return absl::OkStatus();
  }));
  MOTIONDB_RETURN_IF_ERROR(SolveMoments(moments, &data));
  return MotionSpace(std::move(data));
}

absl::StatusOr<MotionSpace> MotionSpace::FromData(SpaceData data) {
  MOTIONDB_RETURN_IF_ERROR(CheckData(data));
  return MotionSpace(std::move(data));
}

MotionSpace::MotionSpace(SpaceData data)
    : data_(std::move(data)), pose_weights_(PoseWeights(data_)) {
  project_ = pose_weights_.asDiagonal() * data_.basis;
  project_offset_ = -data_.mean.transpose() * data_.basis;
  unproject_ = data_.basis.transpose() * pose_weights_.cwiseInverse().asDiagonal();
  unproject_offset_ = data_.mean.cwiseQuotient(pose_weights_).transpose();
  if (data_.search_transform.size() > 0)
    search_transform_inverse_ = data_.search_transform.inverse();
}

absl::StatusOr<MotionSpace> MotionSpace::WithSearchTransform(RowMatrixXd transform) const {
  SpaceData data = data_;
  data.search_transform = std::move(transform);
  return FromData(std::move(data));
}

int MotionSpace::part_count() const {
  return canonical() ? kCanonicalBoneCount : skeleton().joint_count();
}

std::string MotionSpace::part_name(int part) const {
  return canonical() ? std::string(CanonicalBoneName(part)) : skeleton().joint(part).name;
}

Eigen::VectorXd MotionSpace::ExplainedVariance() const {
  return data_.eigenvalues / data_.eigenvalues.sum();
}

absl::StatusOr<RowMatrixXd> MotionSpace::Project(const Eigen::Ref<const RowMatrixXd>& poses,
                                                 int dims) const {
  if (poses.cols() != this->dims()) {
    return absl::InvalidArgumentError(absl::StrCat("pose vectors have ", poses.cols(),
                                                   " numbers, the space expects ", this->dims()));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const int n, ResolveDims(dims));
  RowMatrixXd coordinates = poses * project_.leftCols(n);
  coordinates.rowwise() += project_offset_.head(n);
  return coordinates;
}

absl::StatusOr<RowMatrixXd> MotionSpace::Unproject(
    const Eigen::Ref<const RowMatrixXd>& coordinates) const {
  MOTIONDB_ASSIGN_OR_RETURN(const int n, CoordinateDims(coordinates.cols()));
  RowMatrixXd poses = coordinates * unproject_.topRows(n);
  poses.rowwise() += unproject_offset_;
  return poses;
}

absl::StatusOr<RowMatrixXd> MotionSpace::EncodeClip(const Clip& clip,
                                                    const HumanoidMap* map) const {
  if (canonical()) {
    std::optional<HumanoidMap> own;
    if (map == nullptr) {
      MOTIONDB_ASSIGN_OR_RETURN(own, MapHumanoid(clip.skeleton()));
      map = &*own;
    }
    MOTIONDB_RETURN_IF_ERROR(CheckCanonicalMap(*map, "of the clip"));
    MOTIONDB_ASSIGN_OR_RETURN(const Clip sampled, Resample(clip, data_.sample_rate));
    return CanonicalPoses(sampled, *map, data_.pose);
  }
  if (!clip.skeleton().SameTopology(skeleton())) {
    return absl::InvalidArgumentError(
        "the clip's skeleton differs from the space's: joint names or parents do not match");
  }
  MOTIONDB_ASSIGN_OR_RETURN(const Clip sampled, Resample(clip, data_.sample_rate));
  return EncodePoses(ComputePoseRotations(sampled, data_.pose), data_.references);
}

absl::StatusOr<RowMatrixXd> MotionSpace::ProjectClip(const Clip& clip, int dims,
                                                     const HumanoidMap* map) const {
  MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd poses, EncodeClip(clip, map));
  return Project(poses, dims);
}

absl::StatusOr<RowMatrixXd> MotionSpace::Reconstruct(
    const Eigen::Ref<const RowMatrixXd>& coordinates,
    const std::function<bool()>& should_stop) const {
  if (canonical()) {
    return absl::FailedPreconditionError(
        "the space is over several skeletons (canonical bone directions): its points hold no "
        "joint rotations to rebuild a pose from");
  }
  MOTIONDB_ASSIGN_OR_RETURN(const int n, CoordinateDims(coordinates.cols()));
  RowMatrixXd rotations(coordinates.rows(), 4 * skeleton().joint_count());
  // A block of rows at a time, each row on its own (the same rotations, block by block).
  for (Eigen::Index first = 0; first < coordinates.rows(); first += kRowsPerStopPoll) {
    if (should_stop && should_stop()) {
      return absl::CancelledError("reconstruction was stopped by its caller");
    }
    const Eigen::Index rows = std::min(kRowsPerStopPoll, coordinates.rows() - first);
    RowMatrixXd poses = coordinates.middleRows(first, rows) * unproject_.topRows(n);
    poses.rowwise() += unproject_offset_;
    rotations.middleRows(first, rows) = DecodePoses(poses, data_.references);
  }
  return rotations;
}

absl::StatusOr<Eigen::VectorXd> MotionSpace::MetricScales(int dims) const {
  MOTIONDB_ASSIGN_OR_RETURN(const int n, ResolveDims(dims));
  return motiondb::MetricScales(data_.metric, data_.eigenvalues, n);
}

absl::StatusOr<double> MotionSpace::Distance(const Eigen::Ref<const Eigen::RowVectorXd>& p,
                                             const Eigen::Ref<const Eigen::RowVectorXd>& q) const {
  if (p.size() != q.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("points have ", p.size(), " and ", q.size(), " coordinates"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const int n, CoordinateDims(p.size()));
  MOTIONDB_ASSIGN_OR_RETURN(const Eigen::VectorXd scales, MetricScales(n));
  return (p - q).cwiseProduct(scales.transpose()).norm();
}

absl::StatusOr<std::vector<ReconstructionError>> MotionSpace::RepresentationalError(
    const std::vector<TrainingClip>& clips, absl::Span<const int> dims,
    const std::function<bool()>& should_stop) const {
  return RepresentationalError(TrainingSet::Of(clips), dims, should_stop);
}

absl::StatusOr<std::vector<ReconstructionError>> MotionSpace::RepresentationalError(
    const TrainingSet& clips, absl::Span<const int> dims, const std::function<bool()>& should_stop,
    const HumanoidMapper& map_of) const {
  std::vector<int> levels;
  for (const int n : dims) {
    if (n < 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("reconstruction dimensions must be at least 1, got ", n));
    }
    if (n < this->dims()) levels.push_back(n);
  }
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  levels.push_back(this->dims());

  std::vector<ReconstructionError> report;
  for (const int n : levels) report.push_back({n, 0.0, 0.0});
  double angles = 0.0;
  if (canonical()) {
    const CanonicalTrainingPoses poses{clips, map_of, data_.sample_rate, data_.pose, should_stop};
    MOTIONDB_RETURN_IF_ERROR(
        poses.ForEach([&](const TrainingClip&, const RowMatrixXd& pose) -> absl::Status {
          MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd coordinates, Project(pose));
          for (ReconstructionError& level : report) {
            MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd rebuilt,
                                      Unproject(coordinates.leftCols(level.dims)));
            AddDirectionErrors(pose, rebuilt, &level);
          }
          angles += static_cast<double>(pose.rows()) * kCanonicalBoneCount;
          return absl::OkStatus();
        }));
  } else {
    const int joints = skeleton().joint_count();
    const TrainingPoses poses{clips,      skeleton(), "the space's", data_.sample_rate,
                              data_.pose, should_stop};
    MOTIONDB_RETURN_IF_ERROR(
        poses.ForEach([&](const TrainingClip&, const PoseRotations& pose) -> absl::Status {
          MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd coordinates,
                                    Project(EncodePoses(pose, data_.references)));
          for (ReconstructionError& level : report) {
            MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd rebuilt,
                                      Reconstruct(coordinates.leftCols(level.dims)));
            AddAngleErrors(pose.rotations, rebuilt, &level);
          }
          angles += static_cast<double>(pose.rotations.rows()) * joints;
          return absl::OkStatus();
        }));
  }
  if (angles == 0.0) return absl::InvalidArgumentError("no clips to reconstruct");
  for (ReconstructionError& level : report) level.mean_rad /= angles;
  return report;
}

absl::StatusOr<int> MotionSpace::ResolveDims(int dims) const {
  if (dims == -1) return this->dims();
  if (dims < 0 || dims > this->dims()) {
    return absl::InvalidArgumentError(
        absl::StrCat("dimensions must be in 0..", this->dims(), " (or -1 for all), got ", dims));
  }
  return dims;
}

absl::StatusOr<int> MotionSpace::CoordinateDims(Eigen::Index columns) const {
  if (columns > dims()) {
    return absl::InvalidArgumentError(
        absl::StrCat("points have ", columns, " coordinates, the space has ", dims()));
  }
  return static_cast<int>(columns);
}

}  // namespace motiondb
