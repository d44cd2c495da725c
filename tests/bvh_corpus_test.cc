// Every BVH file of the shared corpus and of Debian's assimp-testmodels parses, and the frame
// count equals the frame rows actually in the file (counted here independently).
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/bvh/bvh_reader.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

// The non-blank lines after the "Frame Time" line.
int CountFrameRows(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  bool in_rows = false;
  int rows = 0;
  while (std::getline(in, line)) {
    if (in_rows) {
      rows += line.find_first_not_of(" \t\r") != std::string::npos;
    } else if (line.find("Frame Time") != std::string::npos) {
      in_rows = true;
    }
  }
  return rows;
}

void ExpectAllParse(const std::filesystem::path& dir, size_t minimum_files) {
  const std::vector<std::filesystem::path> files = testing::BvhFilesUnder(dir);
  EXPECT_GE(files.size(), minimum_files) << dir;
  for (const std::filesystem::path& path : files) {
    SCOPED_TRACE(path.string());
    absl::StatusOr<BvhReadResult> result = ReadBvhFile(path.string());
    ASSERT_TRUE(result.ok()) << result.status();
    EXPECT_EQ(result->clip.frame_count(), CountFrameRows(path));
    EXPECT_GT(result->clip.skeleton().joint_count(), 1);
  }
}

TEST(BvhCorpus, SharedMocapFolderParses) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  for (const char* folder : {"conformance", "cmu", "other-skeletons", "bandai1"}) {
    ExpectAllParse(mocap / folder, 4);
  }
}

TEST(BvhCorpus, BandaiDatasetTwoParsesWithItsSkeleton) {
  MOTIONDB_REQUIRE_MOCAP(mocap);
  ExpectAllParse(mocap / "bandai2-normal", 465);
  absl::StatusOr<BvhReadResult> one =
      ReadBvhFile((mocap / "bandai2-normal" / "dataset-2_walk_normal_001.bvh").string());
  ASSERT_TRUE(one.ok()) << one.status();
  EXPECT_EQ(one->clip.skeleton().joint_count(), 22);
  EXPECT_EQ(one->clip.skeleton().joint(1).channels.size(), 6u) << "6 channels on non-root joints";
  EXPECT_NEAR(one->clip.fps(), 30.0, 1e-3);
}

TEST(BvhCorpus, AssimpTestModelsParse) {
  const auto dir = testing::AssimpBvhDir();
  if (!dir) GTEST_SKIP() << "assimp-testmodels is not installed; skipped";
  ExpectAllParse(*dir, 3);
  absl::StatusOr<BvhReadResult> walk = ReadBvhFile((*dir / "01_01.bvh").string());
  ASSERT_TRUE(walk.ok());
  EXPECT_EQ(walk->clip.skeleton().joint_count(), 31);
  EXPECT_EQ(walk->clip.frame_count(), 2752);
}

}  // namespace
}  // namespace motiondb
