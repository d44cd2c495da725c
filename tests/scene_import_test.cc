// FBX and glTF uploads read in a child process (server/upload/scene_import.h): the real
// importer's takes, and an importer that crashes, complains, hangs or is stopped, each failing
// its upload alone with a status that says so.
#include "server/upload/scene_import.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "tests/scene_files.h"
#include "tests/test_data.h"

namespace motiondb::server {
namespace {

using ::motiondb::testing::ReadFileOrDie;

// A shell script standing in for the importer.
std::string FakeImporter(const std::string& name, const std::string& body) {
  const std::filesystem::path path = testing::MakeTempDir("fake_importer") / name;
  std::ofstream(path) << "#!/bin/sh\n" << body << "\n";
  std::filesystem::permissions(path, std::filesystem::perms::owner_all);
  return path.string();
}

const std::string kGlbHead = std::string("glTF\x02\x00\x00\x00", 8);

TEST(SceneImportTest, TheImporterReadsEveryTakeOfAFile) {
  MOTIONDB_BLENDER_FILE(two, "two.fbx");
  auto file = ImportScene(ReadFileOrDie(two), MotionFileFormat::kFbx, UploadLimits());
  ASSERT_TRUE(file.ok()) << file.status();
  ASSERT_EQ(file->takes.size(), 2u);
  EXPECT_EQ(file->takes[0].clip.frame_count(), 51);
  EXPECT_EQ(file->takes[1].clip.frame_count(), 57);
  EXPECT_EQ(file->format, MotionFileFormat::kFbx);
  EXPECT_EQ(file->up_axis, 'Y');
  EXPECT_DOUBLE_EQ(file->unit_m, 0.01);
  EXPECT_NE(file->generator.find("Blender"), std::string::npos);
}

TEST(SceneImportTest, AFileTheImporterCannotReadSaysWhy) {
  auto file = ImportScene(kGlbHead + "not a scene", MotionFileFormat::kGlb, UploadLimits());
  ASSERT_FALSE(file.ok());
  EXPECT_EQ(file.status().code(), absl::StatusCode::kInvalidArgument) << file.status();
  EXPECT_NE(file.status().message().find("not a readable GLB file"), std::string::npos)
      << file.status();
}

TEST(SceneImportTest, AnImporterThatCrashesOrComplainsFailsTheUploadAlone) {
  UploadLimits limits;
  limits.scene_importer = FakeImporter("crash", "kill -SEGV $$");
  auto file = ImportScene(kGlbHead, MotionFileFormat::kGlb, limits);
  EXPECT_EQ(file.status().code(), absl::StatusCode::kInvalidArgument) << file.status();
  EXPECT_NE(file.status().message().find("signal 11"), std::string::npos) << file.status();

  limits.scene_importer = FakeImporter("complain", "echo 'out of sorts' >&2; exit 3");
  file = ImportScene(kGlbHead, MotionFileFormat::kGlb, limits);
  EXPECT_EQ(file.status().code(), absl::StatusCode::kInternal) << file.status();
  EXPECT_NE(file.status().message().find("out of sorts"), std::string::npos) << file.status();

  limits.scene_importer = "/nonexistent/motiondb-scene-import";
  file = ImportScene(kGlbHead, MotionFileFormat::kGlb, limits);
  EXPECT_EQ(file.status().code(), absl::StatusCode::kUnavailable) << file.status();
}

TEST(SceneImportTest, AHangingImporterIsStoppedByItsCallerOrItsTime) {
  UploadLimits limits;
  limits.scene_importer = FakeImporter("hang", "exec sleep 600");
  auto file = ImportScene(kGlbHead, MotionFileFormat::kGlb, limits, [] { return true; });
  EXPECT_EQ(file.status().code(), absl::StatusCode::kCancelled) << file.status();
  limits.max_import_time = std::chrono::milliseconds(0);
  file = ImportScene(kGlbHead, MotionFileFormat::kGlb, limits);
  EXPECT_EQ(file.status().code(), absl::StatusCode::kDeadlineExceeded) << file.status();
}

TEST(SceneImportTest, AnImporterThatWritesWithoutEndIsStoppedAtTheLimit) {
  UploadLimits limits;
  limits.scene_importer = FakeImporter("flood", "exec yes motiondb");
  limits.max_bvh_bytes = 1 << 20;
  auto file = ImportScene(kGlbHead, MotionFileFormat::kGlb, limits);
  EXPECT_EQ(file.status().code(), absl::StatusCode::kResourceExhausted) << file.status();
}

}  // namespace
}  // namespace motiondb::server
