// The HTTP face against pages of other web sites (server/http/request_checks.h, issue 37 defect
// 6 and two of its "Also" items), on the real server: a POST to the API is JSON or refused (a
// page of another origin could send text/plain, a form or nothing without asking), the Host
// header must name the server (DNS rebinding), CORS is off unless an origin is listed, and a
// file path holding a control character once decoded is refused (/index.html%00.js was served
// as JavaScript). Requests go through cpp-httplib's client with the Host the test gives.
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/ascii.h"
#include "absl/strings/escaping.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "tests/server_fixture.h"

// Last: httplib.h includes <resolv.h>, whose _res macro breaks the Eigen headers above.
#include <httplib.h>

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// A request with `headers` ("Name: value"; a Host among them replaces the client's) and, for a
// POST, `body`, through cpp-httplib's client; a default answer (status 0) when it fails.
struct Answer {
  int status = 0;
  httplib::Headers headers;
  std::string body;

  std::string Header(const std::string& name) const {
    const auto found = headers.find(name);  // httplib compares names without case
    return found == headers.end() ? "" : found->second;
  }
  // Whether any header is a CORS one.
  bool AnyCors() const {
    return std::any_of(headers.begin(), headers.end(), [](const auto& header) {
      return absl::StartsWithIgnoreCase(header.first, "Access-Control-");
    });
  }
};

Answer Send(int port, const std::string& method, const std::string& path, const std::string& host,
            const std::vector<std::string>& headers = {}, const std::string& body = "") {
  httplib::Client client("127.0.0.1", port);
  client.set_keep_alive(false);
  client.set_read_timeout(60);
  httplib::Headers sent = {{"Host", host}};
  std::string type;
  for (const std::string& header : headers) {
    const std::pair<std::string, std::string> split =
        absl::StrSplit(header, absl::MaxSplits(':', 1));
    const std::string value(absl::StripAsciiWhitespace(split.second));
    if (absl::EqualsIgnoreCase(split.first, "Content-Type")) {
      type = value;
    } else {
      sent.emplace(split.first, value);
    }
  }
  const httplib::Result result = method == "GET" ? client.Get(path.c_str(), sent)
                                 : method == "OPTIONS"
                                     ? client.Options(path.c_str(), sent)
                                     : client.Post(path.c_str(), sent, body, type.c_str());
  if (!result) return {};
  return {result->status, result->headers, result->body};
}

class HttpRequestChecksTest : public ServerTest {
 protected:
  void SetUp() override {
    ServerTest::SetUp();
    std::filesystem::create_directories(dir_ / "web" / "assets");
    WriteFile("web/index.html", "<!doctype html><title>motiondb</title>");
    WriteFile("web/assets/app.js", "console.log('motiondb');");
  }

  // A server with the test's web root and `args`.
  testing::ServerProcess* Start(std::vector<std::string> args = {}) {
    args.insert(args.end(), {"--web-root", (dir_ / "web").string()});
    return StartServer(args);
  }

  // Whether the server refuses to start with `args`, saying `message`.
  void ExpectRefusedFlag(const std::vector<std::string>& args, const std::string& message) {
    testing::ServerProcess server;
    std::string error;
    std::vector<std::string> all = {"--db", db_};
    all.insert(all.end(), args.begin(), args.end());
    EXPECT_FALSE(server.Start(all, &error)) << args.back();
    EXPECT_THAT(error, HasSubstr(message)) << args.back();
  }
};

