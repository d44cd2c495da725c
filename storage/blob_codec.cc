#include "storage/blob_codec.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/motion/skeleton_coding.h"
#include "util/byte_coding.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

// Layout blob, version 1: u8 version, then the skeleton as core/motion/skeleton_coding.h
// writes it.

namespace motiondb::storage {
namespace {

constexpr uint8_t kLayoutVersion = 1;

}  // namespace

absl::Status CheckFloat32Range(const RowMatrixXd& matrix, absl::string_view what) {
  constexpr double kMax = std::numeric_limits<float>::max();
  for (Eigen::Index i = 0; i < matrix.size(); ++i) {
    const double value = matrix.data()[i];
    if (!std::isfinite(value) || std::abs(value) > kMax) {
      return absl::InvalidArgumentError(absl::StrCat(what, " value ", value, " at row ",
                                                     i / std::max<Eigen::Index>(matrix.cols(), 1),
                                                     " is not a finite float32"));
    }
  }
  return absl::OkStatus();
}

std::string Float32Blob(const RowMatrixXd& matrix) {
  std::string blob;
  blob.reserve(matrix.size() * sizeof(float));
  // The lambda cannot fail.
  ForEachFloat32Piece(matrix, [&blob](absl::string_view piece) {
    blob.append(piece.data(), piece.size());
    return absl::OkStatus();
  }).IgnoreError();
  return blob;
}

absl::Status ForEachFloat32Piece(const RowMatrixXd& matrix,
                                 absl::FunctionRef<absl::Status(absl::string_view)> consume) {
  constexpr Eigen::Index kPieceValues = kFloat32PieceBytes / sizeof(float);
  std::vector<float> values;
  std::string piece;
  for (Eigen::Index first = 0; first < matrix.size(); first += kPieceValues) {
    const Eigen::Index count = std::min(kPieceValues, matrix.size() - first);
    values.assign(matrix.data() + first, matrix.data() + first + count);
    piece.clear();
    AppendFloat32s(values.data(), values.size(), &piece);
    MOTIONDB_RETURN_IF_ERROR(consume(piece));
  }
  return absl::OkStatus();
}

std::string Float32Blob(const RowMatrixXf& matrix) {
  std::string blob;
  AppendFloat32s(matrix.data(), matrix.size(), &blob);
  return blob;
}

absl::StatusOr<RowMatrixXf> ParseFloat32Blob(absl::string_view blob, int64_t rows, int64_t cols,
                                             absl::string_view what) {
  // Division, not multiplication, so that damaged sizes cannot overflow.
  const uint64_t floats = blob.size() / sizeof(float);
  const bool fits =
      rows >= 0 && cols >= 0 && blob.size() % sizeof(float) == 0 &&
      (rows == 0 || cols == 0 ? floats == 0
                              : floats % cols == 0 && floats / cols == static_cast<uint64_t>(rows));
  if (!fits) {
    return absl::DataLossError(absl::StrCat(what, " blob has ", blob.size(), " bytes, expected ",
                                            rows, " x ", cols, " float32"));
  }
  RowMatrixXf matrix(rows, cols);
  ReadFloat32s(blob, matrix.size(), matrix.data());
  return matrix;
}

absl::StatusOr<RowMatrixXd> ParseRotationBlob(absl::string_view blob, int64_t frames,
                                              int64_t joints) {
  MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXf floats,
                            ParseFloat32Blob(blob, frames, 4 * joints, "rotations"));
  RowMatrixXd rotations = floats.cast<double>();
  for (Eigen::Index f = 0; f < rotations.rows(); ++f) {
    for (Eigen::Index j = 0; j < joints; ++j) {
      auto q = rotations.block<1, 4>(f, 4 * j);
      const double norm = q.norm();
      // float32 rounding leaves |q| within about 1e-7 of 1; anything far off is damage.
      if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3) {
        return absl::DataLossError(
            absl::StrCat("rotation of joint ", j, " at frame ", f, " has norm ", norm));
      }
      q /= norm;
    }
  }
  return rotations;
}

std::string SkeletonLayoutBlob(const Skeleton& skeleton) {
  ByteWriter out;
  out.U8(kLayoutVersion);
  WriteSkeleton(skeleton, out);
  return std::move(out.bytes());
}

absl::StatusOr<std::shared_ptr<const Skeleton>> ParseSkeletonLayout(absl::string_view blob) {
  ByteReader in(blob, "clip layout");
  MOTIONDB_ASSIGN_OR_RETURN(const uint8_t version, in.U8("version"));
  if (version != kLayoutVersion) {
    return absl::DataLossError(absl::StrCat("clip layout has unknown version ", version));
  }
  MOTIONDB_ASSIGN_OR_RETURN(std::shared_ptr<const Skeleton> skeleton,
                            Prefixed("clip layout", ReadSkeleton(in)));
  if (in.remaining() != 0) {
    return absl::DataLossError(absl::StrCat("clip layout has ", in.remaining(), " extra bytes"));
  }
  return skeleton;
}

std::string TopologyKey(const Skeleton& skeleton) {
  std::string key;
  for (const Joint& joint : skeleton.joints()) {
    absl::StrAppend(&key, joint.parent, " ", joint.name.size(), " ", joint.name, "\n");
  }
  return key;
}

}  // namespace motiondb::storage
