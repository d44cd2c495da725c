// Integration tests of the HTTP face: the real motiondb-server with --http on a free loopback
// port. Every JSON route's answer is parsed into the gRPC response message and compared with
// the same server's gRPC answer; then errors, the token, TLS, the web UI's files, health and
// the Prometheus metrics (checked by promtool when it is installed).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>
#include <tuple>

#include <gmock/gmock.h>
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/text_format.h>
#include <google/protobuf/util/json_util.h>
#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "core/bvh/bvh_writer.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "motiondb/v1/job_service.grpc.pb.h"
#include "motiondb/v1/label_service.grpc.pb.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "motiondb/v1/server_service.grpc.pb.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "testing/server_process.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"

// Last: httplib.h includes <resolv.h>, whose _res macro breaks the Eigen headers above.
#include <httplib.h>

namespace motiondb {
namespace {

namespace v1 = ::motiondb::v1;
using ::testing::HasSubstr;
using testing::ServerProcess;

constexpr char kToken[] = "http-token";

// A proto from an HTTP answer's JSON (a failed expectation when it does not parse).
template <typename Message>
Message FromJson(const std::string& json) {
  Message message;
  const auto status = google::protobuf::util::JsonStringToMessage(json, &message);
  EXPECT_TRUE(status.ok()) << status.ToString() << "\n" << json.substr(0, 500);
  return message;
}

// Whether `http` holds exactly the message `grpc`, with the differences when not.
template <typename Message>
::testing::AssertionResult SameMessage(const Message& http, const Message& grpc) {
  std::string differences;
  google::protobuf::util::MessageDifferencer differencer;
  differencer.ReportDifferencesToString(&differences);
  if (differencer.Compare(http, grpc)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << Message::descriptor()->name() << " differs:\n"
                                       << differences;
}

// The same for an HTTP answer's JSON.
template <typename Message>
::testing::AssertionResult SameMessage(const std::string& http, const Message& grpc) {
  return SameMessage(FromJson<Message>(http), grpc);
}

std::string BvhOf(const Clip& clip) {
  absl::StatusOr<std::string> text = WriteBvh(clip);
  EXPECT_TRUE(text.ok()) << text.status();
  return text.value_or("");
}

// A humanoid take (testing::HumanoidSkeleton) of 4 s at 60 fps.
std::string HumanoidBvh(int seed) {
  return BvhOf(testing::SyntheticClip(testing::HumanoidSkeleton(false),
                                      {.frames = 240, .fps = 60, .seed = seed}));
}

class HttpTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir("http_test");
    std::filesystem::create_directories(dir_ / "web" / "assets");
    Write("web/index.html", "<!doctype html><title>motiondb</title>");
    Write("web/assets/app.js", "console.log('motiondb');");
    Write("web/assets/app.css", "body { margin: 0; }");
    Write("token", kToken);
  }
  void TearDown() override {
    if (HasFailure()) {
      for (const auto& server : servers_) std::cerr << "---- server log ----\n" << server->Log();
    }
    servers_.clear();
    std::filesystem::remove_all(dir_);
  }

  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  // A server on the test's database (unless `args` name another) with its web UI from web/
  // (unless they name another); null after a failed assertion.
  ServerProcess* Start(std::vector<std::string> args = {}) {
    for (const auto& [flag, value] :
         {std::pair<std::string, std::string>{"--db", "db.sqlite"}, {"--web-root", "web"}}) {
      if (std::find(args.begin(), args.end(), flag) == args.end()) {
        args.insert(args.begin(), {flag, (dir_ / value).string()});
      }
    }
    auto server = std::make_unique<ServerProcess>();
    std::string error;
    if (!server->Start(args, &error)) {
      ADD_FAILURE() << error;
      return nullptr;
    }
    servers_.push_back(std::move(server));
    return servers_.back().get();
  }

  // Four humanoid takes (tagged "take", the first two also "first") and the space "body" on
  // them, a label "raise" on take 1 and "crouch" on take 2; through gRPC.
  void LoadLibrary(const std::shared_ptr<grpc::Channel>& channel) {
    auto clips = v1::ClipService::NewStub(channel);
    for (int i = 0; i < 4; ++i) {
      grpc::ClientContext context;
      v1::IngestClipRequest request;
      request.set_file_name(absl::StrCat("take_", i, ".bvh"));
      request.set_bvh(HumanoidBvh(i + 1));
      request.add_tags("take");
      if (i < 2) request.add_tags("first");
      v1::IngestClipResponse response;
      ASSERT_TRUE(clips->IngestClip(&context, request, &response).ok());
      ids_.push_back(response.clip().clip_id());
    }
    grpc::ClientContext space_context;
    v1::CreateSpaceRequest space;
    space.set_name("body");
    v1::Space created;
    const grpc::Status built =
        v1::SpaceService::NewStub(channel)->CreateSpace(&space_context, space, &created);
    ASSERT_TRUE(built.ok()) << built.error_message();
    grpc::ClientContext label_context;
    v1::AddLabelsRequest labels;
    for (const auto& [index, descriptor] : {std::pair{0, "raise"}, std::pair{1, "crouch"}}) {
      v1::NewLabel* label = labels.add_labels();
      label->set_clip_id(ids_[index]);
      label->set_first_frame(10);
      label->set_last_frame(70);
      label->set_descriptor_name(descriptor);
    }
    v1::AddLabelsResponse added;
    ASSERT_TRUE(v1::LabelService::NewStub(channel)->AddLabels(&label_context, labels, &added).ok());
  }