// The probe's cross-site writes: a page of another origin sent JSON as text/plain (and as a
// form, or with no type), which a browser sends without a preflight, and added labels,
// ingested a clip, deleted labels and started a job. Now only application/json is read.
TEST_F(HttpRequestChecksTest, ApiPostsTakeOnlyJson) {
  testing::ServerProcess* server = Start();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const int64_t clip = client.IngestOrFail("chain.bvh", BvhText(ChainClip()));
  const int port = server->http_port();
  const std::string host = absl::StrCat("127.0.0.1:", port);
  const std::string label =
      absl::StrCat(R"({"labels": [{"clip_id": ")", clip, R"(", "descriptor_name": "csrf"}]})");
  const std::string job = R"({"space": "none", "descriptor_names": ["csrf"]})";
  const std::string ingest = absl::StrCat(R"({"file_name": "x.bvh", "bvh": ")",
                                          absl::Base64Escape(BvhText(ChainClip(0.05))), R"("})");
  const auto labels = [&client]() {
    v1::ListLabelsResponse listed;
    EXPECT_TRUE(client.labels().ListLabels(client.Context().get(), {}, &listed).ok());
    return listed.labels_size();
  };
  for (const std::string& type : std::vector<std::string>{
           "Content-Type: text/plain", "Content-Type: text/plain;charset=UTF-8",
           "Content-Type: application/x-www-form-urlencoded",
           "Content-Type: multipart/form-data; boundary=x", "Content-Type: application/jsonx",
           "Content-Type: application/json; charset=iso-8859-1", ""}) {
    const std::vector<std::string> headers =
        type.empty() ? std::vector<std::string>{} : std::vector<std::string>{type};
    for (const auto& [path, body] : std::vector<std::pair<std::string, std::string>>{
             {"/v1/labels", label},
             {"/v1/clips", ingest},
             {"/v1/jobs", job},
             {"/v1/labels:delete", R"({"descriptor_name": "kept"})"},
             {"/v1/jobs/job-1:cancel", ""}}) {
      const Answer answer = Send(port, "POST", path, host, headers, body);
      EXPECT_EQ(answer.status, 415) << path << " " << type << "\n" << answer.body;
      EXPECT_THAT(answer.body, HasSubstr("'Content-Type: application/json'")) << path;
      EXPECT_THAT(answer.body, HasSubstr("\"code\":3")) << path;
      EXPECT_EQ(answer.Header("connection"), "close") << path;
    }
  }
  EXPECT_EQ(labels(), 0);
  v1::ListClipsResponse clips;
  ASSERT_TRUE(client.clips().ListClips(client.Context().get(), {}, &clips).ok());
  EXPECT_EQ(clips.clips_size(), 1);
  v1::ListJobsResponse jobs;
  ASSERT_TRUE(client.jobs().ListJobs(client.Context().get(), {}, &jobs).ok());
  EXPECT_EQ(jobs.jobs_size(), 0);

  // JSON by its type, whatever the case, with or without a UTF-8 charset.
  for (const std::string& type : std::vector<std::string>{
           "Content-Type: application/json", "Content-Type: Application/JSON ; Charset=\"UTF-8\"",
           "Content-Type: application/json;charset=utf-8"}) {
    const Answer answer = Send(port, "POST", "/v1/labels", host, {type}, label);
    EXPECT_EQ(answer.status, 200) << type << "\n" << answer.body;
  }
  // The second and third are the first again: stored once.
  EXPECT_EQ(labels(), 1);
}

// DNS rebinding: a page whose own name now resolves to this server sends that name as Host.
// Only an address, localhost or a listed name is answered; the port is not compared (a
// container's port mapping changes it).
TEST_F(HttpRequestChecksTest, TheHostHeaderMustNameTheServer) {
  testing::ServerProcess* server = Start();
  ASSERT_NE(server, nullptr);
  const int port = server->http_port();
  const std::string p = absl::StrCat(port);
  for (const std::string& host : std::vector<std::string>{
           "127.0.0.1:" + p, "localhost:" + p, "LocalHost:" + p, "[::1]:" + p, "localhost",
           "127.0.0.1", "localhost:9000", "10.1.2.3:8080", "[fe80::1%25eth0]:" + p}) {
    EXPECT_EQ(Send(port, "GET", "/v1/clips", host).status, 200) << host;
    EXPECT_EQ(Send(port, "GET", "/", host).status, 200) << host;
  }
  for (const std::string& host : std::vector<std::string>{
           "rebound.example:" + p, "rebound.example", "localhost.rebound.example:" + p,
           "127.0.0.1.rebound.example:" + p, "[::1", ":" + p, "127.0.0.1:0", ""}) {
    for (const std::string& path :
         std::vector<std::string>{"/v1/clips", "/v1/info", "/", "/assets/app.js", "/metrics"}) {
      const Answer answer = Send(port, "GET", path, host);
      EXPECT_EQ(answer.status, 421) << host << " " << path;
      EXPECT_THAT(answer.body, HasSubstr("does not name this server")) << host;
      EXPECT_THAT(answer.body, HasSubstr("--http-allowed-hosts")) << host;
      EXPECT_THAT(answer.body, HasSubstr("\"code\":7")) << host;
    }
    // Probes name hosts as they please; health tells nothing.
    EXPECT_EQ(Send(port, "GET", "/healthz", host).status, 200) << host;
    EXPECT_EQ(Send(port, "GET", "/readyz", host).status, 200) << host;
  }

  // Names the operator lists, on any port; "*" takes any name.
  servers_.clear();
  server = Start({"--http-allowed-hosts", "Studio.Example, db.example"});
  ASSERT_NE(server, nullptr);
  const int listed = server->http_port();
  EXPECT_EQ(Send(listed, "GET", "/v1/clips", "studio.example:1234").status, 200);
  EXPECT_EQ(Send(listed, "GET", "/v1/clips", "studio.example").status, 200);
  EXPECT_EQ(Send(listed, "GET", "/v1/clips", "DB.example:8443").status, 200);
  EXPECT_EQ(Send(listed, "GET", "/v1/clips", "rebound.example").status, 421);
  EXPECT_EQ(Send(listed, "GET", "/v1/clips", "localhost:8080").status, 200);
  servers_.clear();
  server = Start({"--http-allowed-hosts", "*"});
  ASSERT_NE(server, nullptr);
  EXPECT_EQ(Send(server->http_port(), "GET", "/v1/clips", "rebound.example").status, 200);

  ExpectRefusedFlag({"--http-allowed-hosts", "studio example"},
                    "--http-allowed-hosts: 'studio example' is not a host name or address");
  ExpectRefusedFlag({"--http-allowed-hosts", "db.example:8443"}, "no port");
  ExpectRefusedFlag({"--http-allowed-hosts", "::1"}, "an IPv6 address in brackets");
}

