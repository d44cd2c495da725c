// The server's lifecycle and concurrency, on the real binary (server_fixture.h): a damaged
// database refused at start, restarts, searches during ingest, deadlines, writes past their
// deadline, a backup while ingesting.
#include <signal.h>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "storage/sqlite_connection.h"
#include "testing/server_process.h"
#include "testing/synthetic_corpus.h"
#include "tests/clip_builder.h"
#include "tests/server_fixture.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using testing::GenerateSyntheticCorpus;
using ::testing::HasSubstr;
using ::testing::Not;
using testing::ServerProcess;
using testing::SyntheticCorpus;
using testing::SyntheticCorpusOptions;
using testing::SyntheticSegment;

// A database file damaged on disk, truncated or with zeroed pages, is refused at start with a
// message that says so and exit code 1, never a crash; the file is left as it was.
TEST_F(ServerTest, DamagedDatabaseIsRefusedAtStart) {
  {
    ServerProcess* server = StartServer();
    ASSERT_NE(server, nullptr);
    Client client(testing::InsecureChannel(server->address()));
    IngestHumanoid(client);
    CreateHumanoidSpace(client);
    ASSERT_EQ(server->Stop(SIGTERM), 0);
  }
  const std::string whole = testing::ReadFileOrDie(db_);
  ASSERT_GT(whole.size(), 64u * 1024);
  std::string zeroed = whole;
  std::fill(zeroed.begin() + 40 * 1024, zeroed.begin() + 60 * 1024, '\0');
  const std::vector<std::pair<std::string, std::string>> damaged = {
      {"truncated", whole.substr(0, whole.size() / 2)}, {"zeroed", zeroed}};
  for (const auto& [kind, bytes] : damaged) {
    SCOPED_TRACE(kind);
    const std::string path = WriteFile(kind + ".sqlite", bytes);
    ServerProcess server;
    std::string error;
    EXPECT_FALSE(server.Start({"--db", path}, &error));
    EXPECT_THAT(error, HasSubstr("exited with code 1"));
    EXPECT_THAT(error, ::testing::ContainsRegex("damaged|integrity check"));
    EXPECT_EQ(testing::ReadFileOrDie(path), bytes);
  }
}

TEST_F(ServerTest, RestartKeepsEverything) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  v1::SearchRequest query;
  v1::SearchResponse before;
  v1::Space space_before;
  v1::ListClipsResponse clips_before;
  {
    Client client(testing::InsecureChannel(server->address()));
    const std::vector<int64_t> ids = IngestHumanoid(client);
    space_before = CreateHumanoidSpace(client);
    const SyntheticSegment& raise = FirstRaise();
    query = ClipQuery("body", ids[raise.clip], raise.first_frame, raise.last_frame);
    ASSERT_TRUE(client.Search(query, &before).ok());
    ASSERT_TRUE(client.clips()
                    .ListClips(client.Context().get(), v1::ListClipsRequest(), &clips_before)
                    .ok());
  }
  EXPECT_EQ(server->Stop(SIGTERM), 0);
  EXPECT_THAT(server->Log(), HasSubstr("received SIGTERM"));

  server = StartServer();
  ASSERT_NE(server, nullptr);
  EXPECT_THAT(server->Log(), HasSubstr("loaded 1 space indices"));
  {
    Client client(testing::InsecureChannel(server->address()));
    v1::ListClipsResponse clips_after;
    ASSERT_TRUE(client.clips()
                    .ListClips(client.Context().get(), v1::ListClipsRequest(), &clips_after)
                    .ok());
    EXPECT_EQ(clips_after.SerializeAsString(), clips_before.SerializeAsString());
    v1::GetSpaceRequest get;
    get.set_name("body");
    v1::Space space_after;
    ASSERT_TRUE(client.spaces().GetSpace(client.Context().get(), get, &space_after).ok());
    EXPECT_EQ(space_after.SerializeAsString(), space_before.SerializeAsString());
    v1::SearchResponse after;
    ASSERT_TRUE(client.Search(query, &after).ok());
    ExpectSameResults(after, before);
  }
  // Stopped with no client connected: an idle connection makes a graceful stop wait (up to
  // 5 s in gRPC 1.51) for the client to acknowledge the GOAWAY.
  EXPECT_EQ(server->Stop(SIGINT), 0);
}

