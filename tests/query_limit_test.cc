// The query length limit on the real server (issue 37): a query longer than --max-query-frames
// frames at the space's rate is refused with INVALID_ARGUMENT naming the limit and the flag,
// whichever way it arrives (a stored clip's range, an uploaded BVH, one search of a batch, over
// gRPC and POST /v1/search, which the web page's BVH drop uses); and a call past its deadline
// ends with DEADLINE_EXCEEDED. The limit is lowered by its flag so that the queries stay small.
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "core/bvh/bvh_writer.h"
#include "tests/server_fixture.h"

// Last: httplib.h includes <resolv.h>, whose _res macro breaks the Eigen headers above.
#include <httplib.h>

namespace motiondb {
namespace {

using ::testing::HasSubstr;

// The humanoid's clips run at 50 fps and the space at its default 30 Hz: 200 clip frames are 120
// at the space's rate, 80 are 48.
constexpr int kLimit = 60;
constexpr int kLongFrames = 200;
constexpr int kShortFrames = 80;

class QueryLimitTest : public ServerTest {
 protected:
  // A server at the lowered limit, with the humanoid library and its space.
  testing::ServerProcess* StartLibrary() {
    testing::ServerProcess* server = StartServer({"--max-query-frames", std::to_string(kLimit)});
    if (server == nullptr) return nullptr;
    client_ = std::make_unique<Client>(testing::InsecureChannel(server->address()));
    ids_ = IngestHumanoid(*client_);
    CreateHumanoidSpace(*client_);
    return server;
  }

  // The first clip's frames 0..frames-1 as a BVH file.
  static std::string BvhOfFrames(int frames) {
    const absl::StatusOr<std::string> text =
        WriteBvh(Humanoid().clips.front(), FrameRange{0, frames - 1});
    EXPECT_TRUE(text.ok()) << text.status();
    return text.ok() ? *text : "";
  }

  std::unique_ptr<Client> client_;
  std::vector<int64_t> ids_;
};

void ExpectRefused(const grpc::Status& status, const std::string& field) {
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("--max-query-frames"));
  EXPECT_THAT(status.error_message(), HasSubstr(absl::StrCat(kLimit)));
  EXPECT_THAT(status.error_message(), HasSubstr(field + ": "));
}

TEST_F(QueryLimitTest, RefusesALongerQueryOverGrpc) {
  ASSERT_NE(StartLibrary(), nullptr);
  v1::SearchResponse found;
  ExpectRefused(client_->Search(ClipQuery("body", ids_[0], 0, kLongFrames - 1), &found), "clip");
  const grpc::Status within =
      client_->Search(ClipQuery("body", ids_[0], 0, kShortFrames - 1), &found);
  EXPECT_TRUE(within.ok()) << within.error_message();
  EXPECT_GT(found.results_size(), 0);

  v1::SearchRequest uploaded;
  uploaded.set_space("body");
  uploaded.mutable_bvh()->set_bvh(BvhOfFrames(kLongFrames));
  ExpectRefused(client_->Search(uploaded, &found), "bvh");
  uploaded.mutable_bvh()->set_bvh(BvhOfFrames(kShortFrames));
  const grpc::Status short_upload = client_->Search(uploaded, &found);
  EXPECT_TRUE(short_upload.ok()) << short_upload.error_message();

  // In a batch the long search fails alone.
  v1::SearchBatchRequest batch;
  *batch.add_requests() = ClipQuery("body", ids_[0], 0, kLongFrames - 1);
  *batch.add_requests() = ClipQuery("body", ids_[0], 0, kShortFrames - 1);
  v1::SearchBatchResponse answers;
  const grpc::Status status =
      client_->search().SearchBatch(client_->Context().get(), batch, &answers);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(answers.items_size(), 2);
  EXPECT_EQ(answers.items(0).code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(answers.items(0).message(), HasSubstr("--max-query-frames"));
  EXPECT_EQ(answers.items(1).code(), 0) << answers.items(1).message();
}

// POST /v1/search is how the web page searches, a dropped BVH file included.
TEST_F(QueryLimitTest, RefusesALongerQueryOverHttp) {
  testing::ServerProcess* server = StartLibrary();
  ASSERT_NE(server, nullptr);
  httplib::Client http("127.0.0.1", server->http_port());
  http.set_read_timeout(60);
  const auto search = [&](const std::string& query) {
    const httplib::Result result = http.Post(
        "/v1/search", absl::StrCat(R"({"space":"body",)", query, "}"), "application/json");
    EXPECT_TRUE(result) << httplib::to_string(result.error());
    return result ? std::make_pair(result->status, result->body) : std::make_pair(0, "");
  };
  const auto range = [&](int frames) {
    return absl::StrCat(R"("clip":{"clip_id":")", ids_[0], R"(","first_frame":0,"last_frame":)",
                        frames - 1, "}");
  };
  const auto file = [&](int frames) {
    return absl::StrCat(R"("bvh":{"bvh":")", absl::Base64Escape(BvhOfFrames(frames)), R"("})");
  };
  for (const auto& [refused, field] :
       {std::pair{range(kLongFrames), "clip"}, std::pair{file(kLongFrames), "bvh"}}) {
    const auto [status, body] = search(refused);
    EXPECT_EQ(status, 400) << body;
    EXPECT_THAT(body, HasSubstr("--max-query-frames"));
    EXPECT_THAT(body, HasSubstr(absl::StrCat(field, ": ")));
  }
  for (const std::string& admitted : {range(kShortFrames), file(kShortFrames)}) {
    const auto [status, body] = search(admitted);
    EXPECT_EQ(status, 200) << body;
  }
}

// A call whose deadline has passed ends with DEADLINE_EXCEEDED: an HTTP call takes
// --http-timeout-s as its deadline, here passed before the uploaded query is parsed.
TEST_F(QueryLimitTest, ACallPastItsDeadlineIsDeadlineExceeded) {
  testing::ServerProcess* server = StartServer({"--http-timeout-s", "0.000001"});
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  IngestHumanoid(client);
  CreateHumanoidSpace(client);
  httplib::Client http("127.0.0.1", server->http_port());
  http.set_read_timeout(60);
  const httplib::Result result =
      http.Post("/v1/search",
                absl::StrCat(R"({"space":"body","bvh":{"bvh":")",
                             absl::Base64Escape(BvhOfFrames(500)), R"("}})"),
                "application/json");
  ASSERT_TRUE(result) << httplib::to_string(result.error());
  EXPECT_EQ(result->status, 504) << result->body;
  google::protobuf::Struct error;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(result->body, &error).ok());
  EXPECT_EQ(error.fields().at("code").number_value(),
            static_cast<double>(grpc::StatusCode::DEADLINE_EXCEEDED))
      << result->body;
}

}  // namespace
}  // namespace motiondb
