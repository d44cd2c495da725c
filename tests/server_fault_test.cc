// Faults of the storage under the real server: a disk that fills up and a database on a
// read-only file system. Each runs on a small tmpfs the test mounts (mount(2) needs root or
// CAP_SYS_ADMIN, which CI and the project's machines have; elsewhere the tests skip and say so).
#include <signal.h>
#include <sys/mount.h>
#include <sys/statvfs.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <set>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "storage/sqlite_connection.h"
#include "tests/server_fixture.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using testing::ServerProcess;
using testing::SyntheticSegment;

// A tmpfs of a given size mounted on a folder for the life of the object.
class ScratchFileSystem {
 public:
  ~ScratchFileSystem() { Unmount(); }

  void Unmount() {
    if (mounted_) ::umount2(path_.c_str(), MNT_DETACH);
    mounted_ = false;
  }

  // Mounts a tmpfs of `size_kib` on `path` (created); the errno's text when it cannot.
  std::string Mount(const std::filesystem::path& path, int size_kib) {
    path_ = path.string();
    std::filesystem::create_directories(path);
    const std::string options = "size=" + std::to_string(size_kib) + "k,mode=0700";
    if (::mount("tmpfs", path_.c_str(), "tmpfs", 0, options.c_str()) != 0) {
      return std::strerror(errno);
    }
    mounted_ = true;
    return "";
  }

  // Remounts with a new size, or read-only; false with the errno's text in `error`.
  bool Remount(const std::string& options, unsigned long flags, std::string* error) {
    if (::mount("tmpfs", path_.c_str(), "tmpfs", MS_REMOUNT | flags, options.c_str()) == 0) {
      return true;
    }
    *error = std::strerror(errno);
    return false;
  }

  // Shrinks the file system to what it holds now and `free_kib` more.
  bool LeaveFree(int free_kib, std::string* error) {
    struct statvfs usage;
    if (::statvfs(path_.c_str(), &usage) != 0) {
      *error = std::strerror(errno);
      return false;
    }
    const uint64_t used_kib = (usage.f_blocks - usage.f_bfree) * usage.f_frsize / 1024;
    return Remount("size=" + std::to_string(used_kib + free_kib) + "k", 0, error);
  }

 private:
  std::string path_;
  bool mounted_ = false;
};

class ServerFaultTest : public ServerTest {
 protected:
  // The servers stop and the file system goes before the test's folder is removed.
  void TearDown() override {
    StopServers();
    disk_.Unmount();
    ServerTest::TearDown();
  }

  // A tmpfs of `size_kib` at dir_/disk, the test's database moved onto it.
  void MountScratch(int size_kib) {
    const std::string error = disk_.Mount(dir_ / "disk", size_kib);
    if (!error.empty()) {
      GTEST_SKIP() << "cannot mount a tmpfs here (" << error
                   << "): these tests need root or CAP_SYS_ADMIN; skipped";
    }
    db_ = (dir_ / "disk" / "motiondb.sqlite").string();
  }

  // The names of the stored clips.
  static std::set<std::string> StoredNames(Client& client) {
    v1::ListClipsRequest list;
    list.set_page_size(1000);
    v1::ListClipsResponse stored;
    const grpc::Status status = client.clips().ListClips(client.Context().get(), list, &stored);
    EXPECT_TRUE(status.ok()) << status.error_message();
    std::set<std::string> names;
    for (const v1::Clip& clip : stored.clips()) names.insert(clip.name());
    return names;
  }

  std::string IntegrityCheck() const {
    absl::StatusOr<std::unique_ptr<storage::SqliteConnection>> connection =
        storage::SqliteConnection::Open(db_, storage::SqliteConnection::Mode::kReadOnly, 1000);
    if (!connection.ok()) return connection.status().ToString();
    absl::StatusOr<std::string> answer = (*connection)->QueryText("PRAGMA integrity_check");
    return answer.ok() ? *answer : answer.status().ToString();
  }

  ScratchFileSystem disk_;
};