// CORS is off by default: no page of another origin may call the API, and no answer carries an
// Access-Control-* header. --http-cors-origins lets the pages of the origins it lists call it.
TEST_F(HttpRequestChecksTest, CorsIsOffUnlessAnOriginIsListed) {
  testing::ServerProcess* server = Start();
  ASSERT_NE(server, nullptr);
  int port = server->http_port();
  std::string host = absl::StrCat("127.0.0.1:", port);
  const std::vector<std::string> preflight = {"Origin: http://app.example:5173",
                                              "Access-Control-Request-Method: POST",
                                              "Access-Control-Request-Headers: content-type"};
  Answer answer = Send(port, "OPTIONS", "/v1/labels", host, preflight);
  EXPECT_EQ(answer.status, 403);
  EXPECT_THAT(answer.body, HasSubstr("--http-cors-origins"));
  EXPECT_FALSE(answer.AnyCors());
  answer = Send(port, "GET", "/v1/clips", host, {"Origin: http://app.example:5173"});
  EXPECT_EQ(answer.status, 200);
  EXPECT_FALSE(answer.AnyCors());

  servers_.clear();
  server = Start({"--http-cors-origins", "http://app.example:5173,https://studio.example"});
  ASSERT_NE(server, nullptr);
  port = server->http_port();
  host = absl::StrCat("127.0.0.1:", port);
  answer = Send(port, "OPTIONS", "/v1/labels", host, preflight);
  EXPECT_EQ(answer.status, 204) << answer.body;
  EXPECT_EQ(answer.Header("access-control-allow-origin"), "http://app.example:5173");
  EXPECT_THAT(answer.Header("access-control-allow-methods"), HasSubstr("POST"));
  EXPECT_THAT(answer.Header("access-control-allow-headers"), HasSubstr("Content-Type"));
  EXPECT_THAT(answer.Header("access-control-allow-headers"), HasSubstr("Authorization"));
  EXPECT_EQ(answer.Header("vary"), "Origin");
  answer = Send(port, "GET", "/v1/clips", host, {"Origin: https://studio.example"});
  EXPECT_EQ(answer.status, 200);
  EXPECT_EQ(answer.Header("access-control-allow-origin"), "https://studio.example");
  // A listed origin's refused call is readable by its page too.
  answer = Send(port, "POST", "/v1/search", host,
                {"Origin: https://studio.example", "Content-Type: text/plain"}, "{}");
  EXPECT_EQ(answer.status, 415);
  EXPECT_EQ(answer.Header("access-control-allow-origin"), "https://studio.example");
  // Another origin is refused its preflight, and its answers carry no CORS header.
  answer = Send(port, "OPTIONS", "/v1/labels", host,
                {"Origin: http://rebound.example", "Access-Control-Request-Method: POST"});
  EXPECT_EQ(answer.status, 403);
  EXPECT_FALSE(answer.AnyCors());
  answer = Send(port, "GET", "/v1/clips", host, {"Origin: null"});
  EXPECT_EQ(answer.status, 200);
  EXPECT_FALSE(answer.AnyCors());

  ExpectRefusedFlag({"--http-cors-origins", "*"}, "--http-cors-origins: '*' is not an origin");
  ExpectRefusedFlag({"--http-cors-origins", "studio.example"}, "is not an origin");
  ExpectRefusedFlag({"--http-cors-origins", "https://studio.example/app"}, "is not an origin");
}

// /index.html%00.js was served with index.html's bytes as text/javascript: the file read was
// cut at the NUL, its type taken from what followed. A path holding a control character once
// decoded is refused; a file's type is its own name's.
TEST_F(HttpRequestChecksTest, AFilePathHoldingAControlCharacterIsRefused) {
  testing::ServerProcess* server = Start();
  ASSERT_NE(server, nullptr);
  const int port = server->http_port();
  const std::string host = absl::StrCat("127.0.0.1:", port);
  for (const std::string& path :
       std::vector<std::string>{"/index.html%00.js", "/index.html%00", "/assets/app.js%0a.html",
                                "/index.html%0d%0a.js", "/%7f", "/v1/clips%00"}) {
    const Answer answer = Send(port, "GET", path, host);
    EXPECT_EQ(answer.status, 400) << path;
    EXPECT_THAT(answer.body, HasSubstr("the path holds a control character")) << path;
    EXPECT_THAT(answer.Header("content-type"), Not(HasSubstr("javascript"))) << path;
  }
  EXPECT_EQ(Send(port, "GET", "/index.html%2500.js", host).status, 404);
  Answer answer = Send(port, "GET", "/index.html", host);
  EXPECT_EQ(answer.status, 200);
  EXPECT_THAT(answer.Header("content-type"), HasSubstr("text/html"));
  answer = Send(port, "GET", "/assets/app.js", host);
  EXPECT_EQ(answer.status, 200);
  EXPECT_THAT(answer.Header("content-type"), HasSubstr("text/javascript"));
}

}  // namespace
}  // namespace motiondb
