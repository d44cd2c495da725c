// FBX and glTF read into clips (core/scene/scene_reader.h), on files Debian's Blender made from
// real BVH takes: each file's joints move where its BVH's do.
#include "core/scene/scene_reader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <optional>

#include "core/bvh/bvh_reader.h"
#include "core/motion/forward_kinematics.h"
#include "tests/scene_files.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using ::motiondb::testing::ReadFileOrDie;

// World positions agree within this fraction of the skeleton's height: Blender keeps 32-bit
// floats, and the BVH text six decimals.
constexpr double kPositionTolerance = 1e-4;

absl::StatusOr<SceneReadResult> ReadSceneFile(const std::filesystem::path& path,
                                              MotionFileFormat format) {
  return ReadScene(ReadFileOrDie(path), format);
}

// Each joint's world positions, in metres, by name.
std::map<std::string, RowMatrixXd> WorldPositions(const Clip& clip, double unit_m) {
  const RowMatrixXd world = ForwardKinematics(clip) * unit_m;
  std::map<std::string, RowMatrixXd> by_name;
  for (int j = 0; j < clip.skeleton().joint_count(); ++j) {
    by_name[clip.skeleton().joint(j).name] = world.middleCols(3 * j, 3);
  }
  return by_name;
}

// Blender reads a BVH's units as metres; so does this comparison.
void ExpectSameMotion(const Clip& bvh, const Clip& scene, double unit_m, int min_joints) {
  ASSERT_EQ(scene.frame_count(), bvh.frame_count());
  EXPECT_NEAR(scene.frame_time(), bvh.frame_time(), 1e-4 * bvh.frame_time());
  const auto expected = WorldPositions(bvh, 1.0);
  const auto actual = WorldPositions(scene, unit_m);
  double height = 0;
  for (const auto& [name, positions] : expected) {
    height = std::max(height, positions.col(1).maxCoeff() - positions.col(1).minCoeff());
  }
  int compared = 0;
  double worst = 0;
  std::string worst_joint;
  for (const auto& [name, positions] : actual) {
    const auto found = expected.find(name);
    if (found == expected.end()) continue;
    ++compared;
    const double error = (positions - found->second).rowwise().norm().maxCoeff();
    if (error > worst) {
      worst = error;
      worst_joint = name;
    }
  }
  EXPECT_GE(compared, min_joints);
  EXPECT_LE(worst, kPositionTolerance * height) << "joint " << worst_joint << ", height " << height;
}

TEST(SceneReaderTest, FbxOfABvhTakeMovesItsJointsAsTheBvhDoes) {
  MOTIONDB_BLENDER_FILE(fbx, "one.fbx");
  auto bvh = ReadBvhFile(testing::FirstTake().string());
  ASSERT_TRUE(bvh.ok()) << bvh.status();
  auto scene = ReadSceneFile(fbx, MotionFileFormat::kFbx);
  ASSERT_TRUE(scene.ok()) << scene.status();
  ASSERT_EQ(scene->takes.size(), 1u);
  EXPECT_EQ(scene->facts.up_axis, 'Y');
  EXPECT_DOUBLE_EQ(scene->facts.unit_m, 0.01);  // Blender writes centimetres
  EXPECT_NE(scene->facts.generator.find("Blender"), std::string::npos);
  // Blender animates the armature's object too: it is the FBX's root, above the BVH's.
  EXPECT_EQ(scene->takes[0].clip.skeleton().joint_count(), bvh->clip.skeleton().joint_count() + 1);
  ExpectSameMotion(bvh->clip, scene->takes[0].clip, scene->facts.unit_m,
                   bvh->clip.skeleton().joint_count());
}