  std::filesystem::path dir_;
  std::vector<std::unique_ptr<ServerProcess>> servers_;
  std::vector<int64_t> ids_;  // LoadLibrary's clips
};

// The HTTP client of a server (plain text), with the token when given.
httplib::Client HttpClient(const ServerProcess& server, const std::string& token = "") {
  httplib::Client client("127.0.0.1", server.http_port());
  client.set_read_timeout(60);
  if (!token.empty()) client.set_bearer_token_auth(token.c_str());
  return client;
}

// GET `path`: the body of a 200 answer (a failed expectation otherwise).
std::string Get200(httplib::Client& client, const std::string& path) {
  const httplib::Result result = client.Get(path.c_str());
  if (!result) {
    ADD_FAILURE() << "GET " << path << ": " << httplib::to_string(result.error());
    return "";
  }
  EXPECT_EQ(result->status, 200) << "GET " << path << ": " << result->body;
  EXPECT_THAT(result->get_header_value("Content-Type"), HasSubstr("application/json"));
  return result->body;
}

std::string Post200(httplib::Client& client, const std::string& path, const std::string& json) {
  const httplib::Result result = client.Post(path.c_str(), json, "application/json");
  if (!result) {
    ADD_FAILURE() << "POST " << path << ": " << httplib::to_string(result.error());
    return "";
  }
  EXPECT_EQ(result->status, 200) << "POST " << path << ": " << result->body;
  return result->body;
}

// An error answer: its HTTP status and its {code, message} body.
struct ErrorAnswer {
  int status = 0;
  int code = -1;
  std::string message;
};

ErrorAnswer ErrorOf(const httplib::Result& result) {
  if (!result) return {};
  const auto body = FromJson<google::protobuf::Struct>(result->body);
  ErrorAnswer error{result->status, -1, ""};
  if (body.fields().count("code"))
    error.code = static_cast<int>(body.fields().at("code").number_value());
  if (body.fields().count("message")) error.message = body.fields().at("message").string_value();
  EXPECT_EQ(body.fields_size(), 2) << result->body;
  return error;
}

// The gRPC answer to `request` by `method` of `stub` (a failed expectation when not OK).
template <typename Stub, typename Request, typename Response>
Response GrpcAnswer(Stub& stub,
                    grpc::Status (Stub::*method)(grpc::ClientContext*, const Request&, Response*),
                    const Request& request) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
  Response response;
  const grpc::Status status = (stub.*method)(&context, request, &response);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return response;
}

template <typename Message>
Message Parse(const std::string& text) {
  Message message;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &message)) << text;
  return message;
}

// Sends `request` (headers and as much body as given) on a connection of its own and returns
// the status line of the answer, read without sending more: a server that waited for the rest
// of the body would answer only once its read timed out, with another status.
std::string RawStatusLine(int port, const std::string& request) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval timeout{60, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
  std::string answer;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0 &&
      ::send(fd, request.data(), request.size(), MSG_NOSIGNAL) ==
          static_cast<ssize_t>(request.size())) {
    char buffer[4096];
    while (answer.find("\r\n") == std::string::npos) {
      const ssize_t n = ::recv(fd, buffer, sizeof(buffer), 0);
      if (n <= 0) break;
      answer.append(buffer, static_cast<size_t>(n));
    }
  }
  ::close(fd);
  return answer.substr(0, answer.find("\r\n"));
}

TEST_F(HttpTest, ReadRoutesAnswerAsGrpc) {
  ServerProcess* server = Start();
  ASSERT_NE(server, nullptr);
  const auto channel = testing::InsecureChannel(server->address());
  ASSERT_NO_FATAL_FAILURE(LoadLibrary(channel));
  httplib::Client http = HttpClient(*server);
  auto clips = v1::ClipService::NewStub(channel);
  auto spaces = v1::SpaceService::NewStub(channel);
  auto labels = v1::LabelService::NewStub(channel);
  using ClipStub = v1::ClipService::Stub;
  const std::string id = absl::StrCat(ids_[1]);

  // The info's uptime moves between the calls; everything else is the same.
  auto info = FromJson<v1::ServerInfo>(Get200(http, "/v1/info"));
  auto grpc_info = GrpcAnswer(*v1::ServerService::NewStub(channel),
                              &v1::ServerService::Stub::GetServerInfo, v1::GetServerInfoRequest());
  EXPECT_GT(info.uptime_s(), 0);
  info.clear_uptime_s();
  grpc_info.clear_uptime_s();
  EXPECT_TRUE(SameMessage(info, grpc_info));

  EXPECT_TRUE(SameMessage(Get200(http, "/v1/clips"),
                          GrpcAnswer(*clips, &ClipStub::ListClips, v1::ListClipsRequest())));
  const std::string skeleton =
      absl::StrCat(GrpcAnswer(*clips, &ClipStub::ListSkeletons, v1::ListSkeletonsRequest())
                       .skeletons(0)
                       .skeleton_id());
  for (const auto& [query, request] : std::vector<std::pair<std::string, std::string>>{
           {"page_size=2&sort=name", "page_size: 2 sort: 'name'"},
           {"tag=first&name_contains=take_1", "tag: 'first' name_contains: 'take_1'"},
           {"skeleton_id=" + skeleton + "&descriptor=crouch",
            "skeleton_id: " + skeleton + " descriptor_name: 'crouch'"},
           {"descriptorName=raise&pageSize=1", "descriptor_name: 'raise' page_size: 1"}}) {
    const std::string json = Get200(http, "/v1/clips?" + query);
    const auto grpc =
        GrpcAnswer(*clips, &ClipStub::ListClips, Parse<v1::ListClipsRequest>(request));
    EXPECT_TRUE(SameMessage(json, grpc)) << query;
    EXPECT_THAT(json, HasSubstr("\"total_size\""));
  }
  EXPECT_TRUE(SameMessage(
      Get200(http, "/v1/clips/" + id),
      GrpcAnswer(*clips, &ClipStub::GetClip, Parse<v1::GetClipRequest>("clip_id: " + id))));
  EXPECT_TRUE(SameMessage(
      Get200(http, "/v1/clips/" + id + "/poses?from=5&to=100&max_rate=20"),
      GrpcAnswer(*clips, &ClipStub::GetClipPoses,
                 Parse<v1::GetClipPosesRequest>(
                     "clip { clip_id: " + id + " first_frame: 5 last_frame: 100 } max_rate: 20"))));
  EXPECT_TRUE(SameMessage(Get200(http, "/v1/clips/" + id + "/labels"),
                          GrpcAnswer(*labels, &v1::LabelService::Stub::GetClipLabels,
                                     Parse<v1::GetClipLabelsRequest>("clip_id: " + id))));
  EXPECT_TRUE(
      SameMessage(Get200(http, "/v1/skeletons"),
                  GrpcAnswer(*clips, &ClipStub::ListSkeletons, v1::ListSkeletonsRequest())));
  EXPECT_TRUE(SameMessage(Get200(http, "/v1/skeletons/" + skeleton),
                          GrpcAnswer(*clips, &ClipStub::GetSkeleton,
                                     Parse<v1::GetSkeletonRequest>("skeleton_id: " + skeleton))));
  EXPECT_TRUE(SameMessage(
      Get200(http, "/v1/spaces"),
      GrpcAnswer(*spaces, &v1::SpaceService::Stub::ListSpaces, v1::ListSpacesRequest())));
  EXPECT_TRUE(SameMessage(Get200(http, "/v1/spaces/body"),
                          GrpcAnswer(*spaces, &v1::SpaceService::Stub::GetSpace,
                                     Parse<v1::GetSpaceRequest>("name: 'body'"))));
  EXPECT_TRUE(SameMessage(
      Get200(http, "/v1/spaces/body/curve?clip=" + id + "&from=10&to=90&dims=4"),
      GrpcAnswer(*spaces, &v1::SpaceService::Stub::GetCurve,
                 Parse<v1::GetCurveRequest>("space: 'body' dims: 4 clip { clip_id: " + id +
                                            " first_frame: 10 last_frame: 90 }"))));
  EXPECT_TRUE(SameMessage(Get200(http, "/v1/labels?clip_id=" + id),
                          GrpcAnswer(*labels, &v1::LabelService::Stub::ListLabels,
                                     Parse<v1::ListLabelsRequest>("clip_id: " + id))));
  EXPECT_TRUE(SameMessage(
      Get200(http, "/v1/labels:find?descriptor=crouch&min_value=0.5"),
      GrpcAnswer(*labels, &v1::LabelService::Stub::FindLabels,
                 Parse<v1::FindLabelsRequest>("descriptor_name: 'crouch' min_value: 0.5"))));
}

