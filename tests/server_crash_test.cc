// Crash safety of the real server binary (server_fixture.h): SIGKILL at random points of ingest,
// space creation and propagation jobs (scripts/crash-loop.sh runs more rounds).
#include <signal.h>
#include <atomic>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <map>
#include <random>
#include <set>
#include <thread>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "core/bvh/bvh_reader.h"
#include "storage/sqlite_connection.h"
#include "testing/server_process.h"
#include "tests/server_fixture.h"

namespace motiondb {
namespace {

using testing::ServerProcess;

// Rounds of the crash loop: MOTIONDB_CRASH_ROUNDS (scripts/crash-loop.sh runs 20), default 3;
// its random kill points come from MOTIONDB_CRASH_SEED (default 1).
int EnvInt(const char* name, int default_value) {
  const char* value = std::getenv(name);
  return value != nullptr ? std::atoi(value) : default_value;
}

// What the client of an ingest loop saw when the server was killed under it.
struct CutIngest {
  std::map<std::string, int> acknowledged;  // frames of each clip answered OK, by name
  std::string in_flight;                    // the clip sent when the answer failed
  int in_flight_frames = 0;
  bool failed_early = false;  // an ingest failed before the kill
};

// Ingests humanoid clips ("<prefix>_<i>", single messages and chunked streams alternately) until
// a call fails, while the server is killed after `delay` past the second acknowledged clip.
CutIngest IngestUntilKilled(ServerProcess& server, const std::string& prefix,
                            std::chrono::milliseconds delay) {
  std::vector<std::string> texts;
  for (const Clip& clip : Humanoid().clips) texts.push_back(BvhText(clip));
  CutIngest cut;
  std::atomic<int> acknowledged{0};
  std::atomic<bool> stopped{false};
  std::thread ingester([&] {
    Client own(testing::InsecureChannel(server.address()));
    for (int i = 0;; ++i) {
      const size_t source = i % texts.size();
      const std::string name = prefix + "_" + std::to_string(i);
      cut.in_flight = name;
      cut.in_flight_frames = Humanoid().clips[source].frame_count();
      v1::IngestClipResponse response;
      grpc::Status status;
      if (i % 2 == 0) {
        status = own.Ingest(name + ".bvh", texts[source], &response);
      } else {
        auto context = own.Context();
        auto writer = own.clips().IngestClipStream(context.get(), &response);
        v1::IngestClipStreamRequest header;
        header.set_file_name(name + ".bvh");
        bool written = writer->Write(header);
        for (size_t at = 0; written && at < texts[source].size(); at += 16384) {
          v1::IngestClipStreamRequest chunk;
          chunk.set_chunk(texts[source].substr(at, 16384));
          written = writer->Write(chunk);
        }
        if (written) writer->WritesDone();
        status = writer->Finish();
      }
      if (!status.ok()) {  // the server is gone (or, before the kill, a failure)
        stopped = true;
        return;
      }
      cut.acknowledged[name] = response.clip().frame_count();
      ++acknowledged;
    }
  });
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (acknowledged < 2 && !stopped && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::this_thread::sleep_for(delay);
  cut.failed_early = stopped;
  EXPECT_EQ(server.Stop(SIGKILL), 128 + SIGKILL);
  ingester.join();
  return cut;
}

// Kills the server `delay` after a call to `operation` started on its own thread.
void KillDuring(ServerProcess& server, std::chrono::milliseconds delay,
                const std::function<void(Client&)>& operation) {
  std::thread caller([&] {
    Client own(testing::InsecureChannel(server.address()));
    operation(own);
  });
  std::this_thread::sleep_for(delay);
  EXPECT_EQ(server.Stop(SIGKILL), 128 + SIGKILL);
  caller.join();
}

// Every propagated label of `job_id`.
std::set<int64_t> LabelsOfJob(const std::vector<v1::Label>& labels, const std::string& job_id) {
  std::set<int64_t> ids;
  for (const v1::Label& label : labels) {
    if (label.job_id() == job_id) ids.insert(label.label_id());
  }
  return ids;
}

// Rounds of: a SIGKILL at a random moment of an ingest loop (single messages and chunked
// streams, each projected into a space), of a space's creation, or of a propagation job; then a
// restart on the same database. It must open (its integrity check passes) and hold every
// acknowledged clip whole, at most the one clip in flight besides (whole), every stored clip in
// the space's index; a space cut off is absent or whole (indexed and searchable); a job cut off
// is interrupted with none of its output, the earlier output kept, or succeeded with its output
// whole.
TEST_F(ServerTest, KillAtRandomPointsLosesNoAcknowledgedWriteAndLeavesNoHalfWrite) {
  const int rounds = EnvInt("MOTIONDB_CRASH_ROUNDS", 3);
  const int seed = EnvInt("MOTIONDB_CRASH_SEED", 1);
  std::mt19937 random(seed);
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  std::map<std::string, int> expected_frames;  // every clip that must be stored, by name
  std::chrono::milliseconds creation_time, job_time;
  std::vector<v1::Label> job_output;  // the propagated labels of the last whole job
  {
    Client client(testing::InsecureChannel(server->address()));
    const std::vector<int64_t> ids = IngestHumanoid(client);
    ASSERT_EQ(ids.size(), Humanoid().clips.size());
    for (size_t i = 0; i < ids.size(); ++i) {
      expected_frames["humanoid_" + std::to_string(i)] = Humanoid().clips[i].frame_count();
    }
    auto started = std::chrono::steady_clock::now();
    CreateHumanoidSpace(client);
    creation_time = std::chrono::duration_cast<std::chrono::milliseconds>(
        std::chrono::steady_clock::now() - started);
    LabelManyRanges(client, ids, 400);
    started = std::chrono::steady_clock::now();
    const v1::Job first = PollJob(client, StartOrFail(client, Propagation({"long"})).job_id());
    ASSERT_EQ(first.state(), v1::JOB_STATE_SUCCEEDED) << first.error();
    job_time = std::chrono::duration_cast<std::chrono::milliseconds>(
        std::chrono::steady_clock::now() - started);
    job_output = Propagated(client);
    ASSERT_FALSE(job_output.empty());
  }
  std::set<std::string> known_spaces = {"body"};  // spaces that must be there
  const std::vector<std::string> kinds = {"ingest", "space creation", "propagation job"};
  for (int round = 0; round < rounds; ++round) {
    const int kind = round % 3;
    // Up to 1.5x the operation's uninterrupted time on the library as it is now (both grow with
    // it), so that some kills come after its end.
    const double growth = static_cast<double>(expected_frames.size()) / Humanoid().clips.size();
    const int window =
        kind == 0
            ? 150
            : static_cast<int>(1.5 * growth *
                               static_cast<double>((kind == 1 ? creation_time : job_time).count()));
    const std::chrono::milliseconds delay(std::uniform_int_distribution<int>(0, window)(random));
    SCOPED_TRACE(absl::StrCat("round ", round, " (seed ", seed, "): kill during ", kinds[kind],
                              " after ", delay.count(), " ms"));
    const std::string space_name = "round_" + std::to_string(round);
    std::string job_id;
    std::string outcome;  // what the round found, for the crash loop's report
    if (kind == 0) {
      CutIngest cut = IngestUntilKilled(*server, "bulk_" + std::to_string(round), delay);
      EXPECT_FALSE(cut.failed_early) << "an ingest failed before the kill";
      outcome = absl::StrCat(cut.acknowledged.size(), " clips acknowledged; the clip in flight ");
      for (const auto& [name, frames] : cut.acknowledged) expected_frames[name] = frames;
      // Only the clip in flight may have been stored besides, and then whole.
      expected_frames.emplace(cut.in_flight, -cut.in_flight_frames);
    } else if (kind == 1) {
      KillDuring(*server, delay, [&](Client& own) {
        v1::CreateSpaceRequest request;
        request.set_name(space_name);
        v1::Space space;
        own.CreateSpace(request, &space);
      });
    } else {
      Client client(testing::InsecureChannel(server->address()));
      job_id = StartOrFail(client, Propagation({"long"})).job_id();
      KillDuring(*server, delay, [](Client&) {});
    }

    server = StartServer();
    ASSERT_NE(server, nullptr);
    Client client(testing::InsecureChannel(server->address()));
    absl::StatusOr<std::unique_ptr<storage::SqliteConnection>> file =
        storage::SqliteConnection::Open(db_, storage::SqliteConnection::Mode::kReadOnly, 1000);
    ASSERT_TRUE(file.ok()) << file.status();
    EXPECT_EQ(*(*file)->QueryText("PRAGMA integrity_check"), "ok");

    v1::ListClipsRequest list;
    list.set_page_size(1000);
    v1::ListClipsResponse stored;
    ASSERT_TRUE(client.clips().ListClips(client.Context().get(), list, &stored).ok());
    std::map<std::string, int> stored_frames;
    for (const v1::Clip& clip : stored.clips()) stored_frames[clip.name()] = clip.frame_count();
    for (auto it = expected_frames.begin(); it != expected_frames.end();) {
      const auto [name, frames] = *it;
      const auto stored_clip = stored_frames.find(name);
      if (frames < 0) {  // the clip in flight: absent, or stored whole
        if (stored_clip == stored_frames.end()) {
          outcome += "absent";
          it = expected_frames.erase(it);
          continue;
        }
        outcome += "stored whole";
        EXPECT_EQ(stored_clip->second, -frames) << name;
        it->second = -frames;
      } else {
        EXPECT_NE(stored_clip, stored_frames.end()) << name << " was acknowledged but is missing";
        if (stored_clip != stored_frames.end()) {
          EXPECT_EQ(stored_clip->second, frames) << name;
        }
      }
      ++it;
    }
    EXPECT_EQ(stored_frames.size(), expected_frames.size());
    // Every stored clip reads back whole and is in the space's index.
    for (const v1::Clip& clip : stored.clips()) {
      v1::ExportClipRequest request;
      request.mutable_clip()->set_clip_id(clip.clip_id());
      v1::ExportClipResponse exported;
      ASSERT_TRUE(client.clips().ExportClip(client.Context().get(), request, &exported).ok());
      absl::StatusOr<BvhReadResult> read = ReadBvh(exported.bvh());
      ASSERT_TRUE(read.ok()) << clip.name() << ": " << read.status();
      EXPECT_EQ(read->clip.frame_count(), clip.frame_count()) << clip.name();
    }
    // Every space (a space cut off while being created is absent or whole) indexes every clip.
    v1::ListSpacesResponse spaces;
    ASSERT_TRUE(
        client.spaces().ListSpaces(client.Context().get(), v1::ListSpacesRequest(), &spaces).ok());
    std::set<std::string> space_names;
    for (const v1::Space& space : spaces.spaces()) space_names.insert(space.name());
    for (const std::string& name : known_spaces) EXPECT_EQ(space_names.count(name), 1u) << name;
    if (space_names.count(space_name) > 0) known_spaces.insert(space_name);
    if (kind == 1) outcome = space_names.count(space_name) > 0 ? "space whole" : "space absent";
    EXPECT_EQ(space_names, known_spaces);
    for (const v1::Space& space : spaces.spaces()) {
      EXPECT_EQ(space.index().clips(), stored.clips_size()) << space.name();
      v1::SearchResponse found;
      ASSERT_TRUE(
          client.Search(ClipQuery(space.name(), stored.clips(0).clip_id(), 0, 40), &found).ok());
      EXPECT_EQ(found.counts().library_frames(), space.index().frames()) << space.name();
      EXPECT_GT(found.results_size(), 0) << space.name();
    }
    if (!job_id.empty()) {
      v1::GetJobRequest get;
      get.set_job_id(job_id);
      v1::Job job;
      ASSERT_TRUE(client.jobs().GetJob(client.Context().get(), get, &job).ok());
      const std::vector<v1::Label> labels = Propagated(client);
      outcome = absl::StrCat("job ", v1::JobState_Name(job.state()), " at ", job.done(), "/",
                             job.total(), " labels, ", labels.size(), " propagated labels");
      if (job.state() == v1::JOB_STATE_SUCCEEDED) {
        EXPECT_EQ(static_cast<int64_t>(LabelsOfJob(labels, job_id).size()), job.labels_written());
        EXPECT_EQ(labels.size(), LabelsOfJob(labels, job_id).size());
        job_output = labels;
      } else {
        EXPECT_EQ(job.state(), v1::JOB_STATE_INTERRUPTED);
        EXPECT_TRUE(LabelsOfJob(labels, job_id).empty());
        ASSERT_EQ(labels.size(), job_output.size());
        for (size_t i = 0; i < labels.size(); ++i) {
          EXPECT_EQ(labels[i].SerializeAsString(), job_output[i].SerializeAsString());
        }
      }
    }
    std::cout << "round " << round << ": SIGKILL " << delay.count() << " ms into " << kinds[kind]
              << " (up to " << window << " ms): " << outcome << std::endl;
    if (HasFailure()) break;
  }
}

}  // namespace
}  // namespace motiondb