TEST(SceneReaderTest, GlbOfABvhTakeMovesItsJointsAsTheBvhDoes) {
  MOTIONDB_BLENDER_FILE(glb, "one.glb");
  auto bvh = ReadBvhFile(testing::FirstTake().string());
  ASSERT_TRUE(bvh.ok()) << bvh.status();
  auto scene = ReadSceneFile(glb, MotionFileFormat::kGlb);
  ASSERT_TRUE(scene.ok()) << scene.status();
  ASSERT_EQ(scene->takes.size(), 1u);
  EXPECT_EQ(scene->facts.format, MotionFileFormat::kGlb);
  EXPECT_DOUBLE_EQ(scene->facts.unit_m, 1.0);
  // glTF keeps no still bone above the moving ones: the BVH's root may be folded away.
  ExpectSameMotion(bvh->clip, scene->takes[0].clip, scene->facts.unit_m,
                   bvh->clip.skeleton().joint_count() - 1);
}

TEST(SceneReaderTest, ZUpFbxIsTurnedYUpAndSaysSo) {
  MOTIONDB_BLENDER_FILE(zup, "zup.fbx");
  auto bvh = ReadBvhFile(testing::FirstTake().string());
  ASSERT_TRUE(bvh.ok()) << bvh.status();
  auto scene = ReadSceneFile(zup, MotionFileFormat::kFbx);
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->facts.up_axis, 'Z');
  // Turned Y up, the world is the BVH's but for the turn about the vertical that the Z-up
  // file's forward axis makes: compare heights, and distances from the root.
  const Clip& clip = scene->takes[0].clip;
  ASSERT_EQ(clip.frame_count(), bvh->clip.frame_count());
  const auto expected = WorldPositions(bvh->clip, 1.0);
  const auto actual = WorldPositions(clip, scene->facts.unit_m);
  const RowMatrixXd& root_expected = expected.at("Hips");
  const RowMatrixXd& root_actual = actual.at("Hips");
  double worst = 0;
  for (const auto& [name, positions] : actual) {
    const auto found = expected.find(name);
    if (found == expected.end()) continue;
    const RowMatrixXd& want = found->second;
    worst = std::max(worst, (positions.col(1) - want.col(1)).cwiseAbs().maxCoeff());
    worst = std::max(worst, ((positions - root_actual).rowwise().norm() -
                             (want - root_expected).rowwise().norm())
                                .cwiseAbs()
                                .maxCoeff());
  }
  EXPECT_LT(worst, 2e-3);
}

TEST(SceneReaderTest, EveryTakeOfAFileIsAClip) {
  MOTIONDB_BLENDER_FILE(two, "two.fbx");
  auto scene = ReadSceneFile(two, MotionFileFormat::kFbx);
  ASSERT_TRUE(scene.ok()) << scene.status();
  ASSERT_EQ(scene->takes.size(), 2u);
  auto second = ReadBvhFile(testing::SecondTake().string());
  ASSERT_TRUE(second.ok()) << second.status();
  EXPECT_NE(scene->takes[0].name, scene->takes[1].name);
  EXPECT_NE(scene->takes[1].name.find("normal_002"), std::string::npos) << scene->takes[1].name;
  ExpectSameMotion(second->clip, scene->takes[1].clip, scene->facts.unit_m,
                   second->clip.skeleton().joint_count());
}

TEST(SceneReaderTest, AFileWithoutAnimationSaysWhatIsMissing) {
  for (const auto& [file, format] : {std::pair{"mesh.fbx", MotionFileFormat::kFbx},
                                     std::pair{"mesh.glb", MotionFileFormat::kGlb}}) {
    MOTIONDB_BLENDER_FILE(path, file);
    auto scene = ReadSceneFile(path, format);
    ASSERT_FALSE(scene.ok()) << file;
    EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(scene.status().message().find("no skeletal animation"), std::string::npos)
        << scene.status();
  }
}

TEST(SceneReaderTest, TruncatedAndCorruptFilesAreRefused) {
  for (const auto& [file, format] : {std::pair{"one.fbx", MotionFileFormat::kFbx},
                                     std::pair{"one.glb", MotionFileFormat::kGlb}}) {
    MOTIONDB_BLENDER_FILE(path, file);
    const std::string bytes = ReadFileOrDie(path);
    for (const size_t keep : {bytes.size() / 2, size_t{40}, size_t{0}}) {
      auto scene = ReadScene(absl::string_view(bytes).substr(0, keep), format);
      ASSERT_FALSE(scene.ok()) << file << " cut at " << keep;
      EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument) << scene.status();
    }
    std::string corrupt = bytes;
    for (size_t i = 64; i < corrupt.size(); i += 7)
      corrupt[i] = static_cast<char>(corrupt[i] ^ 0x5a);
    EXPECT_FALSE(ReadScene(corrupt, format).ok()) << file;
  }
}