TEST_F(HttpTest, ExportAnswersTheBvhAsAFile) {
  ServerProcess* server = Start();
  ASSERT_NE(server, nullptr);
  const auto channel = testing::InsecureChannel(server->address());
  ASSERT_NO_FATAL_FAILURE(LoadLibrary(channel));
  httplib::Client http = HttpClient(*server);
  const auto exported =
      GrpcAnswer(*v1::ClipService::NewStub(channel), &v1::ClipService::Stub::ExportClip,
                 Parse<v1::ExportClipRequest>(
                     absl::StrCat("clip { clip_id: ", ids_[0], " first_frame: 3 last_frame: 9 }")));
  const httplib::Result result =
      http.Get(absl::StrCat("/v1/clips/", ids_[0], "/bvh?from=3&to=9").c_str());
  ASSERT_TRUE(result);
  EXPECT_EQ(result->status, 200);
  EXPECT_EQ(result->body, exported.bvh());
  EXPECT_THAT(result->get_header_value("Content-Type"), HasSubstr("text/plain"));
  EXPECT_EQ(exported.file_name(), "take_0_3-9.bvh");
  EXPECT_THAT(result->get_header_value("Content-Disposition"),
              HasSubstr("attachment; filename=\"take_0_3-9.bvh\""));

  // The same range as binary glTF, through the route of every format.
  const auto glb = GrpcAnswer(
      *v1::ClipService::NewStub(channel), &v1::ClipService::Stub::ExportClip,
      Parse<v1::ExportClipRequest>(absl::StrCat("clip { clip_id: ", ids_[0],
                                                " first_frame: 3 last_frame: 9 } format: 'glb'")));
  const httplib::Result file =
      http.Get(absl::StrCat("/v1/clips/", ids_[0], "/file?from=3&to=9&format=glb").c_str());
  ASSERT_TRUE(file);
  EXPECT_EQ(file->status, 200);
  EXPECT_EQ(file->body, glb.bvh());
  EXPECT_EQ(file->body.substr(0, 4), "glTF");
  EXPECT_EQ(file->get_header_value("Content-Type"), "model/gltf-binary");
  EXPECT_THAT(file->get_header_value("Content-Disposition"),
              HasSubstr("attachment; filename=\"take_0_3-9.glb\""));
}

TEST_F(HttpTest, SearchAnswersAsGrpc) {
  ServerProcess* server = Start();
  ASSERT_NE(server, nullptr);
  const auto channel = testing::InsecureChannel(server->address());
  ASSERT_NO_FATAL_FAILURE(LoadLibrary(channel));
  httplib::Client http = HttpClient(*server);
  auto search = v1::SearchService::NewStub(channel);
  // A stored range and an uploaded file (base64 in JSON); the timings are the only part that
  // differs from one run to the next.
  const std::string bvh = HumanoidBvh(9);
  const std::vector<std::pair<std::string, std::string>> queries = {
      {absl::StrCat(R"({"space":"body","clip":{"clip_id":")", ids_[2],
                    R"(","first_frame":20,"last_frame":80},"return_path":true,"max_results":5})"),
       absl::StrCat("space: 'body' clip { clip_id: ", ids_[2],
                    " first_frame: 20 last_frame: 80 } return_path: true max_results: 5")},
      {absl::StrCat(R"({"space":"body","bvh":{"bvh":")", absl::Base64Escape(bvh),
                    R"(","firstFrame":10,"lastFrame":70}})"),
       "space: 'body' bvh { first_frame: 10 last_frame: 70 }"}};
  // A body sent as a form (curl -d without a Content-Type) is refused: another site's page may
  // send one (http_request_checks_test.cc).
  const httplib::Result form =
      http.Post("/v1/search", queries[0].first, "application/x-www-form-urlencoded");
  ASSERT_TRUE(form);
  EXPECT_EQ(form->status, 415) << form->body;
  for (const auto& [json, text] : queries) {
    v1::SearchRequest request = Parse<v1::SearchRequest>(text);
    if (request.has_bvh()) request.mutable_bvh()->set_bvh(bvh);
    v1::SearchResponse grpc = GrpcAnswer(*search, &v1::SearchService::Stub::Search, request);
    v1::SearchResponse answer = FromJson<v1::SearchResponse>(Post200(http, "/v1/search", json));
    EXPECT_GT(answer.results_size(), 0);
    EXPECT_GT(answer.timings().total_ms(), 0);
    answer.clear_timings();
    grpc.clear_timings();
    EXPECT_TRUE(SameMessage(answer, grpc)) << json.substr(0, 200);
  }
}

