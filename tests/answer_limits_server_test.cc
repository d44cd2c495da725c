// Issue 37's answer limit through the real motiondb-server, on each face: with --max-answer-mb 1
// a clip whose BVH is larger than the limit is refused by the unary export and exports whole
// by the stream, over gRPC, HTTP (chunked) and the CLI, each the stored clip's WriteBvh text;
// the probe's Blend (2 poses, 40 path points, 10000 frames a segment: a 2.3 GB answer that
// aborted the server) is refused at the default limit and the server lives; a batch's searches
// share the limit; label timelines come in pages; the HTTP face refuses JSON past the limit.
// answer_limits_test.cc checks each operation's limit in process.
#include <csignal>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <google/protobuf/util/json_util.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "core/bvh/bvh_writer.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "motiondb/v1/edit_service.grpc.pb.h"
#include "motiondb/v1/label_service.grpc.pb.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "motiondb/v1/server_service.grpc.pb.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "storage/database.h"
#include "testing/server_process.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"

// Last: httplib.h includes <resolv.h>, whose _res macro breaks the Eigen headers above.
#include <httplib.h>

namespace motiondb {
namespace {

namespace v1 = ::motiondb::v1;
using ::testing::HasSubstr;

constexpr int64_t kMiB = int64_t{1} << 20;
constexpr int kLongFrames = 6000;  // at 60 fps: its BVH is about 4 MiB, its poses 1.3 MiB

std::unique_ptr<grpc::ClientContext> Context() {
  auto context = std::make_unique<grpc::ClientContext>();
  context->set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
  return context;
}

std::string Bvh(const Clip& clip) {
  absl::StatusOr<std::string> text = WriteBvh(clip);
  EXPECT_TRUE(text.ok()) << text.status();
  return text.value_or("");
}

class AnswerLimitServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir("answer_limits_server_test");
    db_ = (dir_ / "db.sqlite").string();
  }
  void TearDown() override {
    if (HasFailure() && server_) std::cerr << "---- server log ----\n" << server_->Log() << "\n";
    server_.reset();
    std::filesystem::remove_all(dir_);
  }

  // A server on the test's database with `args`; its channel and stubs.
  void Start(std::vector<std::string> args) {
    server_.reset();
    args.insert(args.begin(), {"--db", db_});
    server_ = std::make_unique<testing::ServerProcess>();
    std::string error;
    ASSERT_TRUE(server_->Start(args, &error)) << error;
    channel_ = testing::InsecureChannel(server_->address());
    ASSERT_TRUE(testing::WaitUntilServing(channel_, ""));
    clips_ = v1::ClipService::NewStub(channel_);
  }

  // Two takes of the humanoid at 60 fps, the first `first_frames` long, the second 300, and the
  // space "body".
  void LoadLibrary(int first_frames = kLongFrames) {
    const auto skeleton = testing::HumanoidSkeleton(/*still_root=*/false);
    for (const int frames : {first_frames, 300}) {
      v1::IngestClipRequest request;
      request.set_file_name(absl::StrCat("take", ids_.size(), ".bvh"));
      request.set_bvh(Bvh(testing::SyntheticClip(
          skeleton, {.frames = frames, .fps = 60, .seed = static_cast<int>(ids_.size()) + 1})));
      v1::IngestClipResponse response;
      const grpc::Status status = clips_->IngestClip(Context().get(), request, &response);
      ASSERT_TRUE(status.ok()) << status.error_message();
      ids_.push_back(response.clip().clip_id());
    }
    v1::CreateSpaceRequest space;
    space.set_name("body");
    v1::Space created;
    const grpc::Status status =
        v1::SpaceService::NewStub(channel_)->CreateSpace(Context().get(), space, &created);
    ASSERT_TRUE(status.ok()) << status.error_message();
  }

  // The stored clip's WriteBvh text, read from the database once the server has stopped.
  std::string StoredBvh(int64_t clip_id, std::optional<FrameRange> range = std::nullopt) {
    auto database = storage::Database::Open(db_);
    EXPECT_TRUE(database.ok()) << database.status();
    if (!database.ok()) return "";
    const absl::StatusOr<storage::StoredClip> stored = (*database)->GetClip(clip_id);
    EXPECT_TRUE(stored.ok()) << stored.status();
    if (!stored.ok()) return "";
    const absl::StatusOr<std::string> text = WriteBvh(stored->clip, range);
    EXPECT_TRUE(text.ok());
    return text.value_or("");
  }

  // SIGTERM, the exit code; the test's channel closed first (a server stopping waits about 5 s
  // for a client's idle connection).
  int Stop() {
    clips_.reset();
    channel_.reset();
    return server_->Stop(SIGTERM);
  }

