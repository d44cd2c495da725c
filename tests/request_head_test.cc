// What the HTTP face reads of a request before its body (server/http/request_head.h,
// server/http/head_checks.h): the head's limits, the body's length and rules, the scope a path
// needs.
#include "server/http/request_head.h"

#include <gtest/gtest.h>

#include <string>

#include "server/http/head_checks.h"

namespace motiondb::server {
namespace {

RequestHead Parsed(const std::string& text) {
  RequestHead head;
  EXPECT_EQ(ParseRequestHead(text, &head), HeadParse::kComplete) << text;
  return head;
}

TEST(RequestHeadTest, ParsesTheRequestLineAndFields) {
  const RequestHead head =
      Parsed("POST /v1/clips%2Fx?a=1 HTTP/1.1\r\nHost: h\r\nContent-Length:  12 \r\n\r\nbody");
  EXPECT_EQ(head.method, "POST");
  EXPECT_EQ(head.target, "/v1/clips%2Fx?a=1");
  EXPECT_EQ(head.path, "/v1/clips/x");
  EXPECT_EQ(head.Values("content-length").at(0), "12");
  EXPECT_EQ(
      head.bytes,
      std::string("POST /v1/clips%2Fx?a=1 HTTP/1.1\r\nHost: h\r\nContent-Length:  12 \r\n\r\n")
          .size());
  // Bare LF line ends, as RFC 9112 lets a server accept.
  EXPECT_EQ(Parsed("GET / HTTP/1.1\nHost: h\n\n").path, "/");
}

TEST(RequestHeadTest, WaitsForTheBlankLineWithinTheLimits) {
  RequestHead head;
  EXPECT_EQ(ParseRequestHead("GET / HTTP/1.1\r\nHost: h\r\n", &head), HeadParse::kIncomplete);
  const std::string big = "GET / HTTP/1.1\r\nX: " + std::string(kMaxRequestHeadBytes, 'a');
  EXPECT_EQ(ParseRequestHead(big, &head), HeadParse::kTooLarge);
  std::string many = "GET / HTTP/1.1\r\n";
  for (int i = 0; i <= kMaxRequestFields; ++i) many += "X-A: b\r\n";
  EXPECT_EQ(ParseRequestHead(many + "\r\n", &head), HeadParse::kTooLarge);
}

TEST(RequestHeadTest, RefusesWhatCouldSmuggleARequest) {
  RequestHead head;
  for (const char* bad :
       {"GET / HTTP/1.1\r\nHost h\r\n\r\n", "GET / HTTP/1.1\r\nHo st: h\r\n\r\n", "GET /\r\n\r\n",
        "GET / HTTP/2.0\r\n\r\n", "\r\nGET / HTTP/1.1\r\n\r\n"}) {
    EXPECT_EQ(ParseRequestHead(bad, &head), HeadParse::kMalformed) << bad;
  }
  std::string problem;
  EXPECT_FALSE(ContentLength(
      Parsed("POST / HTTP/1.1\r\nContent-Length: 3\r\nContent-Length: 4\r\n\r\n"), &problem));
  EXPECT_NE(problem.find("differ"), std::string::npos);
  EXPECT_FALSE(ContentLength(Parsed("POST / HTTP/1.1\r\nContent-Length: -3\r\n\r\n"), &problem));
  EXPECT_EQ(
      ContentLength(Parsed("POST / HTTP/1.1\r\nContent-Length: 3\r\nContent-Length: 3\r\n\r\n"),
                    &problem),
      3u);
  EXPECT_EQ(ContentLength(Parsed("GET / HTTP/1.1\r\n\r\n"), &problem), 0u);
}

TEST(RequestHeadTest, TheExpectFieldIsTakenOutOfWhatHttplibReads) {
  EXPECT_EQ(WithoutExpect("POST / HTTP/1.1\r\nExpect: 100-continue\r\nA: b\r\n\r\n"),
            "POST / HTTP/1.1\r\nA: b\r\n\r\n");
}

TEST(HeadChecksTest, ABodyComesOnlyWithALengthToARouteThatTakesOne) {
  const std::vector<std::regex> routes = BodyRoutePaths();
  const auto refusal = [&routes](const std::string& head, size_t max_body = 1000) {
    const std::optional<HttpRefusal> refused = RefuseBody(Parsed(head), max_body, routes);
    return refused ? refused->status : 0;
  };
  EXPECT_EQ(refusal("POST /v1/search HTTP/1.1\r\nContent-Length: 10\r\n\r\n"), 0);
  EXPECT_EQ(refusal("POST /v1/search HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n"), 411);
  EXPECT_EQ(refusal("POST /v1/search HTTP/1.1\r\n\r\n"), 411);
  EXPECT_EQ(
      refusal("POST /v1/search HTTP/1.1\r\nContent-Length: 5\r\nContent-Encoding: gzip\r\n\r\n"),
      415);
  EXPECT_EQ(refusal("POST /v1/search HTTP/1.1\r\nContent-Length: 1001\r\n\r\n"), 413);
  EXPECT_EQ(refusal("GET /v1/clips HTTP/1.1\r\nContent-Length: 5\r\n\r\n"), 413);
  EXPECT_EQ(refusal("GET /v1/clips HTTP/1.1\r\n\r\n"), 0);
}

TEST(HeadChecksTest, EachPathNeedsItsMethodsScope) {
  EXPECT_EQ(NeededScope("GET", "/v1/clips", false), TokenScope::kRead);
  EXPECT_EQ(NeededScope("HEAD", "/v1/clips/3/bvh", false), TokenScope::kRead);
  EXPECT_EQ(NeededScope("POST", "/v1/clips", false), TokenScope::kWrite);
  EXPECT_EQ(NeededScope("POST", "/v1/labels", false), TokenScope::kWrite);
  EXPECT_EQ(NeededScope("POST", "/v1/jobs", false), TokenScope::kWrite);
  EXPECT_EQ(NeededScope("DELETE", "/v1/clips/3", false), TokenScope::kAdmin);
  EXPECT_EQ(NeededScope("POST", "/v1/labels:delete", false), TokenScope::kAdmin);
  EXPECT_EQ(NeededScope("GET", "/metrics", false), TokenScope::kAdmin);
  EXPECT_EQ(NeededScope("GET", "/v1/nothing-here", false), TokenScope::kRead);
  EXPECT_EQ(NeededScope("GET", "/healthz", false), std::nullopt);
  EXPECT_EQ(NeededScope("GET", "/readyz", true), TokenScope::kRead);
  EXPECT_EQ(NeededScope("GET", "/index.html", false), std::nullopt);
}

}  // namespace
}  // namespace motiondb::server
