#include "storage/blob_codec.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/status_macros.h"

// Layout blob, version 1 (integers and doubles in host byte order, which the assertion below
// pins to little-endian):
//   u8 version, u32 joint count; per joint: u32 name length, name bytes, i32 parent,
//   3 f64 offset, u8 channel count, that many u8 Channel values, u8 End Site flag,
//   [3 f64 End Site].

namespace motiondb::storage {
namespace {

// Blobs are copied to and from memory as they are; a big-endian host would need byte swaps.
static_assert(std::endian::native == std::endian::little,
              "motiondb storage writes little-endian blobs by copying memory");

constexpr uint8_t kLayoutVersion = 1;

template <typename T>
void Append(std::string& out, T value) {
  static_assert(std::is_trivially_copyable_v<T>);
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

// Consumes the layout blob front to back; every read fails once the bytes run out.
class LayoutCursor {
 public:
  explicit LayoutCursor(absl::string_view bytes) : rest_(bytes) {}

  template <typename T>
  absl::Status Take(T& value, absl::string_view what) {
    static_assert(std::is_trivially_copyable_v<T>);
    MOTIONDB_RETURN_IF_ERROR(Need(sizeof(T), what));
    std::memcpy(&value, rest_.data(), sizeof(T));
    rest_.remove_prefix(sizeof(T));
    return absl::OkStatus();
  }
  absl::Status TakeVector(Eigen::Vector3d& value, absl::string_view what) {
    for (int i = 0; i < 3; ++i) MOTIONDB_RETURN_IF_ERROR(Take(value[i], what));
    return absl::OkStatus();
  }
  absl::Status TakeString(std::string& value, absl::string_view what) {
    uint32_t size = 0;
    MOTIONDB_RETURN_IF_ERROR(Take(size, what));
    MOTIONDB_RETURN_IF_ERROR(Need(size, what));
    value.assign(rest_.data(), size);
    rest_.remove_prefix(size);
    return absl::OkStatus();
  }
  size_t remaining() const { return rest_.size(); }

 private:
  absl::Status Need(size_t size, absl::string_view what) const {
    if (size <= rest_.size()) return absl::OkStatus();
    return absl::DataLossError(absl::StrCat("clip layout is truncated at the ", what));
  }

  absl::string_view rest_;
};

std::string FloatBytes(const float* values, Eigen::Index count) {
  return std::string(reinterpret_cast<const char*>(values), count * sizeof(float));
}

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
  const RowMatrixXf floats = matrix.cast<float>();
  return FloatBytes(floats.data(), floats.size());
}

std::string Float32Blob(const RowMatrixXf& matrix) {
  return FloatBytes(matrix.data(), matrix.size());
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
  if (!blob.empty()) std::memcpy(matrix.data(), blob.data(), blob.size());
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
  std::string out;
  Append<uint8_t>(out, kLayoutVersion);
  Append<uint32_t>(out, skeleton.joint_count());
  for (const Joint& joint : skeleton.joints()) {
    Append<uint32_t>(out, static_cast<uint32_t>(joint.name.size()));
    out += joint.name;
    Append<int32_t>(out, joint.parent);
    for (int i = 0; i < 3; ++i) Append<double>(out, joint.offset[i]);
    Append<uint8_t>(out, static_cast<uint8_t>(joint.channels.size()));
    for (const Channel channel : joint.channels)
      Append<uint8_t>(out, static_cast<uint8_t>(channel));
    Append<uint8_t>(out, joint.end_site.has_value());
    if (joint.end_site) {
      for (int i = 0; i < 3; ++i) Append<double>(out, (*joint.end_site)[i]);
    }
  }
  return out;
}

absl::StatusOr<std::shared_ptr<const Skeleton>> ParseSkeletonLayout(absl::string_view blob) {
  LayoutCursor in(blob);
  uint8_t version = 0;
  MOTIONDB_RETURN_IF_ERROR(in.Take(version, "version"));
  if (version != kLayoutVersion) {
    return absl::DataLossError(absl::StrCat("clip layout has unknown version ", version));
  }
  uint32_t count = 0;
  MOTIONDB_RETURN_IF_ERROR(in.Take(count, "joint count"));
  // A joint takes at least 35 bytes, so a damaged count cannot cause a huge allocation.
  if (count > in.remaining() / 35) {
    return absl::DataLossError(
        absl::StrCat("clip layout claims ", count, " joints in ", in.remaining(), " bytes"));
  }
  std::vector<Joint> joints(count);
  for (Joint& joint : joints) {
    MOTIONDB_RETURN_IF_ERROR(in.TakeString(joint.name, "joint name"));
    int32_t parent = 0;
    MOTIONDB_RETURN_IF_ERROR(in.Take(parent, "joint parent"));
    joint.parent = parent;
    MOTIONDB_RETURN_IF_ERROR(in.TakeVector(joint.offset, "joint offset"));
    uint8_t channels = 0;
    MOTIONDB_RETURN_IF_ERROR(in.Take(channels, "channel count"));
    for (uint8_t c = 0; c < channels; ++c) {
      uint8_t channel = 0;
      MOTIONDB_RETURN_IF_ERROR(in.Take(channel, "channel"));
      if (channel > static_cast<uint8_t>(Channel::kZrotation)) {
        return absl::DataLossError(absl::StrCat("clip layout has unknown channel ", channel));
      }
      joint.channels.push_back(static_cast<Channel>(channel));
    }
    uint8_t has_end_site = 0;
    MOTIONDB_RETURN_IF_ERROR(in.Take(has_end_site, "End Site flag"));
    if (has_end_site != 0) {
      MOTIONDB_RETURN_IF_ERROR(in.TakeVector(joint.end_site.emplace(), "End Site"));
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