  httplib::Client Http() {
    httplib::Client client("127.0.0.1", server_->http_port());
    client.set_read_timeout(60);
    return client;
  }

  std::filesystem::path dir_;
  std::string db_;
  std::unique_ptr<testing::ServerProcess> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::ClipService::Stub> clips_;
  std::vector<int64_t> ids_;
};

TEST_F(AnswerLimitServerTest, AClipPastTheLimitExportsWholeByTheStreamOnEveryFace) {
  ASSERT_NO_FATAL_FAILURE(Start({"--max-answer-mb", "1"}));
  ASSERT_NO_FATAL_FAILURE(LoadLibrary());
  const int64_t id = ids_[0];
  v1::ServerInfo info;
  ASSERT_TRUE(v1::ServerService::NewStub(channel_)->GetServerInfo(Context().get(), {}, &info).ok());
  EXPECT_EQ(info.max_answer_bytes(), kMiB);

  // Unary: refused, naming the limit, its flag and the stream.
  v1::ExportClipRequest request;
  request.mutable_clip()->set_clip_id(id);
  v1::ExportClipResponse unary;
  const grpc::Status refused = clips_->ExportClip(Context().get(), request, &unary);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(refused.error_message(), HasSubstr("answer limit of 1.0 MiB (--max-answer-mb)"));
  EXPECT_THAT(refused.error_message(), HasSubstr("ExportClipStream"));

  // gRPC: the stream's pieces, each far below the limit, the first with the file's name.
  std::string grpc_text;
  int pieces = 0;
  {
    auto context = Context();
    auto reader = clips_->ExportClipStream(context.get(), request);
    v1::ExportClipResponse piece;
    while (reader->Read(&piece)) {
      if (pieces++ == 0) {
        EXPECT_EQ(piece.file_name(), "take0.bvh");
        EXPECT_EQ(piece.last_frame(), kLongFrames - 1);
      }
      EXPECT_LE(static_cast<int64_t>(piece.ByteSizeLong()), kMiB + 1024);
      grpc_text += piece.bvh();
    }
    const grpc::Status status = reader->Finish();
    ASSERT_TRUE(status.ok()) << status.error_message();
  }
  EXPECT_GT(static_cast<int64_t>(grpc_text.size()), kMiB);
  EXPECT_GE(pieces, 3);
  // Errors come before any piece, as the unary export's.
  request.mutable_clip()->set_last_frame(kLongFrames);
  {
    auto context = Context();
    auto reader = clips_->ExportClipStream(context.get(), request);
    v1::ExportClipResponse piece;
    EXPECT_FALSE(reader->Read(&piece));
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  }

  // HTTP: chunked, the whole file, and a range; errors as JSON.
  httplib::Client http = Http();
  const httplib::Result whole = http.Get(absl::StrCat("/v1/clips/", id, "/bvh").c_str());
  ASSERT_TRUE(whole);
  EXPECT_EQ(whole->status, 200);
  EXPECT_EQ(whole->get_header_value("Transfer-Encoding"), "chunked");
  EXPECT_THAT(whole->get_header_value("Content-Disposition"), HasSubstr("filename=\"take0.bvh\""));
  const httplib::Result range =
      http.Get(absl::StrCat("/v1/clips/", id, "/bvh?from=100&to=1999").c_str());
  ASSERT_TRUE(range);
  EXPECT_EQ(range->status, 200);
  const httplib::Result missing = http.Get("/v1/clips/4242/bvh");
  ASSERT_TRUE(missing);
  EXPECT_EQ(missing->status, 404);
  EXPECT_THAT(missing->body, HasSubstr("\"code\":5"));
  const httplib::Result outside =
      http.Get(absl::StrCat("/v1/clips/", id, "/bvh?to=", kLongFrames).c_str());
  ASSERT_TRUE(outside);
  EXPECT_EQ(outside->status, 400);

  // The CLI: the stream written into the file, renamed into place once whole.
  const std::string out = (dir_ / "exported.bvh").string();
  const testing::CommandResult cli = testing::RunCli(
      {"--server", server_->address(), "export", std::to_string(id), "-o", out, "--json"});
  EXPECT_EQ(cli.exit_code, 0) << cli.err;
  EXPECT_THAT(cli.out, HasSubstr(absl::StrCat("\"last_frame\":", kLongFrames - 1)));
  EXPECT_FALSE(std::filesystem::exists(out + ".tmp"));
  // A range outside the clip: the CLI's words for the field, and no file.
  const std::string bad = (dir_ / "bad.bvh").string();
  const testing::CommandResult refused_cli =
      testing::RunCli({"--server", server_->address(), "export", std::to_string(id), "--to",
                       std::to_string(kLongFrames), "-o", bad});
  EXPECT_NE(refused_cli.exit_code, 0);
  EXPECT_THAT(refused_cli.err, HasSubstr("--to"));
  EXPECT_FALSE(std::filesystem::exists(bad));
  EXPECT_FALSE(std::filesystem::exists(bad + ".tmp"));

  ASSERT_EQ(Stop(), 0);
  const std::string expected = StoredBvh(id);
  EXPECT_EQ(grpc_text, expected);
  EXPECT_EQ(whole->body, expected);
  EXPECT_EQ(range->body, StoredBvh(id, FrameRange{100, 1999}));
  EXPECT_EQ(testing::ReadFileOrDie(out), expected);
}