// The disk fills up under ingest: the write that does not fit is refused with
// RESOURCE_EXHAUSTED saying the disk is full, every acknowledged clip stays listed and
// searchable, a space that does not fit is not created, the server stays up, and once space
// returns writes succeed again without a restart; the file passes its integrity check.
TEST_F(ServerFaultTest, FullDiskRefusesWritesClearlyAndRecoversWhenSpaceReturns) {
  MountScratch(65536);
  if (IsSkipped()) return;
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::vector<int64_t> ids = IngestHumanoid(client);
  CreateHumanoidSpace(client);
  std::set<std::string> acknowledged = StoredNames(client);
  ASSERT_EQ(acknowledged.size(), ids.size());
  // Room for a few more clips: the write-ahead log grows with each commit until a checkpoint.
  std::string error;
  ASSERT_TRUE(disk_.LeaveFree(2048, &error)) << error;

  std::vector<std::string> texts;
  for (const Clip& clip : Humanoid().clips) texts.push_back(BvhText(clip));
  grpc::Status refused;
  for (int i = 0; i < 400 && refused.ok(); ++i) {
    const std::string name = "fill_" + std::to_string(i);
    v1::IngestClipResponse response;
    refused = client.Ingest(name + ".bvh", texts[i % texts.size()], &response);
    if (refused.ok()) acknowledged.insert(name);
  }
  ASSERT_FALSE(refused.ok()) << "the disk never filled up";
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << refused.error_message();
  EXPECT_THAT(refused.error_message(), HasSubstr("full"));

  // Still serving, with every acknowledged clip and nothing else.
  EXPECT_EQ(StoredNames(client), acknowledged);
  v1::SearchResponse found;
  const SyntheticSegment& raise = FirstRaise();
  grpc::Status searched = client.Search(
      ClipQuery("body", ids[raise.clip], raise.first_frame, raise.last_frame), &found);
  ASSERT_TRUE(searched.ok()) << searched.error_message();
  EXPECT_GT(found.results_size(), 0);
  v1::CreateSpaceRequest second;
  second.set_name("second");
  v1::Space space;
  const grpc::Status not_created = client.CreateSpace(second, &space);
  EXPECT_EQ(not_created.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED)
      << not_created.error_message();
  v1::GetSpaceRequest get;
  get.set_name("second");
  EXPECT_EQ(client.spaces().GetSpace(client.Context().get(), get, &space).error_code(),
            grpc::StatusCode::NOT_FOUND);

  // Space returns: the same server takes writes again.
  ASSERT_TRUE(disk_.Remount("size=64m", 0, &error)) << error;
  const int64_t after = client.IngestOrFail("after_full.bvh", texts[0]);
  EXPECT_GT(after, 0);
  acknowledged.insert("after_full");
  ASSERT_TRUE(client.CreateSpace(second, &space).ok());
  EXPECT_EQ(space.index().clips(), static_cast<int64_t>(acknowledged.size()));
  EXPECT_EQ(StoredNames(client), acknowledged);
  ASSERT_EQ(server->Stop(SIGTERM), 0);
  EXPECT_EQ(IntegrityCheck(), "ok");
  EXPECT_THAT(server->Log(), HasSubstr("full"));
}

// A database on a read-only file system is refused at start (exit code 1) with a message
// saying so and naming the file, and is left as it was.
TEST_F(ServerFaultTest, DatabaseOnAReadOnlyFileSystemIsRefusedAtStart) {
  MountScratch(65536);
  if (IsSkipped()) return;
  {
    ServerProcess* server = StartServer();
    ASSERT_NE(server, nullptr);
    Client client(testing::InsecureChannel(server->address()));
    client.IngestOrFail("chain.bvh", BvhText(ChainClip()));
    ASSERT_EQ(server->Stop(SIGTERM), 0);
  }
  const std::string before = testing::ReadFileOrDie(db_);
  std::string error;
  ASSERT_TRUE(disk_.Remount("", MS_RDONLY, &error)) << error;
  ServerProcess server;
  EXPECT_FALSE(server.Start({"--db", db_}, &error));
  EXPECT_THAT(error, HasSubstr("exited with code 1"));
  EXPECT_THAT(error, HasSubstr("read-only"));
  EXPECT_THAT(error, HasSubstr(db_));
  EXPECT_EQ(testing::ReadFileOrDie(db_), before);
}

}  // namespace
}  // namespace motiondb
