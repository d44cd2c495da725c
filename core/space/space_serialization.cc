#include "core/space/space_serialization.h"

#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/motion/skeleton_coding.h"
#include "util/byte_coding.h"
#include "util/crc32.h"
#include "util/file_io.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

// Payload, in order (u8/u32/i32/u64 integers, f64 doubles, str = u32 length + bytes):
//   skeleton: u32 joints; per joint: str name, i32 parent, 3 f64 offset, u8 channel count,
//             that many u8 channels (Channel enum values), u8 has End Site, [3 f64 End Site]
//   f64 sample rate, u8 remove heading, i32 yaw-rate window, f64 yaw-rate weight, u8 metric,
//   [version 2 on: u8 root velocity, f64 root-velocity weight]
//   [version 4 on: u8 representation (SpaceRepresentation)]
//   joints f64 joint weights, joints x 4 f64 references (w, x, y, z); with canonical bones,
//   kCanonicalBoneCount f64 bone weights and no references
//   u32 dims, dims f64 mean, dims f64 eigenvalues, dims x dims f64 basis (row-major)
//   u32 training ranges; per range: str source, i32 first frame, i32 last frame
//   [version 3 on: u8 search transform, [dims x dims f64 search transform (row-major)]]; a space
//   without a search transform is written as version 2, one with joint rotations as version 3:
//   only a canonical-bones space needs 4

namespace motiondb {
namespace {

constexpr absl::string_view kMagic = "MDBSPACE";
constexpr size_t kHeaderSize = 8 + 4 + 8;
constexpr size_t kChecksumSize = 4;
// Files larger than this are refused before reading: a 1000-joint space is about 72 MB.
constexpr int64_t kMaxFileBytes = int64_t{1} << 30;

absl::StatusOr<SpaceData> ReadPayload(ByteReader& in, uint32_t version) {
  SpaceData data;
  MOTIONDB_ASSIGN_OR_RETURN(data.skeleton, ReadSkeleton(in));
  MOTIONDB_ASSIGN_OR_RETURN(data.sample_rate, in.F64("sample rate"));
  MOTIONDB_ASSIGN_OR_RETURN(const uint8_t remove_heading, in.U8("heading flag"));
  data.pose.remove_heading = remove_heading != 0;
  MOTIONDB_ASSIGN_OR_RETURN(data.pose.yaw_rate_window, in.I32("yaw-rate window"));
  MOTIONDB_ASSIGN_OR_RETURN(data.yaw_rate_weight, in.F64("yaw-rate weight"));
  MOTIONDB_ASSIGN_OR_RETURN(const uint8_t metric, in.U8("metric"));
  if (metric > static_cast<uint8_t>(SpaceMetric::kEigenvalueScaled)) {
    return absl::InvalidArgumentError(absl::StrCat("space has unknown metric ", metric));
  }
  data.metric = static_cast<SpaceMetric>(metric);
  data.pose.root_velocity = false;
  if (version >= 2) {
    MOTIONDB_ASSIGN_OR_RETURN(const uint8_t root_velocity, in.U8("root-velocity flag"));
    data.pose.root_velocity = root_velocity != 0;
    MOTIONDB_ASSIGN_OR_RETURN(data.root_velocity_weight, in.F64("root-velocity weight"));
  }

  if (version >= 4) {
    MOTIONDB_ASSIGN_OR_RETURN(const uint8_t representation, in.U8("representation"));
    if (representation > static_cast<uint8_t>(SpaceRepresentation::kCanonicalBones)) {
      return absl::InvalidArgumentError(
          absl::StrCat("space has unknown representation ", representation));
    }
    data.representation = static_cast<SpaceRepresentation>(representation);
  }
  const bool canonical = data.representation == SpaceRepresentation::kCanonicalBones;
  const Eigen::Index joints = canonical ? kCanonicalBoneCount : data.skeleton->joint_count();
  data.joint_weights.resize(joints);
  MOTIONDB_RETURN_IF_ERROR(in.F64s("joint weights", data.joint_weights.data(), joints));
  const Eigen::Index references = canonical ? 0 : joints;
  data.references.resize(references, 4);
  MOTIONDB_RETURN_IF_ERROR(in.F64s("references", data.references.data(), 4 * references));
  const int expected_dims =
      canonical ? CanonicalPoseDims(data.pose) : PoseDims(static_cast<int>(joints), data.pose);
  MOTIONDB_ASSIGN_OR_RETURN(const uint32_t dims, in.Count("dimension count", 8 * 2));
  if (dims != static_cast<uint32_t>(expected_dims)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "space has ", dims, " dimensions, its skeleton and options make ", expected_dims));
  }
  data.mean.resize(dims);
  MOTIONDB_RETURN_IF_ERROR(in.F64s("mean", data.mean.data(), dims));
  data.eigenvalues.resize(dims);
  MOTIONDB_RETURN_IF_ERROR(in.F64s("eigenvalues", data.eigenvalues.data(), dims));
  data.basis.resize(dims, dims);
  MOTIONDB_RETURN_IF_ERROR(in.F64s("basis", data.basis.data(), data.basis.size()));

