// The fixture of the server's integration tests (server_*_test.cc, server_fault_test.cc and
// others): a synthetic library, a client of one server over the generated stubs, a temporary
// folder whose database the real motiondb-server binary is started on, and the helpers of labels,
// searches and propagation jobs that more than one of those files uses.
#ifndef MOTIONDB_TESTS_SERVER_FIXTURE_H_
#define MOTIONDB_TESTS_SERVER_FIXTURE_H_

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include "core/motion/clip.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "motiondb/v1/job_service.grpc.pb.h"
#include "motiondb/v1/label_service.grpc.pb.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "motiondb/v1/server_service.grpc.pb.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "testing/server_process.h"
#include "testing/synthetic_corpus.h"
#include "tests/test_data.h"

namespace motiondb {

namespace v1 = ::motiondb::v1;

// A small library of the synthetic humanoid (21 joints) with arm raises and shrugs at 50 fps,
// in clips of about 20 s; generated once.
const testing::SyntheticCorpus& Humanoid();
// The first right-arm raise of the humanoid library: its clip index and frames (50 fps).
const testing::SyntheticSegment& FirstRaise();

std::string BvhText(const Clip& clip);
// A 3-joint chain (another skeleton than the humanoid's) turning slowly, 61 frames at 30 fps.
Clip ChainClip(double speed = 0.02);

// A stored range as the query. These tests check that a search finds its own query first,
// so the query's range is kept (exclude_query defaults to true).
v1::SearchRequest ClipQuery(const std::string& space, int64_t clip_id, int first, int last);

// ---------------------------------------------------------------------------------------------
// A client of one server.

class Client {
 public:
  explicit Client(std::shared_ptr<grpc::Channel> channel, std::string token = "")
      : channel_(std::move(channel)),
        token_(std::move(token)),
        clips_(v1::ClipService::NewStub(channel_)),
        spaces_(v1::SpaceService::NewStub(channel_)),
        search_(v1::SearchService::NewStub(channel_)),
        server_(v1::ServerService::NewStub(channel_)),
        labels_(v1::LabelService::NewStub(channel_)),
        jobs_(v1::JobService::NewStub(channel_)) {}

  // A call context carrying the token and a deadline (generous by default: a test that hangs
  // should fail, not stall the suite).
  std::unique_ptr<grpc::ClientContext> Context(
      std::chrono::milliseconds deadline = std::chrono::milliseconds(30000)) const {
    auto context = std::make_unique<grpc::ClientContext>();
    context->set_deadline(std::chrono::system_clock::now() + deadline);
    if (!token_.empty()) context->AddMetadata("authorization", "Bearer " + token_);
    return context;
  }

  grpc::Status Ingest(const std::string& file_name, const std::string& bvh,
                      v1::IngestClipResponse* response, std::vector<std::string> tags = {}) {
    v1::IngestClipRequest request;
    request.set_file_name(file_name);
    request.set_bvh(bvh);
    for (const std::string& tag : tags) request.add_tags(tag);
    return clips_->IngestClip(Context().get(), request, response);
  }
  // The new clip's id, or -1 after a failed expectation.
  int64_t IngestOrFail(const std::string& file_name, const std::string& bvh,
                       std::vector<std::string> tags = {}) {
    v1::IngestClipResponse response;
    const grpc::Status status = Ingest(file_name, bvh, &response, std::move(tags));
    EXPECT_TRUE(status.ok()) << file_name << ": " << status.error_message();
    return status.ok() ? response.clip().clip_id() : -1;
  }

  grpc::Status CreateSpace(const v1::CreateSpaceRequest& request, v1::Space* space) {
    return spaces_->CreateSpace(Context().get(), request, space);
  }
  grpc::Status Search(const v1::SearchRequest& request, v1::SearchResponse* response,
                      std::chrono::milliseconds deadline = std::chrono::milliseconds(30000)) {
    return search_->Search(Context(deadline).get(), request, response);
  }

  v1::ClipService::Stub& clips() { return *clips_; }
  v1::SpaceService::Stub& spaces() { return *spaces_; }
  v1::SearchService::Stub& search() { return *search_; }
  v1::ServerService::Stub& server() { return *server_; }
  v1::LabelService::Stub& labels() { return *labels_; }
  v1::JobService::Stub& jobs() { return *jobs_; }
  const std::shared_ptr<grpc::Channel>& channel() const { return channel_; }

