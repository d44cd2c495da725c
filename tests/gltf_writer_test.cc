// Clips written as glTF (core/gltf/gltf_writer.h) and read back by assimp, as other tools read
// them: the joints move where the clip's do, at its frame times.
#include "core/gltf/gltf_writer.h"

#include <gtest/gtest.h>

#include "core/bvh/bvh_reader.h"
#include "core/motion/forward_kinematics.h"
#include "core/scene/scene_reader.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

// Joint positions agree within this fraction of the clip's extent: glTF holds 32-bit floats.
constexpr double kTolerance = 1e-5;

void ExpectReadsBack(const Clip& clip, const GltfWriteOptions& options) {
  auto written = WriteGltf(clip, options);
  ASSERT_TRUE(written.ok()) << written.status();
  EXPECT_LE(static_cast<int64_t>(written->size()),
            GltfBound(clip.skeleton(), options.range ? options.range->size() : clip.frame_count(),
                      static_cast<int64_t>(options.name.size())));
  auto read =
      ReadScene(*written, options.binary ? MotionFileFormat::kGlb : MotionFileFormat::kGltf);
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->takes.size(), 1u);
  EXPECT_EQ(read->takes[0].name, options.name.empty() ? "motion" : options.name);
  const Clip& back = read->takes[0].clip;
  const FrameRange range = options.range.value_or(FrameRange{0, clip.frame_count() - 1});
  ASSERT_EQ(back.frame_count(), range.size());
  if (range.size() > 1) {
    EXPECT_NEAR(back.frame_time(), clip.frame_time(), 1e-6);
  }
  const RowMatrixXd expected = ForwardKinematics(clip).middleRows(range.first, range.size());
  const RowMatrixXd actual = ForwardKinematics(back);
  const double extent = expected.cwiseAbs().maxCoeff();
  for (int j = 0; j < back.skeleton().joint_count(); ++j) {
    const int source = clip.skeleton().FindJoint(back.skeleton().joint(j).name);
    ASSERT_GE(source, 0) << back.skeleton().joint(j).name;
    const double error =
        (actual.middleCols(3 * j, 3) - expected.middleCols(3 * source, 3)).cwiseAbs().maxCoeff();
    EXPECT_LE(error, kTolerance * extent) << back.skeleton().joint(j).name;
  }
  EXPECT_EQ(back.skeleton().joint_count(), clip.skeleton().joint_count());
}

TEST(GltfWriterTest, RealTakesReadBackAsGlbAndGltf) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  for (const char* file : {"cmu/01_01_motionbuilder.bvh",
                           "bandai2-normal/dataset-2_raise-up-both-hands_normal_001.bvh"}) {
    auto bvh = ReadBvhFile((mocap / file).string());
    ASSERT_TRUE(bvh.ok()) << bvh.status();
    ExpectReadsBack(bvh->clip, {true, "take", std::nullopt});
    ExpectReadsBack(bvh->clip, {false, "", std::nullopt});
    ExpectReadsBack(bvh->clip, {true, "hit", FrameRange{10, 40}});
  }
}

TEST(GltfWriterTest, ARangeOutsideTheClipIsRefused) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  auto bvh = ReadBvhFile((mocap / "cmu/01_01_motionbuilder.bvh").string());
  ASSERT_TRUE(bvh.ok()) << bvh.status();
  auto written = WriteGltf(bvh->clip, {false, "", FrameRange{0, bvh->clip.frame_count()}});
  EXPECT_EQ(written.status().code(), absl::StatusCode::kOutOfRange);
}

}  // namespace
}  // namespace motiondb