// HTTP clients send no deadline: the server gives each API call --http-timeout-s, past which the
// call's work stops and the answer is 504 with DEADLINE_EXCEEDED. The exact search looks at the
// deadline as it starts each clip: over the fixture's four clips an exhaustive search with every
// dimension in the warp took 1.5 ms, and a fast build could finish before looking past 1 ms, so
// the library gets a hundred more clips (about 20-40 ms of work, more under load), while gRPC
// calls keep their own deadlines.
TEST_F(HttpTest, ApiCallsEndAtTheHttpTimeout) {
  ServerProcess* server = Start({"--http-timeout-s", "0.001"});
  ASSERT_NE(server, nullptr);
  const auto channel = testing::InsecureChannel(server->address());
  ASSERT_NO_FATAL_FAILURE(LoadLibrary(channel));
  auto clips = v1::ClipService::NewStub(channel);
  for (int i = 0; i < 100; ++i) {
    grpc::ClientContext context;
    v1::IngestClipRequest request;
    request.set_file_name(absl::StrCat("more_", i, ".bvh"));
    request.set_bvh(HumanoidBvh(100 + i));
    v1::IngestClipResponse response;
    ASSERT_TRUE(clips->IngestClip(&context, request, &response).ok());
  }
  const std::string query = absl::StrCat(
      R"({"space":"body","clip":{"clip_id":")", ids_[0],
      R"(","first_frame":0,"last_frame":239},"exact":true,"dtw_dims":60,)", R"("slope_limit":4})");
  httplib::Client http = HttpClient(*server);
  const ErrorAnswer ended = ErrorOf(http.Post("/v1/search", query, "application/json"));
  EXPECT_EQ(ended.status, 504);
  EXPECT_EQ(ended.code, static_cast<int>(grpc::StatusCode::DEADLINE_EXCEEDED));
  v1::SearchRequest request;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(query, &request).ok());
  auto search = v1::SearchService::NewStub(channel);
  EXPECT_GT(GrpcAnswer(*search, &v1::SearchService::Stub::Search, request).results_size(), 0);
}

TEST_F(HttpTest, WritesGoThroughTheSameServices) {
  ServerProcess* server = Start({"--test-job-pause-after", "0"});
  ASSERT_NE(server, nullptr);
  const auto channel = testing::InsecureChannel(server->address());
  ASSERT_NO_FATAL_FAILURE(LoadLibrary(channel));
  httplib::Client http = HttpClient(*server);
  auto clips = v1::ClipService::NewStub(channel);
  auto labels = v1::LabelService::NewStub(channel);
  auto jobs = v1::JobService::NewStub(channel);

  // An ingest of a base64 file, as stored and projected into the space.
  const auto ingested = FromJson<v1::IngestClipResponse>(
      Post200(http, "/v1/clips",
              absl::StrCat(R"({"file_name":"new.bvh","bvh":")", absl::Base64Escape(HumanoidBvh(7)),
                           R"(","tags":["web"]})")));
  EXPECT_EQ(ingested.result(), v1::INGEST_RESULT_STORED);
  EXPECT_THAT(ingested.projected_spaces(), ::testing::ElementsAre("body"));
  v1::Clip stored =
      GrpcAnswer(*clips, &v1::ClipService::Stub::GetClip,
                 Parse<v1::GetClipRequest>(absl::StrCat("clip_id: ", ingested.clip().clip_id())));
  stored.clear_joint_names();  // GetClip only
  EXPECT_TRUE(SameMessage(ingested.clip(), stored));

  // Labels added, then deleted by a filter.
  const auto added = FromJson<v1::AddLabelsResponse>(Post200(
      http, "/v1/labels",
      absl::StrCat(R"({"labels":[{"clip_id":")", ingested.clip().clip_id(),
                   R"(","first_frame":5,"last_frame":50,"descriptor":"wave","value":0.5}]})")));
  ASSERT_EQ(added.labels_size(), 1);
  EXPECT_TRUE(SameMessage(Get200(http, absl::StrCat("/v1/labels?descriptor=wave")),
                          GrpcAnswer(*labels, &v1::LabelService::Stub::ListLabels,
                                     Parse<v1::ListLabelsRequest>("descriptor_name: 'wave'"))));
  EXPECT_EQ(FromJson<v1::DeleteLabelsResponse>(
                Post200(http, "/v1/labels:delete", R"({"descriptor":"wave"})"))
                .deleted(),
            1);

  // A job started, seen, cancelled; once it ended, every read of it agrees.
  const auto job =
      FromJson<v1::Job>(Post200(http, "/v1/jobs", R"({"space":"body","descriptors":["raise"]})"));
  ASSERT_FALSE(job.job_id().empty());
  Post200(http, "/v1/jobs/" + job.job_id() + ":cancel", "");
  v1::Job ended;
  for (int polls = 0; polls < 600; ++polls) {
    ended = FromJson<v1::Job>(Get200(http, "/v1/jobs/" + job.job_id()));
    if (ended.state() == v1::JOB_STATE_CANCELLED) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(ended.state(), v1::JOB_STATE_CANCELLED);
  EXPECT_TRUE(
      SameMessage(ended, GrpcAnswer(*jobs, &v1::JobService::Stub::GetJob,
                                    Parse<v1::GetJobRequest>("job_id: '" + job.job_id() + "'"))));
  EXPECT_TRUE(
      SameMessage(Get200(http, "/v1/jobs"),
                  GrpcAnswer(*jobs, &v1::JobService::Stub::ListJobs, v1::ListJobsRequest())));

  // A skeleton's head given by hand, as GetSkeleton then shows it; a bad override is refused
  // and changes nothing.
  const std::string skeleton = absl::StrCat(stored.skeleton_id());
  const std::string map_path = "/v1/skeletons/" + skeleton + ":map";
  const auto mapped = FromJson<v1::SkeletonDetail>(
      Post200(http, map_path, R"({"set":[{"slot":"Head","joint":"Neck"}],"clear":["Neck"]})"));
  const auto shown = [&] {
    return GrpcAnswer(*clips, &v1::ClipService::Stub::GetSkeleton,
                      Parse<v1::GetSkeletonRequest>("skeleton_id: " + skeleton));
  };
  EXPECT_TRUE(SameMessage(mapped, shown()));
  EXPECT_THAT(mapped.humanoid_map().DebugString(),
              HasSubstr("slot: \"Head\"\n  joint: 3\n  joint_name: \"Neck\"\n  overridden: true"));
  const httplib::Result refused = http.Post(
      map_path.c_str(), R"({"set":[{"slot":"LeftHand","joint":"hand_l"}]})", "application/json");
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 400);
  EXPECT_THAT(ErrorOf(refused).message, HasSubstr("set[0].joint: skeleton " + skeleton));
  EXPECT_TRUE(SameMessage(mapped, shown()));

  // A delete, after which gRPC finds no clip.
  const httplib::Result deleted =
      http.Delete(absl::StrCat("/v1/clips/", ingested.clip().clip_id()).c_str());
  ASSERT_TRUE(deleted);
  EXPECT_EQ(deleted->status, 200);
  EXPECT_EQ(deleted->body, "{}");
  grpc::ClientContext context;
  v1::Clip gone;
  EXPECT_EQ(
      clips
          ->GetClip(&context,
                    Parse<v1::GetClipRequest>(absl::StrCat("clip_id: ", ingested.clip().clip_id())),
                    &gone)
          .error_code(),
      grpc::StatusCode::NOT_FOUND);
}