 private:
  std::shared_ptr<grpc::Channel> channel_;
  std::string token_;
  std::unique_ptr<v1::ClipService::Stub> clips_;
  std::unique_ptr<v1::SpaceService::Stub> spaces_;
  std::unique_ptr<v1::SearchService::Stub> search_;
  std::unique_ptr<v1::ServerService::Stub> server_;
  std::unique_ptr<v1::LabelService::Stub> labels_;
  std::unique_ptr<v1::JobService::Stub> jobs_;
};

// ---------------------------------------------------------------------------------------------
// Fixture: a temporary folder with the database; servers started on it.

class ServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir("server_test");
    db_ = (dir_ / "motiondb.sqlite").string();
  }
  void TearDown() override {
    StopServers();
    std::filesystem::remove_all(dir_);
  }

  // Kills the servers still running, after printing their logs when the test failed.
  void StopServers() {
    if (HasFailure()) {
      for (const auto& server : servers_) {
        std::cerr << "---- server log ----\n" << server->Log() << "--------------------\n";
      }
    }
    servers_.clear();
  }

  // Starts a server with `args`, on the test's database unless they give --db; null after a
  // failed assertion.
  testing::ServerProcess* StartServer(std::vector<std::string> args = {},
                                      const std::string& token = "", bool tls = false) {
    if (std::find(args.begin(), args.end(), "--db") == args.end()) {
      args.insert(args.begin(), {"--db", db_});
    }
    auto server = std::make_unique<testing::ServerProcess>();
    std::string error;
    if (!server->Start(args, &error)) {
      ADD_FAILURE() << error;
      return nullptr;
    }
    if (!tls && !testing::WaitUntilServing(testing::InsecureChannel(server->address()), token)) {
      ADD_FAILURE() << "the server never reported SERVING:\n" << server->Log();
      return nullptr;
    }
    servers_.push_back(std::move(server));
    return servers_.back().get();
  }

  std::string WriteFile(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  // Ingests the synthetic humanoid library ("humanoid_0".. with tags "synthetic" and "clip<i>");
  // returns the clip ids.
  std::vector<int64_t> IngestHumanoid(Client& client) {
    std::vector<int64_t> ids;
    const testing::SyntheticCorpus& library = Humanoid();
    for (size_t i = 0; i < library.clips.size(); ++i) {
      ids.push_back(client.IngestOrFail("humanoid_" + std::to_string(i) + ".bvh",
                                        BvhText(library.clips[i]),
                                        {"synthetic", "clip" + std::to_string(i)}));
    }
    return ids;
  }

  // Creates the space "body" on every humanoid clip.
  v1::Space CreateHumanoidSpace(Client& client, const std::string& name = "body") {
    v1::CreateSpaceRequest request;
    request.set_name(name);
    v1::Space space;
    const grpc::Status status = client.CreateSpace(request, &space);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return space;
  }

  // Creates the space `name` over the skeleton of clip `clip_id` as a space over several
  // skeletons (canonical bone directions), as one skeleton's.
  v1::Space CreateBonesSpace(Client& client, int64_t clip_id, const std::string& name = "bones") {
    v1::GetClipRequest get;
    get.set_clip_id(clip_id);
    v1::Clip clip;
    EXPECT_TRUE(client.clips().GetClip(client.Context().get(), get, &clip).ok());
    v1::CreateSpaceRequest request;
    request.set_name(name);
    request.add_skeleton_ids(clip.skeleton_id());
    v1::Space space;
    const grpc::Status status = client.CreateSpace(request, &space);
    EXPECT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(space.representation(), "canonical-bones");
    return space;
  }

  std::filesystem::path dir_;
  std::string db_;
  std::vector<std::unique_ptr<testing::ServerProcess>> servers_;
};

// ---------------------------------------------------------------------------------------------
// Labels, searches and propagation jobs (the calls of a test, with failed expectations).

// A manual label on frames `first`..`last` of a clip (both unset: the whole clip).
v1::NewLabel FrameLabel(int64_t clip_id, std::optional<int> first, std::optional<int> last,
                        const std::string& descriptor, std::optional<double> value = 1.0);

// The same results, place and score, in the same order.
void ExpectSameResults(const v1::SearchResponse& after, const v1::SearchResponse& before);

// Adds `labels` (manual); returns them as stored.
std::vector<v1::Label> AddLabelsOrFail(Client& client, const std::vector<v1::NewLabel>& labels);

v1::StartPropagationRequest Propagation(const std::vector<std::string>& descriptors,
                                        int max_results = 8);

// The job as started; an empty job after a failed expectation.
v1::Job StartOrFail(Client& client, const v1::StartPropagationRequest& request);

bool Ended(const v1::Job& job);

// Polls the job until `done(job)` (the job then) or 120 s (a failed expectation).
v1::Job PollJob(Client& client, const std::string& job_id,
                const std::function<bool(const v1::Job&)>& done = Ended);

// Every propagated label, in id order.
std::vector<v1::Label> Propagated(Client& client);

// Many manual labels of "long" over the humanoid library, so that a job runs for a while.
std::vector<v1::Label> LabelManyRanges(Client& client, const std::vector<int64_t>& ids, int count);

}  // namespace motiondb

#endif  // MOTIONDB_TESTS_SERVER_FIXTURE_H_