TEST_F(AnswerLimitServerTest, TheProbesBlendIsRefusedAndTheServerLives) {
  ASSERT_NO_FATAL_FAILURE(Start({}));  // the default limit, 256 MiB
  ASSERT_NO_FATAL_FAILURE(LoadLibrary(300));
  auto edits = v1::EditService::NewStub(channel_);
  v1::BlendRequest request;
  request.set_space("body");
  for (int i = 0; i < 2; ++i) {
    v1::PlanarPose* pose = request.add_poses();
    pose->mutable_pose()->set_clip_id(ids_[i]);
    pose->mutable_pose()->set_first_frame(10);
    pose->mutable_pose()->set_last_frame(10);
    pose->set_x(i);
  }
  for (int i = 0; i < 40; ++i) {
    v1::PlanePoint* point = request.add_path();
    point->set_x(i % 2);
    point->set_y(i / 40.0);
  }
  request.set_frames_per_segment(10000);
  v1::BlendResponse response;
  grpc::Status status = edits->Blend(Context().get(), request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("answer limit of 256.0 MiB (--max-answer-mb)"));
  EXPECT_THAT(status.error_message(), HasSubstr("frames_per_segment"));
  // The probe's second: a million path points a frame each.
  request.clear_path();
  for (int i = 0; i < 1000000; ++i) request.add_path()->set_x(i % 7);
  request.set_frames_per_segment(1);
  status = edits->Blend(Context().get(), request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  // The server lives, and stores nothing.
  v1::ServerInfo info;
  ASSERT_TRUE(v1::ServerService::NewStub(channel_)->GetServerInfo(Context().get(), {}, &info).ok());
  EXPECT_EQ(info.counts().clips(), 2);
  EXPECT_TRUE(server_->running());
  edits.reset();
  EXPECT_EQ(Stop(), 0);
}

TEST_F(AnswerLimitServerTest, ABatchsSearchesShareTheLimit) {
  ASSERT_NO_FATAL_FAILURE(Start({"--max-answer-mb", "1"}));
  ASSERT_NO_FATAL_FAILURE(LoadLibrary(300));
  v1::SearchBatchRequest batch;
  for (int i = 0; i < 3; ++i) {
    v1::SearchRequest* search = batch.add_requests();
    search->set_space("body");
    search->mutable_clip()->set_clip_id(ids_[1]);
    search->mutable_clip()->set_first_frame(0);
    search->mutable_clip()->set_last_frame(59);
    // About 0.4 MiB each at their longest: two fit, the third does not.
    search->set_max_results(500);
    search->set_return_path(true);
  }
  v1::SearchBatchResponse answer;
  const grpc::Status status =
      v1::SearchService::NewStub(channel_)->SearchBatch(Context().get(), batch, &answer);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(answer.items_size(), 3);
  EXPECT_EQ(answer.items(0).code(), 0) << answer.items(0).message();
  EXPECT_EQ(answer.items(1).code(), 0) << answer.items(1).message();
  EXPECT_EQ(answer.items(2).code(), static_cast<int>(grpc::StatusCode::RESOURCE_EXHAUSTED));
  EXPECT_THAT(answer.items(2).message(), HasSubstr("requests[2]: with the batch's earlier"));
  EXPECT_LE(static_cast<int64_t>(answer.ByteSizeLong()), kMiB);
}

TEST_F(AnswerLimitServerTest, TimelinesComeInPagesAndJsonPastTheLimitIsRefused) {
  ASSERT_NO_FATAL_FAILURE(Start({"--max-answer-mb", "1"}));
  ASSERT_NO_FATAL_FAILURE(LoadLibrary());
  auto labels = v1::LabelService::NewStub(channel_);
  constexpr int kLabels = 1500;
  for (int first = 0; first < kLabels; first += 500) {
    v1::AddLabelsRequest add;
    for (int i = first; i < first + 500; ++i) {
      v1::NewLabel* label = add.add_labels();
      label->set_clip_id(ids_[0]);
      label->set_first_frame(i);
      label->set_last_frame(i + 10);
      label->set_descriptor_name("step");
    }
    v1::AddLabelsResponse added;
    const grpc::Status status = labels->AddLabels(Context().get(), add, &added);
    ASSERT_TRUE(status.ok()) << status.error_message();
  }
  // Pages of at most what 1 MiB holds, in timeline order, together every label once.
  v1::GetClipLabelsRequest request;
  request.set_clip_id(ids_[0]);
  request.set_page_size(1000);
  std::vector<int> firsts;
  int pages = 0;
  do {
    v1::GetClipLabelsResponse page;
    const grpc::Status status = labels->GetClipLabels(Context().get(), request, &page);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_LT(page.labels_size(), 1000);
    for (const v1::Label& label : page.labels()) firsts.push_back(label.first_frame());
    request.set_page_token(page.next_page_token());
    ++pages;
  } while (!request.page_token().empty());
  EXPECT_EQ(pages, 3);
  ASSERT_EQ(static_cast<int>(firsts.size()), kLabels);
  for (int i = 0; i < kLabels; ++i) EXPECT_EQ(firsts[i], i);
  // By default a page of 100.
  v1::GetClipLabelsRequest first_page;
  first_page.set_clip_id(ids_[0]);
  v1::GetClipLabelsResponse page;
  ASSERT_TRUE(labels->GetClipLabels(Context().get(), first_page, &page).ok());
  EXPECT_EQ(page.labels_size(), 100);
  httplib::Client http = Http();
  const httplib::Result json =
      http.Get(absl::StrCat("/v1/clips/", ids_[0], "/labels?page_size=2").c_str());
  ASSERT_TRUE(json);
  EXPECT_EQ(json->status, 200);
  v1::GetClipLabelsResponse from_json;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(json->body, &from_json).ok());
  EXPECT_EQ(from_json.labels_size(), 2);
  EXPECT_FALSE(from_json.next_page_token().empty());

  // Poses whose encoding fits the limit but whose JSON (base64, a third larger) does not: the
  // gRPC answer, then HTTP's refusal; half as many frames pass both.
  const auto poses_path = [&](int last) {
    return absl::StrCat("/v1/clips/", ids_[0], "/poses?max_rate=0&from=0&to=", last);
  };
  v1::GetClipPosesRequest poses;
  poses.mutable_clip()->set_clip_id(ids_[0]);
  poses.mutable_clip()->set_first_frame(0);
  poses.set_max_rate(0);
  // The last frame of the longest range admitted, by bisection: `admitted` OK, `refused` not.
  int admitted = 0, refused = kLongFrames - 1;
  v1::ClipPoses answer;
  while (refused - admitted > 1) {
    const int last = admitted + (refused - admitted) / 2;
    poses.mutable_clip()->set_last_frame(last);
    const grpc::Status status = clips_->GetClipPoses(Context().get(), poses, &answer);
    ASSERT_TRUE(status.ok() || status.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED)
        << status.error_message();
    if (!status.ok()) {
      EXPECT_THAT(status.error_message(), HasSubstr("max_rate"));
    }
    (status.ok() ? admitted : refused) = last;
  }
  poses.mutable_clip()->set_last_frame(admitted);
  ASSERT_TRUE(clips_->GetClipPoses(Context().get(), poses, &answer).ok());
  EXPECT_LE(static_cast<int64_t>(answer.ByteSizeLong()), kMiB);
  EXPECT_GT(static_cast<int64_t>(answer.ByteSizeLong()), kMiB * 3 / 4);
  const int last = admitted;
  const httplib::Result too_long = http.Get(poses_path(last).c_str());
  ASSERT_TRUE(too_long);
  EXPECT_EQ(too_long->status, 429);
  const std::string refusal = too_long->body.substr(0, 400);  // not a whole answer, if one came
  EXPECT_THAT(refusal, HasSubstr("answer's JSON is longer than"));
  EXPECT_THAT(refusal, HasSubstr("--max-answer-mb"));
  const httplib::Result fits = http.Get(poses_path(last / 2).c_str());
  ASSERT_TRUE(fits);
  EXPECT_EQ(fits->status, 200);
  EXPECT_LE(static_cast<int64_t>(fits->body.size()), kMiB);
}

TEST_F(AnswerLimitServerTest, TheFlagIsChecked) {
  for (const char* value : {"0", "2048"}) {
    testing::ServerProcess server;
    std::string error;
    EXPECT_FALSE(
        server.Start({"--db", db_, "--max-answer-mb", value}, &error, std::chrono::seconds(20)));
    EXPECT_THAT(error, HasSubstr("--max-answer-mb")) << value;
  }
}

}  // namespace
}  // namespace motiondb