TEST_F(HttpTest, ErrorsAreMappedAsGrpcGatewayMapsThemWithCodeAndMessage) {
  ServerProcess* server = Start();
  ASSERT_NE(server, nullptr);
  const auto channel = testing::InsecureChannel(server->address());
  ASSERT_NO_FATAL_FAILURE(LoadLibrary(channel));
  httplib::Client http = HttpClient(*server);
  const auto expect_error = [](const httplib::Result& result, int status, int code,
                               const std::string& part) {
    ASSERT_TRUE(result);
    EXPECT_THAT(result->get_header_value("Content-Type"), HasSubstr("application/json"));
    const ErrorAnswer error = ErrorOf(result);
    EXPECT_EQ(error.status, status) << result->body;
    EXPECT_EQ(error.code, code) << result->body;
    EXPECT_THAT(error.message, HasSubstr(part));
  };
  // NOT_FOUND, with the message gRPC gives.
  expect_error(http.Get("/v1/clips/999"), 404, 5, "clip 999 not found");
  expect_error(http.Get("/v1/skeletons/999"), 404, 5, "skeleton 999 not found");
  expect_error(http.Get("/v1/spaces/nowhere"), 404, 5, "nowhere");
  // INVALID_ARGUMENT: a parameter of the wrong type, an unknown one, a value the service
  // refuses, malformed JSON, an unknown JSON field, a path value that is no number.
  expect_error(http.Get("/v1/clips?page_size=many"), 400, 3, "page_size");
  expect_error(http.Get("/v1/clips?colour=red"), 400, 3, "colour");
  expect_error(http.Get("/v1/clips?sort=size"), 400, 3, "sort");
  expect_error(http.Get("/v1/clips/abc"), 400, 3, "clip_id");
  // A string that is not UTF-8 (percent-encoded bytes) was answered 500 with no message: the
  // services' side refuses such a request as a whole (found by the http_route fuzzer).
  expect_error(http.Get("/v1/jobs/%D0%FE"), 400, 3, "not UTF-8");
  expect_error(http.Get("/v1/clips?tag=%FF"), 400, 3, "tag");
  // A message that quotes such bytes (a parameter's name, a number's text) had them raw in the
  // body, which was then no JSON (found by the http_route fuzzer): they are U+FFFD now.
  expect_error(http.Get("/v1/clips?%FF%FEx=1"), 400, 3, "parameter '\uFFFD\uFFFDx'");
  expect_error(http.Get("/v1/clips/%C1%FF7"), 400, 3, "'\uFFFD\uFFFD7' is not a valid int64");
  expect_error(http.Get(absl::StrCat("/v1/clips/", ids_[0], "/poses?to=100000").c_str()), 400, 3,
               "clip.last_frame");
  expect_error(http.Get(absl::StrCat("/v1/clips/", ids_[0], "/poses?max_rate=-1").c_str()), 400, 3,
               "max_rate");
  expect_error(http.Post("/v1/search", "{\"space\": ", "application/json"), 400, 3, "request body");
  expect_error(http.Post("/v1/search", R"({"space":"body","colour":1})", "application/json"), 400,
               3, "colour");
  expect_error(http.Post("/v1/search",
                         absl::StrCat(R"({"space":"body","clip":{"clip_id":")", ids_[0],
                                      R"("},"max_results":-3})"),
                         "application/json"),
               400, 3, "max_results");
  // FAILED_PRECONDITION is 400 too (a job cancelled once it ended); ALREADY_EXISTS 409.
  const auto job =
      FromJson<v1::Job>(Post200(http, "/v1/jobs", R"({"space":"body","descriptors":["raise"]})"));
  for (int polls = 0; polls < 1200; ++polls) {
    const auto now = FromJson<v1::Job>(Get200(http, "/v1/jobs/" + job.job_id()));
    if (now.state() != v1::JOB_STATE_QUEUED && now.state() != v1::JOB_STATE_RUNNING) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  expect_error(http.Post(("/v1/jobs/" + job.job_id() + ":cancel").c_str(), "", "application/json"),
               400, 9, job.job_id());
  expect_error(http.Post("/v1/jobs/job-99:cancel", "", "application/json"), 404, 5, "job-99");
  const std::string again =
      absl::StrCat(R"({"file_name":"take_0.bvh","on_conflict":"ON_CONFLICT_ERROR","bvh":")",
                   absl::Base64Escape(HumanoidBvh(1)), R"("})");
  expect_error(http.Post("/v1/clips", again, "application/json"), 409, 6, "take_0");
  // A query parameter naming a field the path gives, by any of its names, is refused and
  // changes nothing.
  const std::string clip = absl::StrCat("/v1/clips/", ids_[3]);
  for (const std::string& query :
       {"clip_id=" + absl::StrCat(ids_[0]), std::string("id=77"), std::string("clipId=77")}) {
    expect_error(http.Delete((clip + "?" + query).c_str()), 400, 3, "the path gives clip_id");
  }
  expect_error(http.Get((clip + "/bvh?clip.clipId=77").c_str()), 400, 3,
               "the path gives clip.clip_id");
  expect_error(http.Get("/v1/spaces/body/curve?space=other"), 400, 3, "the path gives space");
  EXPECT_EQ(http.Get(clip.c_str())->status, 200);
  EXPECT_EQ(http.Get(absl::StrCat("/v1/clips/", ids_[0]).c_str())->status, 200);
  // No such route, or not with that method.
  expect_error(http.Get("/v1/nothing"), 404, 5, "GET /v1/nothing");
  expect_error(http.Put("/v1/clips", "", "application/json"), 404, 5, "PUT /v1/clips");
  expect_error(http.Get("/v1/jobs/job-1:cancel"), 404, 5, "");
}