TEST_F(ServerTest, ConcurrentSearchesDuringIngestAllSucceed) {
  ServerProcess* server = StartServer({"--threads", "8"});
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::vector<int64_t> ids = IngestHumanoid(client);
  CreateHumanoidSpace(client);
  const SyntheticSegment& raise = FirstRaise();
  const v1::SearchRequest query =
      ClipQuery("body", ids[raise.clip], raise.first_frame, raise.last_frame);
  v1::SearchResponse baseline;
  ASSERT_TRUE(client.Search(query, &baseline).ok());

  std::atomic<bool> ingesting{true};
  std::atomic<int> searches{0};
  std::vector<std::string> failures[4];
  std::vector<std::thread> searchers;
  for (int t = 0; t < 4; ++t) {
    searchers.emplace_back([&, t] {
      Client own(testing::InsecureChannel(server->address()));
      int64_t library_frames = 0;
      // At least a few searches each, and on until the ingests are done.
      for (int i = 0; i < 5 || ingesting; ++i) {
        v1::SearchResponse found;
        const grpc::Status status = own.Search(query, &found);
        ++searches;
        if (!status.ok()) {
          failures[t].push_back(status.error_message());
          continue;
        }
        // Every answer comes from one whole snapshot: the query finds itself first, and the
        // library only grows.
        if (found.results_size() == 0 || found.results(0).clip_id() != ids[raise.clip] ||
            found.results(0).score() > 1e-3) {
          failures[t].push_back("the query did not find itself first");
        }
        if (found.counts().library_frames() < library_frames) {
          failures[t].push_back("the library shrank");
        }
        library_frames = found.counts().library_frames();
      }
    });
  }
  for (int i = 0; i < 6; ++i) {
    client.IngestOrFail("extra_" + std::to_string(i) + ".bvh",
                        BvhText(Humanoid().clips[i % Humanoid().clips.size()]));
  }
  ingesting = false;
  for (std::thread& thread : searchers) thread.join();
  for (const auto& failed : failures) EXPECT_THAT(failed, ::testing::IsEmpty());
  EXPECT_GE(searches.load(), 20);

  v1::SearchResponse final_answer;
  ASSERT_TRUE(client.Search(query, &final_answer).ok());
  v1::GetSpaceRequest get;
  get.set_name("body");
  v1::Space space;
  ASSERT_TRUE(client.spaces().GetSpace(client.Context().get(), get, &space).ok());
  EXPECT_EQ(space.index().clips(), static_cast<int64_t>(ids.size()) + 6);
  EXPECT_EQ(final_answer.counts().library_frames(), space.index().frames());
  EXPECT_GT(final_answer.counts().library_frames(), baseline.counts().library_frames());
}

