// The binary space format: exact round trips, and every kind of damage rejected.
#include "core/space/space_serialization.h"

#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/motion/skeleton_coding.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"
#include "util/byte_coding.h"
#include "util/crc32.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;

constexpr size_t kHeaderSize = 20;  // magic, version, payload size

class SpaceSerializationTest : public ::testing::Test {
 protected:
  SpaceSerializationTest()
      : clip_(testing::SyntheticClip(testing::HumanoidSkeleton(/*still_root=*/true),
                                     {.frames = 60, .turn_rate = 0.4})),
        space_(*MotionSpace::Build({{"walk.bvh", clip_, FrameRange{5, 50}}},
                                   {.yaw_rate_weight = 0.7,
                                    .root_velocity_weight = 1.3,
                                    .metric = SpaceMetric::kEigenvalueScaled})),
        bytes_(SerializeSpace(space_)) {}

  // `bytes` with its checksum recomputed, so that only the later checks can reject it.
  static std::string Resealed(std::string bytes) {
    const uint32_t crc = Crc32(absl::string_view(bytes).substr(0, bytes.size() - 4));
    for (int i = 0; i < 4; ++i) bytes[bytes.size() - 4 + i] = static_cast<char>(crc >> (8 * i));
    return bytes;
  }

  Clip clip_;
  MotionSpace space_;
  std::string bytes_;
};

TEST_F(SpaceSerializationTest, RoundTripIsExact) {
  const absl::StatusOr<MotionSpace> parsed = ParseSpace(bytes_);
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  const SpaceData& a = space_.data();
  const SpaceData& b = parsed->data();
  EXPECT_TRUE(a.skeleton->SameTopology(*b.skeleton));
  for (int j = 0; j < a.skeleton->joint_count(); ++j) {
    EXPECT_EQ(a.skeleton->joint(j).offset, b.skeleton->joint(j).offset);
    EXPECT_EQ(a.skeleton->joint(j).channels, b.skeleton->joint(j).channels);
    EXPECT_EQ(a.skeleton->joint(j).end_site, b.skeleton->joint(j).end_site);
  }
  EXPECT_EQ(a.sample_rate, b.sample_rate);
  EXPECT_EQ(a.pose.remove_heading, b.pose.remove_heading);
  EXPECT_EQ(a.pose.yaw_rate_window, b.pose.yaw_rate_window);
  EXPECT_EQ(b.yaw_rate_weight, 0.7);
  EXPECT_TRUE(b.pose.root_velocity);
  EXPECT_EQ(b.root_velocity_weight, 1.3);
  EXPECT_EQ(b.metric, SpaceMetric::kEigenvalueScaled);
  EXPECT_EQ(a.joint_weights, b.joint_weights);
  EXPECT_EQ(a.references, b.references);
  EXPECT_EQ(a.mean, b.mean);
  EXPECT_EQ(a.basis, b.basis);
  EXPECT_EQ(a.eigenvalues, b.eigenvalues);
  ASSERT_EQ(b.training.size(), 1u);
  EXPECT_EQ(b.training[0].source, "walk.bvh");
  EXPECT_EQ(b.training[0].frames.first, 5);
  EXPECT_EQ(b.training[0].frames.last, 50);
  EXPECT_EQ(*parsed->ProjectClip(clip_), *space_.ProjectClip(clip_));
  EXPECT_EQ(SerializeSpace(*parsed), bytes_);
}

TEST_F(SpaceSerializationTest, LayoutIsLittleEndianWithMagicAndVersion) {
  EXPECT_EQ(bytes_.substr(0, 8), "MDBSPACE");
  EXPECT_EQ(bytes_.substr(8, 4), std::string("\x02\x00\x00\x00", 4));  // no search transform
  uint64_t payload = 0;
  for (int i = 0; i < 8; ++i) payload |= uint64_t{static_cast<uint8_t>(bytes_[12 + i])} << (8 * i);
  EXPECT_EQ(payload, bytes_.size() - kHeaderSize - 4);
  EXPECT_EQ(Crc32("123456789"), 0xCBF43926u);  // the standard check value
  EXPECT_EQ(Crc32(""), 0u);
}

// A file of format 1 (written before the root velocity) reads as a space without it.
TEST_F(SpaceSerializationTest, VersionOneReadsAsWithoutRootVelocity) {
  const MotionSpace plain = *MotionSpace::Build({{"walk.bvh", clip_, FrameRange{5, 50}}},
                                                {.pose = {.root_velocity = false}});
  std::string bytes = SerializeSpace(plain);
  // Version 1 lacks the root-velocity flag and weight that follow the metric.
  ByteWriter skeleton;
  WriteSkeleton(plain.skeleton(), skeleton);
  const size_t added = kHeaderSize + skeleton.bytes().size() + 8 + 1 + 4 + 8 + 1;
  bytes.erase(added, 1 + 8);
  bytes[8] = 1;
  const uint64_t payload = bytes.size() - kHeaderSize - 4;
  for (int i = 0; i < 8; ++i) bytes[12 + i] = static_cast<char>(payload >> (8 * i));
  const absl::StatusOr<MotionSpace> parsed = ParseSpace(Resealed(bytes));
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  EXPECT_FALSE(parsed->data().pose.root_velocity);
  EXPECT_EQ(parsed->dims(), plain.dims());
  EXPECT_EQ(parsed->data().basis, plain.data().basis);
  // The same bytes as version 2 are short by the flag and weight.
  bytes[8] = 2;
  EXPECT_FALSE(ParseSpace(Resealed(bytes)).ok());
}