// httplib 0.11 reads a chunked body whole, inflates a compressed one whole and reads a POST
// without a length until the connection ends, all before any handler; such bodies, and bodies
// where none is taken, are refused from their headers alone. The server then serves on.
TEST_F(HttpTest, BodiesAreRefusedFromTheirHeadersBeforeTheyAreRead) {
  ServerProcess* server =
      Start({"--auth-token-file", (dir_ / "token").string(), "--max-message-mb", "1"});
  ASSERT_NE(server, nullptr);
  const int port = server->http_port();
  const std::string token = absl::StrCat("Authorization: Bearer ", kToken, "\r\n");
  const auto post = [](const std::string& path, const std::string& headers) {
    return absl::StrCat("POST ", path, " HTTP/1.1\r\nHost: test\r\n", headers, "\r\n");
  };
  // The first MiB of a chunked body that never ends.
  EXPECT_EQ(RawStatusLine(port, post("/v1/search", token + "Transfer-Encoding: chunked\r\n") +
                                    "100000\r\n" + std::string(1 << 20, '{') + "\r\n"),
            "HTTP/1.1 411 Length Required");
  // A length far beyond --max-message-mb, its body not sent.
  EXPECT_EQ(RawStatusLine(port, post("/v1/search", token + "Content-Length: 100000000\r\n")),
            "HTTP/1.1 413 Payload Too Large");
  // A POST without a length, to a route that takes a body or to one that does not.
  EXPECT_EQ(RawStatusLine(port, post("/v1/jobs/job-1:cancel", token)),
            "HTTP/1.1 411 Length Required");
  EXPECT_EQ(RawStatusLine(port, post("/x", "")), "HTTP/1.1 411 Length Required");
  // A body on a route without one (its token is right) or on a file's path.
  EXPECT_EQ(RawStatusLine(port, absl::StrCat("GET /v1/clips HTTP/1.1\r\nHost: test\r\n", token,
                                             "Content-Length: 2\r\n\r\n{}")),
            "HTTP/1.1 413 Payload Too Large");
  EXPECT_EQ(RawStatusLine(port, post("/index.html", "Content-Length: 2\r\n") + "{}"),
            "HTTP/1.1 413 Payload Too Large");

  // A gzip body (16 MiB inflated) without a token, through httplib's own client.
  httplib::Client anonymous = HttpClient(*server);
  anonymous.set_compress(true);
  const httplib::Result gzip = anonymous.Post("/x", std::string(16 << 20, ' '), "application/json");
  ASSERT_TRUE(gzip) << httplib::to_string(gzip.error());
  const ErrorAnswer error = ErrorOf(gzip);
  EXPECT_EQ(error.status, 415);
  EXPECT_THAT(error.message, HasSubstr("uncompressed"));

  // It serves on, a body where one belongs too.
  httplib::Client right = HttpClient(*server, kToken);
  EXPECT_EQ(right.Get("/healthz")->status, 200);
  const httplib::Result search = right.Post("/v1/search", "{}", "application/json");
  ASSERT_TRUE(search);
  EXPECT_THAT(ErrorOf(search).message, HasSubstr("space"));
  EXPECT_EQ(right.Post("/v1/jobs/job-1:cancel", "", "application/json")->status, 404);
}

TEST_F(HttpTest, TheTokenGuardsTheApiAndMetricsNotHealthOrFiles) {
  ServerProcess* server = Start({"--auth-token-file", (dir_ / "token").string()});
  ASSERT_NE(server, nullptr);
  httplib::Client anonymous = HttpClient(*server);
  httplib::Client wrong = HttpClient(*server, "not-the-token");
  httplib::Client right = HttpClient(*server, kToken);
  for (const char* path : {"/v1/info", "/v1/clips", "/metrics", "/v1/nothing"}) {
    for (httplib::Client* client : {&anonymous, &wrong}) {
      const httplib::Result result = client->Get(path);
      ASSERT_TRUE(result) << path;
      const ErrorAnswer error = ErrorOf(result);
      EXPECT_EQ(error.status, 401) << path;
      EXPECT_EQ(error.code, 16) << path;
      EXPECT_THAT(error.message, HasSubstr("Authorization: Bearer"));
      EXPECT_EQ(result->get_header_value("WWW-Authenticate"), "Bearer");
    }
  }
  EXPECT_EQ(right.Get("/v1/info")->status, 200);
  EXPECT_EQ(right.Get("/metrics")->status, 200);
  EXPECT_TRUE(FromJson<v1::ServerInfo>(right.Get("/v1/info")->body).auth_required());
  // Probes and the page's files need none.
  EXPECT_EQ(anonymous.Get("/healthz")->status, 200);
  EXPECT_EQ(anonymous.Get("/readyz")->status, 200);
  EXPECT_EQ(anonymous.Get("/")->status, 200);
  EXPECT_EQ(anonymous.Get("/assets/app.js")->status, 200);
  EXPECT_THAT(server->Log(), HasSubstr("GET /v1/info UNAUTHENTICATED"));

  // Unless the health service needs the token too.
  ServerProcess* strict =
      Start({"--auth-token-file", (dir_ / "token").string(), "--health-needs-token", "--db",
             (dir_ / "strict.sqlite").string()});
  ASSERT_NE(strict, nullptr);
  httplib::Client strict_anonymous = HttpClient(*strict);
  EXPECT_EQ(strict_anonymous.Get("/healthz")->status, 401);
  EXPECT_EQ(strict_anonymous.Get("/readyz")->status, 401);
  EXPECT_EQ(HttpClient(*strict, kToken).Get("/readyz")->status, 200);
  EXPECT_EQ(strict_anonymous.Get("/")->status, 200);
}