TEST_F(ServerTest, DeadlineStopsALongExactSearch) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  // A longer library: the whole thesis script, about five minutes at 50 fps.
  SyntheticCorpusOptions options;
  options.seed = 3;
  options.threads = 2;
  options.max_clip_duration_s = 60;
  absl::StatusOr<SyntheticCorpus> library = GenerateSyntheticCorpus(options);
  ASSERT_TRUE(library.ok()) << library.status();
  std::vector<int64_t> ids;
  for (size_t i = 0; i < library->clips.size(); ++i) {
    ids.push_back(
        client.IngestOrFail("long_" + std::to_string(i) + ".bvh", BvhText(library->clips[i])));
  }
  CreateHumanoidSpace(client);
  // A long query with every dimension in the warp makes the exhaustive search slow.
  v1::SearchRequest query = ClipQuery("body", ids[0], 0, library->clips[0].frame_count() / 2);
  query.set_exact(true);
  query.set_dtw_dims(64);
  query.set_slope_limit(4);
  const auto start = std::chrono::steady_clock::now();
  v1::SearchResponse found;
  grpc::Status status = client.Search(query, &found);
  const double full_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(status.ok()) << status.error_message();
  std::cerr << "exact search without a deadline: " << full_ms << " ms\n";

  const auto deadline = std::chrono::milliseconds(static_cast<int>(std::max(20.0, full_ms / 5)));
  const auto start_late = std::chrono::steady_clock::now();
  status = client.Search(query, &found, deadline);
  const double late_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_late)
          .count();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  // The server stops working too: its log line for the call says DEADLINE_EXCEEDED, or
  // CANCELLED when the client's deadline fired first (the server's deadline is the client's
  // timeout from the call's arrival, a little later) and its cancel reached the server before its
  // own deadline passed, as happens under load; a search that ran to its end would be logged OK.
  // The times are printed, not compared: under load they say nothing.
  std::smatch line;
  const std::regex logged(
      "/motiondb.v1.SearchService/Search (?:DEADLINE_EXCEEDED|CANCELLED) ([0-9.]+)ms");
  std::string log;
  for (int i = 0; i < 1500 && !std::regex_search(log, line, logged); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    log = server->Log();
  }
  ASSERT_TRUE(std::regex_search(log, line, logged)) << log;
  const double server_ms = std::stod(line[1]);
  // The next call's line is looked for after this one's, which may say CANCELLED too.
  const size_t deadline_line_end = static_cast<size_t>(line.position(0) + line.length(0));
  std::cerr << "with a " << deadline.count() << " ms deadline: the client waited " << late_ms
            << " ms, the server worked " << server_ms << " ms\n";

  // A client that cancels: the server stops too, and logs CANCELLED.
  auto context = client.Context();
  std::thread canceller([&] {
    std::this_thread::sleep_for(deadline);
    context->TryCancel();
  });
  status = client.search().Search(context.get(), query, &found);
  canceller.join();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::CANCELLED);
  const std::regex cancelled("/motiondb.v1.SearchService/Search CANCELLED ([0-9.]+)ms");
  std::string later = log.substr(deadline_line_end);
  for (int i = 0; i < 1500 && !std::regex_search(later, line, cancelled); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    later = server->Log().substr(deadline_line_end);
  }
  ASSERT_TRUE(std::regex_search(later, line, cancelled)) << server->Log();
  std::cerr << "cancelled after " << deadline.count() << " ms: the server worked " << line[1]
            << " ms\n";
}

// The server's log once it holds `count` lines of `method` (waiting up to 30 s for a call that
// outlives its client's deadline).
std::string LogWithCalls(const ServerProcess& server, const std::string& method, int count) {
  std::string log;
  for (int i = 0; i < 1500; ++i) {
    log = server.Log();
    int found = 0;
    for (size_t at = log.find(method + " "); at != std::string::npos;
         at = log.find(method + " ", at + 1)) {
      ++found;
    }
    if (found >= count) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return log;
}

int64_t ClipCount(Client& client) {
  v1::ListClipsResponse page;
  const grpc::Status status =
      client.clips().ListClips(client.Context().get(), v1::ListClipsRequest(), &page);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return page.clips_size();
}

// A write whose call ends before it commits is rolled back; it used to be stored, so that a
// client told DEADLINE_EXCEEDED retried into ALREADY_EXISTS.
TEST_F(ServerTest, WritesPastTheirDeadlineAreRolledBack) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  // 20'000 frames (2.6 MB): parsing alone outlasts a 1 ms deadline.
  const std::string bvh = BvhText(testing::MakeClip(
      testing::ChainSkeleton(), 20'000, 1.0 / 30,
      [](int f, int j) {
        return Quat(Eigen::AngleAxisd(0.01 * f * (j + 1), Eigen::Vector3d::UnitY()));
      },
      [](int f, int) { return Eigen::Vector3d(0.1 * f, 90, 0); }));
  v1::IngestClipRequest request;
  request.set_file_name("long.bvh");
  request.set_bvh(bvh);
  constexpr int kAttempts = 3;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    v1::IngestClipResponse response;
    const grpc::Status status = client.clips().IngestClip(
        client.Context(std::chrono::milliseconds(1)).get(), request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED) << status.error_message();
  }
  // Some of these reach their handler (which then parses for about 20 ms and rolls back), some
  // end in transfer; which ones is not known here, so there is nothing to wait for but the
  // stream below, which takes 1.5 s. A late commit could only make the test pass wrongly.

  // A stream whose client stops before its last chunk, the file whole so far: the deadline ends
  // the stream, which must not be taken for the end of the file.
  auto context = client.Context(std::chrono::milliseconds(1000));
  v1::IngestClipResponse streamed;
  auto writer = client.clips().IngestClipStream(context.get(), &streamed);
  v1::IngestClipStreamRequest whole;
  whole.set_file_name("cut.bvh");
  whole.set_chunk(bvh);
  ASSERT_TRUE(writer->Write(whole));
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  EXPECT_EQ(writer->Finish().error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  // The server may see the client's cancellation (sent when the client's timer fires) before
  // its own deadline passes: CANCELLED or DEADLINE_EXCEEDED.
  const std::string log = LogWithCalls(*server, "/motiondb.v1.ClipService/IngestClipStream", 1);
  EXPECT_THAT(log, ::testing::ContainsRegex(
                       "/motiondb.v1.ClipService/IngestClipStream (CANCELLED|DEADLINE_EXCEEDED)"));

  EXPECT_EQ(ClipCount(client), 0) << log;
  // The retry a client makes stores the clip, as new.
  v1::IngestClipResponse stored;
  ASSERT_TRUE(client.clips().IngestClip(client.Context().get(), request, &stored).ok());
  EXPECT_EQ(stored.result(), v1::INGEST_RESULT_STORED);
  EXPECT_EQ(ClipCount(client), 1);
}