  // A range takes at least a source length and two frame numbers.
  MOTIONDB_ASSIGN_OR_RETURN(const uint32_t ranges, in.Count("training range count", 4 + 4 + 4));
  data.training.resize(ranges);
  for (TrainingSource& source : data.training) {
    MOTIONDB_ASSIGN_OR_RETURN(source.source, in.Str("training source"));
    MOTIONDB_ASSIGN_OR_RETURN(source.frames.first, in.I32("training first frame"));
    MOTIONDB_ASSIGN_OR_RETURN(source.frames.last, in.I32("training last frame"));
  }
  if (version >= 3) {
    MOTIONDB_ASSIGN_OR_RETURN(const uint8_t has_transform, in.U8("search-transform flag"));
    if (has_transform != 0) {
      data.search_transform.resize(dims, dims);
      MOTIONDB_RETURN_IF_ERROR(
          in.F64s("search transform", data.search_transform.data(), data.search_transform.size()));
    }
  }
  return data;
}

}  // namespace

std::string SerializeSpace(const MotionSpace& space) {
  const SpaceData& data = space.data();
  ByteWriter payload;
  WriteSkeleton(*data.skeleton, payload);
  payload.F64(data.sample_rate);
  payload.U8(data.pose.remove_heading ? 1 : 0);
  payload.I32(data.pose.yaw_rate_window);
  payload.F64(data.yaw_rate_weight);
  payload.U8(static_cast<uint8_t>(data.metric));
  payload.U8(data.pose.root_velocity ? 1 : 0);
  payload.F64(data.root_velocity_weight);
  const bool canonical = data.representation == SpaceRepresentation::kCanonicalBones;
  if (canonical) payload.U8(static_cast<uint8_t>(data.representation));
  payload.F64s(data.joint_weights.data(), data.joint_weights.size());
  payload.F64s(data.references.data(), data.references.size());
  payload.U32(static_cast<uint32_t>(data.mean.size()));
  payload.F64s(data.mean.data(), data.mean.size());
  payload.F64s(data.eigenvalues.data(), data.eigenvalues.size());
  payload.F64s(data.basis.data(), data.basis.size());
  payload.U32(static_cast<uint32_t>(data.training.size()));
  for (const TrainingSource& source : data.training) {
    payload.Str(source.source);
    payload.I32(source.frames.first);
    payload.I32(source.frames.last);
  }
  // A space without a transform is written as version 2, which builds before 3 still read, and
  // only one over canonical bones as 4.
  const bool transformed = data.search_transform.size() > 0;
  if (transformed || canonical) payload.U8(transformed ? 1 : 0);
  if (transformed) payload.F64s(data.search_transform.data(), data.search_transform.size());
  const uint32_t version = canonical ? kSpaceFormatVersion : transformed ? 3 : 2;

  ByteWriter file;
  file.bytes().append(kMagic.data(), kMagic.size());
  file.U32(version);
  file.U64(payload.bytes().size());
  file.bytes() += payload.bytes();
  file.U32(Crc32(file.bytes()));
  return std::move(file.bytes());
}

absl::StatusOr<MotionSpace> ParseSpace(absl::string_view bytes) {
  if (bytes.size() < kMagic.size() || bytes.substr(0, kMagic.size()) != kMagic) {
    return absl::DataLossError("not a motiondb space: bad magic (expected \"MDBSPACE\")");
  }
  ByteReader header(bytes.substr(kMagic.size()), "space");
  MOTIONDB_ASSIGN_OR_RETURN(const uint32_t version, header.U32("format version"));
  if (version < 1 || version > kSpaceFormatVersion) {
    return absl::InvalidArgumentError(absl::StrCat("space format version ", version,
                                                   " is not supported (this build reads 1 to ",
                                                   kSpaceFormatVersion, ")"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const uint64_t payload_size, header.U64("payload size"));
  if (payload_size > header.remaining() || payload_size + kChecksumSize != header.remaining()) {
    return absl::DataLossError(absl::StrCat("space is ", bytes.size(), " bytes, its header says ",
                                            kHeaderSize + payload_size + kChecksumSize));
  }
  const absl::string_view checked = bytes.substr(0, kHeaderSize + payload_size);
  ByteReader trailer(bytes.substr(checked.size()), "space");
  MOTIONDB_ASSIGN_OR_RETURN(const uint32_t checksum, trailer.U32("checksum"));
  if (checksum != Crc32(checked)) {
    return absl::DataLossError("space checksum mismatch: the bytes are damaged");
  }
  ByteReader payload(checked.substr(kHeaderSize), "space");
  MOTIONDB_ASSIGN_OR_RETURN(SpaceData data, ReadPayload(payload, version));
  if (payload.remaining() != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("space payload has ", payload.remaining(), " unread bytes at its end"));
  }
  return MotionSpace::FromData(std::move(data));
}

absl::Status WriteSpaceFile(const std::string& path, const MotionSpace& space) {
  return WriteFileAtomically(path, SerializeSpace(space));
}

absl::StatusOr<MotionSpace> ReadSpaceFile(const std::string& path) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::string bytes, ReadFileBytes(path, kMaxFileBytes));
  return Prefixed(path, ParseSpace(bytes));
}

}  // namespace motiondb