TEST_F(HttpTest, ServesTheWebUiFilesWithTheirTypes) {
  ServerProcess* server = Start();
  ASSERT_NE(server, nullptr);
  httplib::Client http = HttpClient(*server);
  for (const auto& [path, type, body] :
       std::vector<std::tuple<std::string, std::string, std::string>>{
           {"/", "text/html", "<!doctype html><title>motiondb</title>"},
           {"/?space=body&clip=1&from=0&to=60", "text/html",
            "<!doctype html><title>motiondb</title>"},
           {"/index.html", "text/html", "<!doctype html><title>motiondb</title>"},
           {"/assets/app.js", "text/javascript", "console.log('motiondb');"},
           {"/assets/app.css", "text/css", "body { margin: 0; }"}}) {
    const httplib::Result result = http.Get(path.c_str());
    ASSERT_TRUE(result) << path;
    EXPECT_EQ(result->status, 200) << path;
    EXPECT_THAT(result->get_header_value("Content-Type"), HasSubstr(type)) << path;
    EXPECT_EQ(result->body, body) << path;
  }
  const httplib::Result missing = http.Get("/assets/none.js");
  ASSERT_TRUE(missing);
  EXPECT_EQ(ErrorOf(missing).status, 404);
  const httplib::Result outside = http.Get("/../token");
  ASSERT_TRUE(outside);
  EXPECT_NE(outside->status, 200);
  EXPECT_NE(outside->body, kToken);

  // No built UI: / says how to build it.
  ServerProcess* unbuilt = Start(
      {"--web-root", (dir_ / "no-such-dist").string(), "--db", (dir_ / "unbuilt.sqlite").string()});
  ASSERT_NE(unbuilt, nullptr);
  const httplib::Result result = HttpClient(*unbuilt).Get("/");
  ASSERT_TRUE(result);
  const ErrorAnswer error = ErrorOf(result);
  EXPECT_EQ(error.status, 404);
  EXPECT_EQ(error.code, 5);
  EXPECT_THAT(error.message, HasSubstr("not built"));
  EXPECT_THAT(error.message, HasSubstr("no-such-dist"));

  // An empty web root (the image built where the npm registry was unreachable) is not built
  // either: / says so rather than answering a bare 404.
  std::filesystem::create_directory(dir_ / "empty-dist");
  ServerProcess* empty = Start(
      {"--web-root", (dir_ / "empty-dist").string(), "--db", (dir_ / "empty.sqlite").string()});
  ASSERT_NE(empty, nullptr);
  const ErrorAnswer empty_error = ErrorOf(HttpClient(*empty).Get("/"));
  EXPECT_EQ(empty_error.status, 404);
  EXPECT_THAT(empty_error.message, HasSubstr("not built"));
  EXPECT_THAT(empty_error.message, HasSubstr("empty-dist"));
}

TEST_F(HttpTest, HealthAndReadiness) {
  ServerProcess* server = Start();
  ASSERT_NE(server, nullptr);
  httplib::Client http = HttpClient(*server);
  const httplib::Result healthz = http.Get("/healthz");
  ASSERT_TRUE(healthz);
  EXPECT_EQ(healthz->status, 200);
  EXPECT_EQ(healthz->body, "ok");
  const httplib::Result readyz = http.Get("/readyz");
  ASSERT_TRUE(readyz);
  EXPECT_EQ(readyz->status, 200);
  EXPECT_EQ(readyz->body, "ready");
}

TEST_F(HttpTest, HttpFlags) {
  // off: no HTTP port at all, gRPC as ever.
  ServerProcess* quiet = Start({"--http", "off"});
  ASSERT_NE(quiet, nullptr);
  EXPECT_EQ(quiet->http_port(), 0);
  EXPECT_THAT(quiet->Log(), ::testing::Not(HasSubstr("HTTP on")));
  EXPECT_TRUE(testing::WaitUntilServing(testing::InsecureChannel(quiet->address()), ""));
  // A malformed address is a usage error; a port in use stops the server with a message.
  ServerProcess malformed;
  std::string error;
  EXPECT_FALSE(
      malformed.Start({"--db", (dir_ / "m.sqlite").string(), "--http", "nowhere"}, &error));
  EXPECT_THAT(error, HasSubstr("--http"));
  ServerProcess* first = Start();
  ASSERT_NE(first, nullptr);
  ServerProcess second;
  EXPECT_FALSE(second.Start({"--db", (dir_ / "b.sqlite").string(), "--http",
                             absl::StrCat("127.0.0.1:", first->http_port())},
                            &error));
  EXPECT_THAT(error, HasSubstr("cannot listen on"));
}

