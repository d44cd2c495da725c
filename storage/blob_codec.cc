#include "storage/blob_codec.h"

#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "util/byte_coding.h"
#include "util/status_macros.h"

// Layout blob, version 1 (little-endian):
//   u8 version, u32 joint count; per joint: u32 name length, name bytes, i32 parent,
//   3 f64 offset, u8 channel count, that many u8 Channel values, u8 End Site flag,
//   [3 f64 End Site].

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
  return Float32Blob(RowMatrixXf(matrix.cast<float>()));
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
  out.U32(skeleton.joint_count());
  for (const Joint& joint : skeleton.joints()) {
    out.Str(joint.name);
    out.I32(joint.parent);
    out.F64s(joint.offset.data(), 3);
    out.U8(static_cast<uint8_t>(joint.channels.size()));
    for (const Channel channel : joint.channels) out.U8(static_cast<uint8_t>(channel));
    out.U8(joint.end_site.has_value());
    if (joint.end_site) out.F64s(joint.end_site->data(), 3);
  }
  return std::move(out.bytes());
}

absl::StatusOr<std::shared_ptr<const Skeleton>> ParseSkeletonLayout(absl::string_view blob) {
  ByteReader in(blob, "clip layout");
  MOTIONDB_ASSIGN_OR_RETURN(const uint8_t version, in.U8("version"));
  if (version != kLayoutVersion) {
    return absl::DataLossError(absl::StrCat("clip layout has unknown version ", version));
  }
  // A joint takes at least 35 bytes, so a damaged count cannot cause a huge allocation.
  MOTIONDB_ASSIGN_OR_RETURN(const uint32_t count, in.Count("joint count", 35));
  std::vector<Joint> joints(count);
  for (Joint& joint : joints) {
    MOTIONDB_ASSIGN_OR_RETURN(joint.name, in.Str("joint name"));
    MOTIONDB_ASSIGN_OR_RETURN(joint.parent, in.I32("joint parent"));
    MOTIONDB_RETURN_IF_ERROR(in.F64s("joint offset", joint.offset.data(), 3));
    MOTIONDB_ASSIGN_OR_RETURN(const uint8_t channels, in.U8("channel count"));
    for (uint8_t c = 0; c < channels; ++c) {
      MOTIONDB_ASSIGN_OR_RETURN(const uint8_t channel, in.U8("channel"));
      if (channel > static_cast<uint8_t>(Channel::kZrotation)) {
        return absl::DataLossError(absl::StrCat("clip layout has unknown channel ", channel));
      }
      joint.channels.push_back(static_cast<Channel>(channel));
    }
    MOTIONDB_ASSIGN_OR_RETURN(const uint8_t has_end_site, in.U8("End Site flag"));
    if (has_end_site != 0) {
      MOTIONDB_RETURN_IF_ERROR(in.F64s("End Site", joint.end_site.emplace().data(), 3));
    }
  }
  if (in.remaining() != 0) {
    return absl::DataLossError(absl::StrCat("clip layout has ", in.remaining(), " extra bytes"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(Skeleton skeleton, Skeleton::Create(std::move(joints)));
  return std::make_shared<const Skeleton>(std::move(skeleton));
}

std::string TopologyKey(const Skeleton& skeleton) {
  std::string key;
  for (const Joint& joint : skeleton.joints()) {
    absl::StrAppend(&key, joint.parent, " ", joint.name.size(), " ", joint.name, "\n");
  }
  return key;
}

}  // namespace motiondb::storage
