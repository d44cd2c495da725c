// The real server under what took it down or locked others out (issue 37): connection floods
// on both ports (per client address, in all, and out of descriptors), slow and silent HTTP
// clients, a full line of HTTP requests, request heads and bodies refused before they are read,
// upload streams that wait for bytes, and scoped tokens on both faces. Limits are lowered by
// their flags so that every case stays small. No assertion on time: each wait is on the
// server's own state (its metrics, its answers), bounded only so that a hang fails.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/server_fixture.h"

// After the fixture: httplib.h includes <resolv.h>, whose macro _res breaks Eigen's headers.
#include <httplib.h>

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using testing::ServerProcess;

// A client socket to 127.0.0.1:`port` from `source` (another loopback address is another
// client: its count of connections is the test's alone), closed when it goes.
class RawConnection {
 public:
  explicit RawConnection(int port, const char* source = "127.0.0.1")
      : fd_(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0)) {
    sockaddr_in from{};
    from.sin_family = AF_INET;
    inet_pton(AF_INET, source, &from.sin_addr);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<uint16_t>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = fd_ >= 0 && ::bind(fd_, reinterpret_cast<sockaddr*>(&from), sizeof(from)) == 0 &&
                 ::connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0;
  }
  RawConnection(RawConnection&& other) noexcept
      : fd_(std::exchange(other.fd_, -1)), connected_(other.connected_) {}
  ~RawConnection() {
    if (fd_ >= 0) ::close(fd_);
  }

  bool connected() const { return connected_; }
  bool Send(const std::string& bytes) {
    return ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL) ==
           static_cast<ssize_t>(bytes.size());
  }
  // What arrives until the server closes the connection (or 60 s pass without a byte: a hang).
  std::string ReadToEnd() {
    std::string text;
    char buffer[4096];
    for (;;) {
      pollfd watched{fd_, POLLIN, 0};
      if (::poll(&watched, 1, 60'000) <= 0) return text + "<no end>";
      const ssize_t got = ::recv(fd_, buffer, sizeof(buffer), 0);
      if (got <= 0) return text;
      text.append(buffer, static_cast<size_t>(got));
    }
  }
  // Reads until `text` holds `wanted` (or the connection ends).
  std::string ReadUntil(const std::string& wanted) {
    std::string text;
    char byte = 0;
    while (text.find(wanted) == std::string::npos && ::recv(fd_, &byte, 1, 0) == 1) text += byte;
    return text;
  }

 private:
  int fd_;
  bool connected_ = false;
};

// Whether the server's /metrics holds the line `line` (polled until it does, for a minute).
bool WaitForMetric(const ServerProcess& server, const std::string& line,
                   const std::string& token = "") {
  httplib::Client http("127.0.0.1", server.http_port());
  if (!token.empty()) http.set_bearer_token_auth(token);
  for (int i = 0; i < 6000; ++i) {
    const httplib::Result metrics = http.Get("/metrics");
    if (metrics && metrics->body.find("\n" + line + "\n") != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

// GetServerInfo over a new channel until it answers (a minute at most); its last status.
grpc::Status InfoEventually(const ServerProcess& server) {
  grpc::Status status;
  for (int i = 0; i < 600; ++i) {
    Client client(testing::InsecureChannel(server.address()));
    v1::ServerInfo info;
    status = client.server().GetServerInfo(client.Context(std::chrono::milliseconds(5000)).get(),
                                           v1::GetServerInfoRequest(), &info);
    if (status.ok()) return status;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return status;
}

// The status of GET `path`, 0 when no answer came; polled until it is `wanted` (a minute at
// most) when `wanted` is set.
int GetStatus(int port, const std::string& path, int wanted = 0) {
  int status = 0;
  for (int i = 0; i < 600; ++i) {
    httplib::Client http("127.0.0.1", port);
    const httplib::Result result = http.Get(path);
    status = result ? result->status : 0;
    if (wanted == 0 || status == wanted) return status;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return status;
}

int HttpStatus(const std::string& response) {
  return response.size() > 12 && response.rfind("HTTP/1.1 ", 0) == 0
             ? std::stoi(response.substr(9, 3))
             : 0;
}

class ServerLimitsTest : public ServerTest {};

// One client address holds at most --max-connections-per-peer connections on each port; past
// it new ones are closed (gRPC) or answered 503 (HTTP), while other addresses are served. The
// flood comes from 127.0.0.2, the test's other calls from 127.0.0.1. Connections are accepted
// in the order they were made, so the fifth of five is the one refused.
TEST_F(ServerLimitsTest, ConnectionsPerClientAddressAreBoundedOnBothPorts) {
  ServerProcess* server = StartServer({"--max-connections-per-peer", "4"});
  ASSERT_NE(server, nullptr);
  constexpr char kFlooder[] = "127.0.0.2";
  {
    std::vector<RawConnection> held;
    for (int i = 0; i < 4; ++i) held.emplace_back(server->port(), kFlooder);
    RawConnection fifth(server->port(), kFlooder);
    ASSERT_TRUE(fifth.connected());
    EXPECT_EQ(fifth.ReadToEnd(), "");                            // closed at once
    EXPECT_TRUE(InfoEventually(*server).ok()) << server->Log();  // another address
  }
  std::vector<RawConnection> held;
  for (int i = 0; i < 4; ++i) held.emplace_back(server->http_port(), kFlooder);
  RawConnection fifth(server->http_port(), kFlooder);
  const std::string answer = fifth.ReadToEnd();
  EXPECT_EQ(HttpStatus(answer), 503) << answer;
  EXPECT_THAT(answer, HasSubstr("127.0.0.2 holds 4 connections, the most one client may"));
  EXPECT_EQ(GetStatus(server->http_port(), "/healthz"), 200);
  // Places come back as connections close.
  held.clear();
  for (int i = 0; i < 600; ++i) {
    RawConnection again(server->http_port(), kFlooder);
    again.Send("GET /healthz HTTP/1.1\r\nConnection: close\r\n\r\n");
    if (HttpStatus(again.ReadToEnd()) == 200) break;
    ASSERT_LT(i, 599) << "the flooder's places never came back";
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_THAT(server->Log(), HasSubstr("(127.0.0.2 holds 4 connections, the most one client may)"));
}

// The probe: ~20,000 idle connections exhausted the descriptors and left the gRPC port dead
// until a restart while /healthz and /readyz said ok. Here the server runs with 200 descriptors
// and limits set above what they hold (so that the flood does run them out); after the flood,
// both ports take connections again.
TEST_F(ServerLimitsTest, PortsSurviveAConnectionFloodThatRunsOutOfDescriptors) {
  auto server = std::make_unique<ServerProcess>();
  server->LimitOpenFiles(200);
  std::string error;
  ASSERT_TRUE(server->Start({"--db", db_, "--max-connections", "1000", "--http-max-connections",
                             "1000", "--max-connections-per-peer", "1000"},
                            &error))
      << error;
  ASSERT_TRUE(testing::WaitUntilServing(testing::InsecureChannel(server->address()), ""));
  {
    std::vector<RawConnection> flood;
    for (int i = 0; i < 150; ++i) {
      flood.emplace_back(server->port());
      flood.emplace_back(server->http_port());
    }
    // Until the server has run out and said so.
    for (int i = 0; i < 6000 && server->Log().find("Too many open files") == std::string::npos;
         ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    EXPECT_THAT(server->Log(), HasSubstr("cannot accept a connection: Too many open files"));
  }
  EXPECT_TRUE(InfoEventually(*server).ok()) << server->Log();
  EXPECT_EQ(GetStatus(server->http_port(), "/readyz", 200), 200);
  EXPECT_EQ(server->Stop(SIGTERM), 0) << server->Log();
}

// Under the open-file limit, the default connection limits are lowered to what it holds.
TEST_F(ServerLimitsTest, DefaultLimitsFitTheOpenFileLimit) {
  ServerProcess server;
  server.LimitOpenFiles(400);
  std::string error;
  ASSERT_TRUE(server.Start({"--db", db_}, &error)) << error;
  EXPECT_THAT(server.Log(), HasSubstr("the open-file limit (400) holds 272 connections"));
}

// /readyz says not ready while the gRPC port takes no connection (here: every place taken).
TEST_F(ServerLimitsTest, ReadinessFollowsWhetherTheGrpcPortTakesConnections) {
  ServerProcess* server = StartServer({"--max-connections", "2"});
  ASSERT_NE(server, nullptr);
  {
    RawConnection a(server->port()), b(server->port());
    ASSERT_TRUE(WaitForMetric(*server, "motiondb_connections{face=\"grpc\"} 2")) << server->Log();
    EXPECT_EQ(GetStatus(server->http_port(), "/readyz"), 503);
  }
  EXPECT_EQ(GetStatus(server->http_port(), "/readyz", 200), 200);
}

// The probe: 16 clients sending a header byte a second held every HTTP worker, /healthz
// included, and kept SIGTERM from ending the server for 110 s. Now a half-sent request holds no
// worker, SIGTERM ends the server with the slow clients still connected, and a request that
// does not arrive whole in time is answered 408.
TEST_F(ServerLimitsTest, SlowHttpClientsHoldNoWorker) {
  ServerProcess* server = StartServer({"--http-threads", "2", "--http-request-timeout-s", "600"});
  ASSERT_NE(server, nullptr);
  std::vector<RawConnection> slow;
  for (int i = 0; i < 16; ++i) {
    slow.emplace_back(server->http_port(), "127.0.0.2");
    ASSERT_TRUE(slow.back().Send("GET /healthz HTTP/1.1\r\nHo"));
  }
  // The 16 and the scrape's own.
  ASSERT_TRUE(WaitForMetric(*server, "motiondb_connections{face=\"http\"} 17")) << server->Log();
  httplib::Client http("127.0.0.1", server->http_port());
  const httplib::Result health = http.Get("/healthz");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);
  RawConnection trickle(server->http_port());
  ASSERT_TRUE(trickle.Send("POST /v1/search HTTP/1.1\r\nContent-Length: 100\r\n\r\n{"));
  EXPECT_EQ(server->Stop(SIGTERM), 0) << server->Log();

  ServerProcess* strict = StartServer({"--http-request-timeout-s", "1"});
  ASSERT_NE(strict, nullptr);
  RawConnection late(strict->http_port());
  ASSERT_TRUE(late.Send("GET /healthz HTTP/1.1\r\nHo"));
  const std::string answer = late.ReadToEnd();
  EXPECT_EQ(HttpStatus(answer), 408) << answer;
  EXPECT_THAT(answer, HasSubstr("did not arrive in time"));
}

// Requests that arrived whole wait for a worker in a bounded line; one that finds it full is
// refused with 503 at once rather than queued behind slow work. The one worker here is kept busy
// writing a large file to a client that does not read it.
TEST_F(ServerLimitsTest, AFullLineOfRequestsIsRefusedWith503) {
  const std::filesystem::path web = dir_ / "web";
  std::filesystem::create_directories(web);
  std::ofstream(web / "index.html") << "<html></html>";
  std::ofstream(web / "big.bin", std::ios::binary) << std::string(64 << 20, 'x');
  ServerProcess* server =
      StartServer({"--http-threads", "1", "--http-max-waiting", "0", "--web-root", web.string()});
  ASSERT_NE(server, nullptr);
  RawConnection reader(server->http_port());
  ASSERT_TRUE(reader.Send("GET /big.bin HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"));
  // Its answer has begun: the worker is writing 64 MB that nobody reads.
  EXPECT_THAT(reader.ReadUntil("\r\n\r\n"), HasSubstr("200 OK"));
  RawConnection second(server->http_port());
  ASSERT_TRUE(second.Send("GET /healthz HTTP/1.1\r\nHost: x\r\n\r\n"));
  const std::string answer = second.ReadToEnd();
  EXPECT_EQ(HttpStatus(answer), 503) << answer;
  EXPECT_THAT(answer, HasSubstr("--http-max-waiting"));
  EXPECT_THAT(answer, HasSubstr("Retry-After: 1"));
}

// Heads are bounded (200 MB of headers once took 300 MB), and a body is refused before it is
// read: without the token, past the uploads' budget, or too large.
TEST_F(ServerLimitsTest, HeadsAndBodiesAreRefusedBeforeTheyAreRead) {
  const std::string token_file = WriteFile("tokens", "admin good-token\n");
  ServerProcess* server =
      StartServer({"--auth-token-file", token_file, "--max-upload-buffer-mb", "1"});
  ASSERT_NE(server, nullptr);
  {
    RawConnection big_head(server->http_port());
    big_head.Send("GET /healthz HTTP/1.1\r\n");
    for (int i = 0; i < 20; ++i) big_head.Send("X-Filler: " + std::string(5000, 'a') + "\r\n");
    const std::string answer = big_head.ReadToEnd();
    EXPECT_EQ(HttpStatus(answer), 431) << answer;
  }
  // What a request of this head (its body announced, none sent) is answered.
  const auto answer_to = [&server](const std::string& head) {
    RawConnection connection(server->http_port());
    connection.Send(head);
    return connection.ReadToEnd();
  };
  // 300 MB announced without the token: the refusal does not wait for them.
  std::string answer = answer_to(
      "POST /v1/search HTTP/1.1\r\nContent-Type: application/json\r\n"
      "Content-Length: 300000000\r\n\r\n");
  EXPECT_EQ(HttpStatus(answer), 401) << answer;
  EXPECT_THAT(answer, HasSubstr("WWW-Authenticate: Bearer"));
  answer = answer_to(
      "POST /v1/search HTTP/1.1\r\nAuthorization: Bearer good-token\r\n"
      "Content-Type: application/json\r\nContent-Length: 2000000\r\n\r\n");
  EXPECT_EQ(HttpStatus(answer), 503) << answer;
  EXPECT_THAT(answer, HasSubstr("--max-upload-buffer-mb"));
  {
    // Expect: 100-continue is answered once the body is wanted, and the request goes on.
    RawConnection expect(server->http_port());
    expect.Send(
        "POST /v1/search HTTP/1.1\r\nAuthorization: Bearer good-token\r\n"
        "Content-Type: application/json\r\nExpect: 100-continue\r\n"
        "Content-Length: 2\r\nConnection: close\r\n\r\n");
    EXPECT_THAT(expect.ReadUntil("\r\n\r\n"), HasSubstr("100 Continue"));
  }
}

// The probe: with --threads 4, 8 idle upload streams locked GetServerInfo out, and 32 streams
// sending a byte every 20 s kept every ingest out. A stream waiting for bytes holds no call
// slot, and one slower than --min-upload-kbps (after --http-request-timeout-s) is ended.
TEST_F(ServerLimitsTest, UploadStreamsWaitingForBytesHoldNoSlotAndCrawlersAreEnded) {
  const auto open_stream = [](Client& client, grpc::ClientContext* context,
                              v1::IngestClipResponse* response) {
    auto writer = client.clips().IngestClipStream(context, response);
    v1::IngestClipStreamRequest first;
    first.set_file_name("slow.bvh");
    first.set_chunk("HIERARCHY\n");
    EXPECT_TRUE(writer->Write(first));
    return writer;
  };
  ServerProcess* server = StartServer(
      {"--threads", "1", "--stream-idle-timeout-s", "0", "--http-request-timeout-s", "600"});
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  auto context = client.Context();
  v1::IngestClipResponse response;
  auto writer = open_stream(client, context.get(), &response);
  ASSERT_TRUE(WaitForMetric(*server, "motiondb_uploads_in_progress 1")) << server->Log();
  v1::ServerInfo info;
  const grpc::Status status =
      client.server().GetServerInfo(client.Context().get(), v1::GetServerInfoRequest(), &info);
  EXPECT_TRUE(status.ok()) << status.error_message();
  context->TryCancel();
  writer->Finish();

  ServerProcess* strict = StartServer({"--stream-idle-timeout-s", "0", "--min-upload-kbps", "1000",
                                       "--http-request-timeout-s", "1"});
  ASSERT_NE(strict, nullptr);
  Client crawler(testing::InsecureChannel(strict->address()));
  auto crawl_context = crawler.Context();
  auto crawling = open_stream(crawler, crawl_context.get(), &response);
  const grpc::Status ended = crawling->Finish();
  EXPECT_EQ(ended.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  EXPECT_THAT(ended.error_message(), HasSubstr("--min-upload-kbps"));
}

// Scoped tokens: read, write and admin on both faces; GetServerInfo says which the caller holds.
TEST_F(ServerLimitsTest, TokensMayDoWhatTheirScopeHolds) {
  const std::string token_file =
      WriteFile("tokens", "# studio\nread r-token\nwrite w-token\nadmin a-token\n");
  ServerProcess* server = StartServer({"--auth-token-file", token_file});
  ASSERT_NE(server, nullptr);
  const auto channel = testing::InsecureChannel(server->address());
  Client reader(channel, "r-token"), writer(channel, "w-token"), admin(channel, "a-token");
  v1::ServerInfo info;
  ASSERT_TRUE(reader.server()
                  .GetServerInfo(reader.Context().get(), v1::GetServerInfoRequest(), &info)
                  .ok());
  EXPECT_EQ(info.scope(), "read");
  v1::ListClipsResponse clips;
  EXPECT_TRUE(
      reader.clips().ListClips(reader.Context().get(), v1::ListClipsRequest(), &clips).ok());
  v1::IngestClipResponse ingested;
  const grpc::Status denied = reader.Ingest("chain.bvh", BvhText(ChainClip()), &ingested);
  EXPECT_EQ(denied.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_EQ(denied.error_message(),
            "this token's scope is 'read'; /motiondb.v1.ClipService/IngestClip needs 'write'");
  const int64_t clip_id = writer.IngestOrFail("chain.bvh", BvhText(ChainClip()));
  v1::DeleteClipRequest remove;
  remove.set_clip_id(clip_id);
  v1::DeleteClipResponse removed;
  const grpc::Status not_admin =
      writer.clips().DeleteClip(writer.Context().get(), remove, &removed);
  EXPECT_EQ(not_admin.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_THAT(not_admin.error_message(), HasSubstr("needs 'admin'"));
  EXPECT_TRUE(admin.clips().DeleteClip(admin.Context().get(), remove, &removed).ok());
  // Without a token: refused in the service, its log line naming the peer.
  Client anonymous(channel);
  EXPECT_EQ(anonymous.clips()
                .ListClips(anonymous.Context().get(), v1::ListClipsRequest(), &clips)
                .error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_THAT(server->Log(), HasSubstr("/motiondb.v1.ClipService/ListClips UNAUTHENTICATED"));
  EXPECT_THAT(server->Log(), ::testing::ContainsRegex(
                                 "ListClips UNAUTHENTICATED [0-9.]+ms ipv4:127\\.0\\.0\\.1:"));

  httplib::Client http("127.0.0.1", server->http_port());
  http.set_bearer_token_auth("r-token");
  const httplib::Result listed = http.Get("/v1/clips");
  ASSERT_TRUE(listed);
  EXPECT_EQ(listed->status, 200);
  const httplib::Result shown = http.Get("/v1/info");
  ASSERT_TRUE(shown);
  EXPECT_THAT(shown->body, HasSubstr("\"scope\":\"read\""));
  const httplib::Result label = http.Post("/v1/labels", R"({"labels":[]})", "application/json");
  ASSERT_TRUE(label);
  EXPECT_EQ(label->status, 403);
  EXPECT_THAT(label->body, HasSubstr("POST /v1/labels needs 'write'"));
  EXPECT_EQ(http.Get("/metrics")->status, 403);
  http.set_bearer_token_auth("a-token");
  EXPECT_EQ(http.Get("/metrics")->status, 200);
  http.set_bearer_token_auth("wrong");
  const httplib::Result wrong = http.Get("/v1/clips");
  ASSERT_TRUE(wrong);
  EXPECT_EQ(wrong->status, 401);
  EXPECT_THAT(server->Log(), HasSubstr("GET /v1/clips UNAUTHENTICATED"));
}

// Failed authentications from one address, on either face, lock it out for a while; the token
// is then not even looked at.
TEST_F(ServerLimitsTest, FailedAuthenticationsFromAnAddressAreLimited) {
  const std::string token_file = WriteFile("tokens", "good-token\n");
  ServerProcess* server = StartServer({"--auth-token-file", token_file});
  ASSERT_NE(server, nullptr);
  const auto channel = testing::InsecureChannel(server->address());
  Client guesser(channel, "guess");
  v1::ServerInfo info;
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(guesser.server()
                  .GetServerInfo(guesser.Context().get(), v1::GetServerInfoRequest(), &info)
                  .error_code(),
              grpc::StatusCode::UNAUTHENTICATED);
  }
  httplib::Client http("127.0.0.1", server->http_port());
  http.set_bearer_token_auth("guess");
  for (int i = 0; i < 5; ++i) EXPECT_EQ(http.Get("/v1/info")->status, 401);
  Client good(channel, "good-token");
  const grpc::Status locked =
      good.server().GetServerInfo(good.Context().get(), v1::GetServerInfoRequest(), &info);
  EXPECT_EQ(locked.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(locked.error_message(), HasSubstr("too many failed authentications from 127.0.0.1"));
  http.set_bearer_token_auth("good-token");
  EXPECT_EQ(http.Get("/v1/info")->status, 429);
}

}  // namespace
}  // namespace motiondb