// A learned metric's search transform (core/space/learned_metric.h) survives exactly, in format
// 3; a space without one is written in format 2; a transform that cannot be inverted is refused.
TEST_F(SpaceSerializationTest, SearchTransformRoundTripsAndPlainSpacesStayVersionTwo) {
  RowMatrixXd transform = RowMatrixXd::Identity(space_.dims(), space_.dims());
  transform(0, 1) = 0.25;
  transform(2, 2) = 1.0 / 3;
  const absl::StatusOr<MotionSpace> learned = space_.WithSearchTransform(transform);
  ASSERT_TRUE(learned.ok()) << learned.status();
  const std::string bytes = SerializeSpace(*learned);
  const absl::StatusOr<MotionSpace> parsed = ParseSpace(bytes);
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  EXPECT_EQ(parsed->data().search_transform, transform);
  EXPECT_TRUE((parsed->search_transform_inverse() * transform)
                  .isApprox(RowMatrixXd::Identity(space_.dims(), space_.dims()), 1e-12));
  EXPECT_EQ(SerializeSpace(*parsed), bytes);

  EXPECT_EQ(bytes.substr(8, 4), std::string("\x03\x00\x00\x00", 4));
  // A space without one is written as version 2 (above), and reads back without one.
  const absl::StatusOr<MotionSpace> plain = ParseSpace(bytes_);
  ASSERT_TRUE(plain.ok()) << plain.status();
  EXPECT_EQ(plain->data().search_transform.size(), 0);
  EXPECT_EQ(plain->search_transform_inverse().size(), 0);
  // Version 3 with the flag at 0 reads as without one too.
  std::string flagged = bytes_;
  flagged.insert(flagged.size() - 4, 1, '\0');
  flagged[8] = 3;
  const uint64_t payload = flagged.size() - kHeaderSize - 4;
  for (int i = 0; i < 8; ++i) flagged[12 + i] = static_cast<char>(payload >> (8 * i));
  const absl::StatusOr<MotionSpace> unflagged = ParseSpace(Resealed(flagged));
  ASSERT_TRUE(unflagged.ok()) << unflagged.status();
  EXPECT_EQ(unflagged->data().search_transform.size(), 0);
  EXPECT_EQ(unflagged->data().basis, space_.data().basis);

  transform.row(1) = transform.row(0);
  EXPECT_EQ(space_.WithSearchTransform(transform).status().message(),
            "space search transform must be finite and invertible");
  EXPECT_THAT(space_.WithSearchTransform(RowMatrixXd::Identity(2, 2)).status().message(),
              HasSubstr("search transform"));
}

TEST_F(SpaceSerializationTest, RejectsBadMagicVersionAndChecksum) {
  std::string magic = bytes_;
  magic[0] = 'X';
  EXPECT_EQ(ParseSpace(magic).status().code(), absl::StatusCode::kDataLoss);
  EXPECT_THAT(ParseSpace(magic).status().message(), HasSubstr("bad magic"));
  EXPECT_THAT(ParseSpace("BVH HIERARCHY").status().message(), HasSubstr("bad magic"));

  std::string version = bytes_;
  version[8] = 5;  // the first version this build does not read
  EXPECT_EQ(ParseSpace(version).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(ParseSpace(version).status().message(), HasSubstr("version 5 is not supported"));

  for (const size_t at : {kHeaderSize, bytes_.size() / 2, bytes_.size() - 5, bytes_.size() - 1}) {
    std::string flipped = bytes_;
    flipped[at] ^= 0x10;
    const absl::Status status = ParseSpace(flipped).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kDataLoss) << at;
    EXPECT_THAT(status.message(), HasSubstr("checksum")) << at;
  }
}

TEST_F(SpaceSerializationTest, RejectsEveryTruncationAndTrailingBytes) {
  for (size_t size = 0; size < bytes_.size(); ++size) {
    EXPECT_FALSE(ParseSpace(absl::string_view(bytes_).substr(0, size)).ok()) << size;
  }
  EXPECT_THAT(ParseSpace(bytes_ + "x").status().message(), HasSubstr("header says"));
}

TEST_F(SpaceSerializationTest, RejectsSealedButInconsistentContents) {
  // A basis entry scaled: the checksum is right, the space is not.
  std::string scaled = bytes_;
  const size_t basis_end = scaled.size() - 4 - (4 + 4 + 8 + 4 + 4);  // training range, checksum
  scaled[basis_end - 1] ^= 0x40;  // an exponent bit of the last basis entry
  EXPECT_THAT(ParseSpace(Resealed(scaled)).status().message(), HasSubstr("orthonormal"));

  // A payload that ends early inside a field the header still covers.
  std::string short_payload = bytes_.substr(0, kHeaderSize + 40);
  const uint64_t payload = 40;
  for (int i = 0; i < 8; ++i) short_payload[12 + i] = static_cast<char>(payload >> (8 * i));
  short_payload += "0000";
  const absl::Status status = ParseSpace(Resealed(short_payload)).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kDataLoss);
  EXPECT_THAT(status.message(), HasSubstr("truncated"));
}

TEST_F(SpaceSerializationTest, FilesRoundTripAndErrorsNameThePath) {
  const std::filesystem::path dir = testing::MakeTempDir("space_files");
  const std::string path = (dir / "walk.mcs").string();
  ASSERT_TRUE(WriteSpaceFile(path, space_).ok());
  const absl::StatusOr<MotionSpace> read = ReadSpaceFile(path);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->data().basis, space_.data().basis);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));

  const absl::Status missing = ReadSpaceFile((dir / "none.mcs").string()).status();
  EXPECT_EQ(missing.code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(missing.message(), HasSubstr("none.mcs"));
  std::filesystem::resize_file(path, 100);
  EXPECT_THAT(ReadSpaceFile(path).status().message(), HasSubstr("walk.mcs: space is"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace motiondb