TEST_F(HttpTest, ServesHttpsWithTheGrpcCertificate) {
  const absl::StatusOr<testing::TlsFiles> tls = testing::MakeTlsCertificate(dir_);
  if (absl::IsNotFound(tls.status())) GTEST_SKIP() << tls.status().message();
  ASSERT_TRUE(tls.ok()) << tls.status();
  const std::string& cert = tls->cert;
  const std::string& key = tls->key;
  ServerProcess* server =
      Start({"--tls-cert", cert, "--tls-key", key, "--auth-token-file", (dir_ / "token").string()});
  ASSERT_NE(server, nullptr);
  EXPECT_THAT(server->Log(), HasSubstr("HTTPS"));
  httplib::SSLClient https("127.0.0.1", server->http_port());
  https.set_ca_cert_path(cert.c_str());
  https.enable_server_certificate_verification(true);
  https.set_bearer_token_auth(kToken);
  const httplib::Result info = https.Get("/v1/info");
  ASSERT_TRUE(info) << httplib::to_string(info.error());
  EXPECT_EQ(info->status, 200);
  EXPECT_TRUE(FromJson<v1::ServerInfo>(info->body).tls());
  // Plain HTTP gets no answer from it.
  httplib::Client plain = HttpClient(*server, kToken);
  plain.set_read_timeout(5);
  const httplib::Result refused = plain.Get("/v1/info");
  EXPECT_TRUE(!refused || refused->status != 200);
}

// A scrape after calls on both faces, a search and ingests.
std::string ScrapeAfterTraffic(const ServerProcess& server, const std::vector<int64_t>& ids) {
  const auto channel = testing::InsecureChannel(server.address());
  grpc::ClientContext context;
  v1::Clip clip;
  v1::ClipService::NewStub(channel)->GetClip(&context, Parse<v1::GetClipRequest>("clip_id: 999"),
                                             &clip);  // NOT_FOUND, over gRPC
  httplib::Client http = HttpClient(server);
  Get200(http, "/v1/clips");
  http.Get("/v1/clips/999");
  http.Get("/v1/nothing");
  Post200(http, "/v1/search",
          absl::StrCat(R"({"space":"body","clip":{"clip_id":")", ids[0],
                       R"(","first_frame":0,"last_frame":60}})"));
  const httplib::Result metrics = http.Get("/metrics");
  EXPECT_TRUE(metrics);
  if (!metrics) return "";
  EXPECT_EQ(metrics->status, 200);
  EXPECT_THAT(metrics->get_header_value("Content-Type"), HasSubstr("text/plain; version=0.0.4"));
  return metrics->body;
}

TEST_F(HttpTest, MetricsCountBothFacesSearchesIndicesJobsAndMemory) {
  ServerProcess* server = Start();
  ASSERT_NE(server, nullptr);
  ASSERT_NO_FATAL_FAILURE(LoadLibrary(testing::InsecureChannel(server->address())));
  const std::string text = ScrapeAfterTraffic(*server, ids_);
  const auto has_line = [&text](const std::string& prefix) {
    return ::testing::AssertionResult(text.find("\n" + prefix) != std::string::npos)
           << "no line " << prefix;
  };
  EXPECT_TRUE(has_line(
      R"(motiondb_requests_total{face="grpc",method="/motiondb.v1.ClipService/IngestClip",code="OK"} 4)"));
  EXPECT_TRUE(has_line(
      R"(motiondb_requests_total{face="grpc",method="/motiondb.v1.ClipService/GetClip",code="NOT_FOUND"} 1)"));
  EXPECT_TRUE(has_line(
      R"(motiondb_requests_total{face="http",method="/motiondb.v1.ClipService/GetClip",code="NOT_FOUND"} 1)"));
  EXPECT_TRUE(has_line(
      R"(motiondb_requests_total{face="http",method="/motiondb.v1.ClipService/ListClips",code="OK"} 1)"));
  EXPECT_TRUE(has_line(
      R"(motiondb_request_duration_seconds_count{face="http",method="/motiondb.v1.SearchService/Search"} 1)"));
  EXPECT_TRUE(has_line(
      R"(motiondb_request_duration_seconds_bucket{face="http",method="/motiondb.v1.SearchService/Search",le="+Inf"} 1)"));
  EXPECT_TRUE(
      has_line(R"(motiondb_http_requests_total{route="GET /v1/clips/{id}",status="404"} 1)"));
  EXPECT_TRUE(has_line(R"(motiondb_http_requests_total{route="unmatched",status="404"} 1)"));
  EXPECT_TRUE(
      has_line(R"(motiondb_http_request_duration_seconds_count{route="POST /v1/search"} 1)"));
  for (const char* stage : {"characteristic", "seeds", "warps", "ranking", "total", "request"}) {
    EXPECT_TRUE(has_line(
        absl::StrCat(R"(motiondb_search_stage_duration_seconds_count{stage=")", stage, R"("} 1)")));
  }
  EXPECT_TRUE(has_line(R"(motiondb_index_clips{space="body"} 4)"));
  EXPECT_TRUE(has_line(R"(motiondb_index_frames{space="body"} )"));
  EXPECT_TRUE(has_line("motiondb_ingested_frames_total 960"));  // 4 takes of 240 frames
  EXPECT_TRUE(has_line(R"(motiondb_jobs{state="queued"} 0)"));
  EXPECT_TRUE(has_line(R"(motiondb_jobs{state="interrupted"} 0)"));
  EXPECT_TRUE(has_line("motiondb_uploads_in_progress 0\n"));  // every ingest done
  EXPECT_TRUE(has_line("motiondb_upload_buffered_bytes 0\n"));
  EXPECT_TRUE(has_line("process_resident_memory_bytes "));
  EXPECT_THAT(text, HasSubstr("# TYPE motiondb_request_duration_seconds histogram\n"));
}

TEST_F(HttpTest, MetricsPassPromtool) {
  if (std::system("command -v promtool >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "promtool is not installed (Debian package prometheus, packages-dev.txt)";
  }
  ServerProcess* server = Start();
  ASSERT_NE(server, nullptr);
  ASSERT_NO_FATAL_FAILURE(LoadLibrary(testing::InsecureChannel(server->address())));
  const std::string scraped = Write("metrics.txt", ScrapeAfterTraffic(*server, ids_));
  const std::string output = (dir_ / "promtool.out").string();
  const int status =
      std::system(("promtool check metrics < '" + scraped + "' > '" + output + "' 2>&1").c_str());
  EXPECT_EQ(status, 0) << testing::ReadFileOrDie(output);
  // promtool's lint complains on stdout or stderr without failing for some findings.
  EXPECT_EQ(testing::ReadFileOrDie(output), "");
}

}  // namespace
}  // namespace motiondb