// A backup taken while a client ingests: the copy passes integrity_check, holds every clip
// acknowledged before the backup began, and a server started on it serves the same searches.
TEST_F(ServerTest, BackupWhileIngestingServesTheSameSearches) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::vector<int64_t> ids = IngestHumanoid(client);
  CreateHumanoidSpace(client);
  const SyntheticSegment& raise = FirstRaise();
  const v1::SearchRequest query =
      ClipQuery("body", ids[raise.clip], raise.first_frame, raise.last_frame);
  v1::SearchResponse live;
  ASSERT_TRUE(client.Search(query, &live).ok());

  std::atomic<int64_t> acknowledged = static_cast<int64_t>(ids.size());
  std::atomic<bool> stop = false;
  std::thread ingester([&] {
    Client own(testing::InsecureChannel(server->address()));
    for (int i = 0; !stop; ++i) {
      v1::IngestClipResponse response;
      if (own.Ingest("chain_" + std::to_string(i) + ".bvh", BvhText(ChainClip(0.01 * (i + 1))),
                     &response)
              .ok()) {
        ++acknowledged;
      }
    }
  });
  while (acknowledged < static_cast<int64_t>(ids.size()) + 5) std::this_thread::yield();
  const int64_t before = acknowledged;
  const std::string copy = (dir_ / "copy.sqlite").string();
  {
    auto context = client.Context();
    auto reader = client.server().CreateBackup(context.get(), v1::CreateBackupRequest());
    std::ofstream file(copy, std::ios::binary);
    v1::BackupChunk chunk;
    int64_t total = -1, received = 0;
    while (reader->Read(&chunk)) {
      if (total < 0) {
        total = chunk.total_bytes();
        EXPECT_GE(chunk.counts().clips(), before);
      }
      file << chunk.data();
      received += static_cast<int64_t>(chunk.data().size());
    }
    const grpc::Status status = reader->Finish();
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(received, total);
  }
  stop = true;
  ingester.join();
  // Nothing is left beside the live database.
  for (const auto& entry : std::filesystem::directory_iterator(dir_)) {
    EXPECT_THAT(entry.path().filename().string(), ::testing::Not(HasSubstr("backup"))) << entry;
  }

  ServerProcess* restored = StartServer({"--db", copy});
  ASSERT_NE(restored, nullptr);
  Client copy_client(testing::InsecureChannel(restored->address()));
  v1::ListClipsRequest all;
  all.set_page_size(1000);
  v1::ListClipsResponse page;
  ASSERT_TRUE(copy_client.clips().ListClips(copy_client.Context().get(), all, &page).ok());
  EXPECT_GE(page.clips_size(), before);
  v1::SearchResponse restored_found;
  ASSERT_TRUE(copy_client.Search(query, &restored_found).ok());
  ASSERT_EQ(restored_found.results_size(), live.results_size());
  for (int i = 0; i < live.results_size(); ++i) {
    EXPECT_EQ(restored_found.results(i).clip_id(), live.results(i).clip_id());
    EXPECT_EQ(restored_found.results(i).start_frame(), live.results(i).start_frame());
    EXPECT_EQ(restored_found.results(i).score(), live.results(i).score());
  }
  restored->Stop(SIGTERM);
  std::unique_ptr<storage::SqliteConnection> raw =
      *storage::SqliteConnection::Open(copy, storage::SqliteConnection::Mode::kReadOnly, 1000);
  EXPECT_EQ(*raw->QueryText("PRAGMA integrity_check"), "ok");
}

}  // namespace
}  // namespace motiondb