TEST(SceneReaderTest, AnOversizeTakeIsRefusedBeforeItIsBuilt) {
  MOTIONDB_BLENDER_FILE(fbx, "one.fbx");
  SceneReadOptions options;
  options.max_clip_bytes = 1000;
  auto scene = ReadScene(ReadFileOrDie(fbx), MotionFileFormat::kFbx, options);
  ASSERT_FALSE(scene.ok());
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kResourceExhausted) << scene.status();
}

// Files from other tools: Debian's assimp-testmodels.
std::optional<std::filesystem::path> AssimpModel(const char* relative) {
  const auto bvh_dir = testing::AssimpBvhDir();
  if (!bvh_dir) return std::nullopt;
  return bvh_dir->parent_path() / relative;
}

TEST(SceneReaderTest, ReadsAnAnimatedSkeletonFromAnotherToolsFbx) {
  const auto path = AssimpModel("FBX/animation_with_skeleton.fbx");
  if (!path) GTEST_SKIP() << "assimp-testmodels is not installed; skipped";
  auto scene = ReadSceneFile(*path, MotionFileFormat::kFbx);
  ASSERT_TRUE(scene.ok()) << scene.status();
  ASSERT_EQ(scene->takes.size(), 1u);
  EXPECT_EQ(scene->takes[0].name, "Armature|ArmatureAction");
  EXPECT_EQ(scene->takes[0].clip.frame_count(), 21);
  EXPECT_NEAR(scene->takes[0].clip.fps(), 24, 1e-6);
  EXPECT_GE(scene->takes[0].clip.skeleton().joint_count(), 3);
}

TEST(SceneReaderTest, MeshesWithoutAnimationAndMissingBuffersAreRefused) {
  const auto spider = AssimpModel("FBX/spider.fbx");
  if (!spider) GTEST_SKIP() << "assimp-testmodels is not installed; skipped";
  auto scene = ReadSceneFile(*spider, MotionFileFormat::kFbx);
  ASSERT_FALSE(scene.ok());
  EXPECT_NE(scene.status().message().find("no skeletal animation: the file has 19 mesh(es)"),
            std::string::npos)
      << scene.status();
  // A .gltf whose data lies in a file beside it, which an upload cannot bring.
  scene = ReadSceneFile(*AssimpModel("glTF2/MissingBin/BoxTextured.gltf"), MotionFileFormat::kGltf);
  ASSERT_FALSE(scene.ok());
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(scene.status().message().find("BoxTextured0.bin"), std::string::npos);
  EXPECT_NE(scene.status().message().find("a .glb"), std::string::npos) << scene.status();
}

TEST(SceneFormatTest, FilesAreToldApartByTheirFirstBytes) {
  EXPECT_EQ(DetectMotionFileFormat("HIERARCHY\nROOT Hips"), MotionFileFormat::kBvh);
  EXPECT_EQ(DetectMotionFileFormat("\xEF\xBB\xBF  HIERARCHY"), MotionFileFormat::kBvh);
  EXPECT_EQ(DetectMotionFileFormat(std::string("Kaydara FBX Binary  \0\x1a", 22)),
            MotionFileFormat::kFbx);
  EXPECT_EQ(DetectMotionFileFormat("; FBX 7.4.0 project file"), MotionFileFormat::kFbx);
  EXPECT_EQ(DetectMotionFileFormat("glTF\x02"), MotionFileFormat::kGlb);
  EXPECT_EQ(DetectMotionFileFormat(" {\"asset\": {\"version\": \"2.0\"}}"),
            MotionFileFormat::kGltf);
  EXPECT_EQ(DetectMotionFileFormat("MOTION"), std::nullopt);
  EXPECT_EQ(DetectMotionFileFormat(""), std::nullopt);
}

}  // namespace
}  // namespace motiondb
