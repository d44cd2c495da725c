// Scoped tokens (util/token_file.h), who may call what (server/grpc/access_control.h,
// method_scopes.h) and the limit on failed authentications per client address.
#include "server/grpc/access_control.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <google/protobuf/descriptor.h>

#include "absl/strings/str_cat.h"

#include "motiondb/shard/v1/shard_service.pb.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "server/grpc/auth_failure_limiter.h"
#include "server/grpc/method_scopes.h"
#include "util/token_file.h"

namespace motiondb::server {
namespace {

std::string WriteTokenFile(const std::string& text) {
  const std::string path =
      (std::filesystem::temp_directory_path() /
       ("tokens_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
        ::testing::UnitTest::GetInstance()->current_test_info()->name()))
          .string();
  std::ofstream(path) << text;
  return path;
}

TEST(ScopedTokenFileTest, ReadsScopesAndKeepsABareTokenAllPowerful) {
  absl::StatusOr<std::vector<ScopedToken>> tokens = ReadScopedTokenFile(
      WriteTokenFile("# studio tokens\nread r-token\n\nwrite  w-token\nadmin a-token\n"));
  ASSERT_TRUE(tokens.ok()) << tokens.status();
  ASSERT_EQ(tokens->size(), 3u);
  EXPECT_EQ((*tokens)[0].scope, TokenScope::kRead);
  EXPECT_EQ((*tokens)[1].token, "w-token");
  EXPECT_EQ((*tokens)[2].scope, TokenScope::kAdmin);
  tokens = ReadScopedTokenFile(WriteTokenFile("  just-one-token \n"));
  ASSERT_TRUE(tokens.ok()) << tokens.status();
  EXPECT_EQ(tokens->at(0).scope, TokenScope::kAdmin);
}

TEST(ScopedTokenFileTest, BadFilesAreRefusedWithTheirLine) {
  const auto error = [](const std::string& text) {
    return std::string(ReadScopedTokenFile(WriteTokenFile(text)).status().message());
  };
  EXPECT_NE(error("read a\nroot b\n").find("line 2: unknown scope 'root'"), std::string::npos);
  // The cluster's scope is its own token's (--cluster-token-file), never a client's.
  EXPECT_NE(error("cluster c\n").find("line 1: unknown scope 'cluster'"), std::string::npos);
  EXPECT_NE(error("read a\nwrite a\n").find("line 2: this token is given twice"),
            std::string::npos);
  EXPECT_NE(error("read a b c\n").find("line 1: expected 'SCOPE TOKEN'"), std::string::npos);
  EXPECT_NE(error("read t\xc3\xa9\n").find("printable ASCII"), std::string::npos);
  EXPECT_NE(error("# nothing\n\n").find("no token"), std::string::npos);
  EXPECT_NE(error("bare\nread r\n").find("only alone"), std::string::npos);
}

AccessControl Access() {
  return AccessControl(AccessOptions{.tokens = {{TokenScope::kRead, "r"},
                                                {TokenScope::kWrite, "w"},
                                                {TokenScope::kAdmin, "a"},
                                                {TokenScope::kCluster, "c"}},
                                     .max_failures = 3});
}

TEST(AccessControlTest, ATokenMayDoWhatItsScopeHolds) {
  AccessControl access = Access();
  const auto decide = [&access](absl::string_view token, TokenScope needed) {
    return access.Decide("X", needed, "10.0.0.1", {token}, "header").status.error_code();
  };
  EXPECT_EQ(decide("Bearer r", TokenScope::kRead), grpc::StatusCode::OK);
  EXPECT_EQ(decide("Bearer r", TokenScope::kWrite), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_EQ(decide("Bearer w", TokenScope::kWrite), grpc::StatusCode::OK);
  EXPECT_EQ(decide("Bearer w", TokenScope::kAdmin), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_EQ(decide("bearer a", TokenScope::kAdmin), grpc::StatusCode::OK);
  EXPECT_EQ(decide("Bearer a", TokenScope::kCluster), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_EQ(decide("Bearer c", TokenScope::kCluster), grpc::StatusCode::OK);
  EXPECT_EQ(decide("Bearer c", TokenScope::kAdmin), grpc::StatusCode::OK);
  const AccessControl::Verdict denied =
      access.Decide("POST /v1/labels", TokenScope::kWrite, "10.0.0.1", {"Bearer r"}, "header");
  EXPECT_EQ(denied.status.error_message(),
            "this token's scope is 'read'; POST /v1/labels needs 'write'");
  // Several headers: the widest scope among them.
  EXPECT_EQ(access.ScopeOf({"Bearer nope", "Bearer w", "Bearer r"}), TokenScope::kWrite);
}

TEST(AccessControlTest, FailedAttemptsLockAnAddressOutAndOnlyIt) {
  AccessControl access = Access();
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(access.Decide("X", TokenScope::kRead, "10.0.0.9", {"Bearer guess"}, "header")
                  .status.error_code(),
              grpc::StatusCode::UNAUTHENTICATED);
  }
  const AccessControl::Verdict locked =
      access.Decide("X", TokenScope::kRead, "10.0.0.9", {"Bearer a"}, "header");
  EXPECT_EQ(locked.status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(locked.status.error_message().find("too many failed authentications from 10.0.0.9"),
            std::string::npos);
  EXPECT_TRUE(
      access.Decide("X", TokenScope::kRead, "10.0.0.8", {"Bearer a"}, "header").status.ok());
  // A permission refused is no failed authentication.
  for (int i = 0; i < 5; ++i) access.Decide("X", TokenScope::kAdmin, "10.0.0.7", {"Bearer r"}, "h");
  EXPECT_TRUE(access.Decide("X", TokenScope::kRead, "10.0.0.7", {"Bearer r"}, "h").status.ok());
}

TEST(AccessControlTest, WithoutTokensEverythingIsAllowed) {
  AccessControl open{AccessOptions{}};
  EXPECT_FALSE(open.enabled());
  const AccessControl::Verdict verdict = open.Decide("X", TokenScope::kAdmin, "a", {}, "header");
  EXPECT_TRUE(verdict.status.ok());
  EXPECT_EQ(verdict.scope, TokenScope::kAdmin);
}

TEST(AuthFailureLimiterTest, TheLockEndsWithItsWindowAndOldAddressesAreForgotten) {
  AuthFailureLimiter limiter(2, std::chrono::seconds(60));
  const auto t0 = AuthFailureLimiter::Clock::time_point{} + std::chrono::hours(1);
  limiter.Fail("a", t0);
  EXPECT_EQ(limiter.Blocked("a", t0).count(), 0);
  limiter.Fail("a", t0 + std::chrono::seconds(1));
  EXPECT_EQ(limiter.Blocked("a", t0 + std::chrono::seconds(10)).count(), 50);
  EXPECT_EQ(limiter.Blocked("a", t0 + std::chrono::seconds(60)).count(), 0);
  // A failure after the window starts a new one.
  limiter.Fail("a", t0 + std::chrono::seconds(61));
  EXPECT_EQ(limiter.Blocked("a", t0 + std::chrono::seconds(62)).count(), 0);
  for (size_t i = 0; i < AuthFailureLimiter::kMaxAddresses + 10; ++i) {
    limiter.Fail(std::to_string(i), t0 + std::chrono::seconds(100));
  }
  limiter.Fail("z", t0 + std::chrono::seconds(101));
  limiter.Fail("z", t0 + std::chrono::seconds(101));
  EXPECT_GT(limiter.Blocked("z", t0 + std::chrono::seconds(102)).count(), 0);
}

TEST(AccessControlTest, PeersAreCountedByAddress) {
  EXPECT_EQ(AddressOfPeer("ipv4:127.0.0.1:5555"), "127.0.0.1");
  EXPECT_EQ(AddressOfPeer("ipv6:[::1]:5555"), "::1");
  EXPECT_EQ(AddressOfPeer("ipv6:[::ffff:10.1.2.3]:5555"), "10.1.2.3");
}

// Every motiondb.v1 and motiondb.shard.v1 method has its scope written down: a new one is not
// silently admin.
TEST(MethodScopesTest, EveryMethodIsInTheTable) {
  // The generated pool holds the linked files.
  (void)v1::Clip::descriptor();
  (void)motiondb::shard::v1::StoreTakeRequest::descriptor();
  const auto* pool = google::protobuf::DescriptorPool::generated_pool();
  int methods = 0;
  for (const char* service :
       {"motiondb.v1.ClipService", "motiondb.v1.EditService", "motiondb.v1.JobService",
        "motiondb.v1.LabelService", "motiondb.v1.SearchService", "motiondb.v1.ServerService",
        "motiondb.v1.SpaceService", "motiondb.shard.v1.ShardService"}) {
    const google::protobuf::ServiceDescriptor* descriptor = pool->FindServiceByName(service);
    ASSERT_NE(descriptor, nullptr) << service;
    for (int i = 0; i < descriptor->method_count(); ++i) {
      const std::string method = absl::StrCat("/", service, "/", descriptor->method(i)->name());
      EXPECT_TRUE(HasScopeEntry(method)) << method;
      ++methods;
    }
  }
  EXPECT_GT(methods, 30);
  EXPECT_EQ(RequiredScope("/motiondb.v1.ClipService/DeleteClip"), TokenScope::kAdmin);
  EXPECT_EQ(RequiredScope("/motiondb.v1.Unknown/Thing"), TokenScope::kAdmin);
  EXPECT_EQ(RequiredScope("/motiondb.shard.v1.ShardService/StoreTake"), TokenScope::kCluster);
  EXPECT_EQ(RequiredScope("/motiondb.shard.v1.ShardService/UpdateClip"), TokenScope::kCluster);
}

}  // namespace
}  // namespace motiondb::server
