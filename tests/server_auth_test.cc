// Authentication, TLS and reflection on the real server binary (server_fixture.h).
#include <gmock/gmock.h>
#include <google/protobuf/descriptor.pb.h>
#include <google/protobuf/unknown_field_set.h>
#include <grpcpp/generic/generic_stub.h>
#include <gtest/gtest.h>

#include "grpc/health/v1/health.grpc.pb.h"
#include "testing/server_process.h"
#include "tests/server_fixture.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using testing::ServerProcess;

// Calls /grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo with one request (raw
// protobuf bytes) and returns the response's bytes. The reflection messages are not compiled
// into the test (libgrpc++_reflection holds their generated code, without headers), so they are
// read as unknown fields.
grpc::Status Reflect(const std::shared_ptr<grpc::Channel>& channel, const std::string& token,
                     const std::string& request, std::string* response) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
  const grpc::internal::RpcMethod method(
      "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo",
      grpc::internal::RpcMethod::BIDI_STREAMING, channel);
  std::unique_ptr<grpc::ClientReaderWriter<grpc::ByteBuffer, grpc::ByteBuffer>> stream(
      grpc::internal::ClientReaderWriterFactory<grpc::ByteBuffer, grpc::ByteBuffer>::Create(
          channel.get(), method, &context));
  grpc::Slice slice(request);
  stream->Write(grpc::ByteBuffer(&slice, 1));
  stream->WritesDone();
  grpc::ByteBuffer reply;
  if (stream->Read(&reply)) {
    std::vector<grpc::Slice> slices;
    (void)reply.Dump(&slices);
    for (const grpc::Slice& s : slices) {
      response->append(reinterpret_cast<const char*>(s.begin()), s.size());
    }
  }
  return stream->Finish();
}

// Length-delimited fields `number` of a message's bytes.
std::vector<std::string> Fields(const std::string& bytes, int number) {
  google::protobuf::UnknownFieldSet fields;
  std::vector<std::string> out;
  if (!fields.ParseFromString(bytes)) return out;
  for (int i = 0; i < fields.field_count(); ++i) {
    if (fields.field(i).number() == number &&
        fields.field(i).type() == google::protobuf::UnknownField::TYPE_LENGTH_DELIMITED) {
      out.push_back(fields.field(i).length_delimited());
    }
  }
  return out;
}

std::string StringField(int number, const std::string& value) {
  std::string out(1, static_cast<char>(number << 3 | 2));
  out.push_back(static_cast<char>(value.size()));  // short values only
  return out + value;
}

TEST_F(ServerTest, ReflectionListsAndDescribesTheServices) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  const auto channel = testing::InsecureChannel(server->address());
  // list_services (field 7) -> list_services_response (6) -> service (1) -> name (1).
  std::string response;
  grpc::Status status = Reflect(channel, "", StringField(7, "*"), &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  std::vector<std::string> names;
  for (const std::string& list : Fields(response, 6)) {
    for (const std::string& service : Fields(list, 1)) {
      for (const std::string& name : Fields(service, 1)) names.push_back(name);
    }
  }
  EXPECT_THAT(names,
              ::testing::IsSupersetOf({"motiondb.v1.ClipService", "motiondb.v1.SpaceService",
                                       "motiondb.v1.SearchService", "motiondb.v1.ServerService",
                                       "motiondb.v1.LabelService", "motiondb.v1.JobService",
                                       "grpc.health.v1.Health"}));
  // file_containing_symbol (4) -> file_descriptor_response (4) -> file_descriptor_proto (1).
  for (const auto& [symbol, file] : std::vector<std::pair<std::string, std::string>>{
           {"grpc.health.v1.Health", "grpc/health/v1/health.proto"},
           {"motiondb.v1.SearchService", "motiondb/v1/search_service.proto"}}) {
    response.clear();
    status = Reflect(channel, "", StringField(4, symbol), &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    std::vector<std::string> files;
    for (const std::string& descriptors : Fields(response, 4)) {
      for (const std::string& bytes : Fields(descriptors, 1)) {
        google::protobuf::FileDescriptorProto descriptor;
        ASSERT_TRUE(descriptor.ParseFromString(bytes));
        files.push_back(descriptor.name());
      }
    }
    EXPECT_THAT(files, ::testing::Contains(file)) << symbol;
  }
}

TEST_F(ServerTest, BearerTokenIsRequiredOnEveryCall) {
  const std::string token_file = WriteFile("token", "s3cret-token\n");
  ServerProcess* server = StartServer({"--auth-token-file", token_file}, "s3cret-token");
  ASSERT_NE(server, nullptr);
  const auto channel = testing::InsecureChannel(server->address());
  const v1::GetServerInfoRequest request;
  v1::ServerInfo info;
  for (const std::string& token : {std::string(""), std::string("wrong"),
                                   std::string("s3cret-tokenX"), std::string("s3cret-toke")}) {
    Client client(channel, token);
    const grpc::Status status =
        client.server().GetServerInfo(client.Context().get(), request, &info);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED) << "'" << token << "'";
  }
  Client good(channel, "s3cret-token");
  ASSERT_TRUE(good.server().GetServerInfo(good.Context().get(), request, &info).ok());
  EXPECT_TRUE(info.auth_required());
  // Reflection too; the health service answers probes without the token.
  auto health = grpc::health::v1::Health::NewStub(channel);
  grpc::ClientContext context;
  grpc::health::v1::HealthCheckResponse serving;
  ASSERT_TRUE(health->Check(&context, grpc::health::v1::HealthCheckRequest(), &serving).ok());
  EXPECT_EQ(serving.status(), grpc::health::v1::HealthCheckResponse::SERVING);
  std::string response;
  EXPECT_EQ(Reflect(channel, "", StringField(7, "*"), &response).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_TRUE(Reflect(channel, "s3cret-token", StringField(7, "*"), &response).ok());
  EXPECT_THAT(server->Log(), HasSubstr("/motiondb.v1.ServerService/GetServerInfo UNAUTHENTICATED"));

  // --health-needs-token: probes need it too.
  ServerProcess* strict =
      StartServer({"--auth-token-file", token_file, "--health-needs-token"}, "s3cret-token");
  ASSERT_NE(strict, nullptr);
  auto strict_health =
      grpc::health::v1::Health::NewStub(testing::InsecureChannel(strict->address()));
  grpc::ClientContext strict_context;
  EXPECT_EQ(strict_health->Check(&strict_context, grpc::health::v1::HealthCheckRequest(), &serving)
                .error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
}

TEST_F(ServerTest, ServesTls) {
  const absl::StatusOr<testing::TlsFiles> tls = testing::MakeTlsCertificate(dir_);
  if (absl::IsNotFound(tls.status())) GTEST_SKIP() << tls.status().message();
  ASSERT_TRUE(tls.ok()) << tls.status();
  const std::string& cert = tls->cert;
  const std::string& key = tls->key;
  const std::string token_file = WriteFile("token", "tls-token");
  ServerProcess* server =
      StartServer({"--tls-cert", cert, "--tls-key", key, "--auth-token-file", token_file},
                  "tls-token", /*tls=*/true);
  ASSERT_NE(server, nullptr);

  grpc::SslCredentialsOptions ssl;
  ssl.pem_root_certs = testing::ReadFileOrDie(cert);
  grpc::ChannelArguments arguments;
  arguments.SetSslTargetNameOverride("localhost");
  Client client(grpc::CreateCustomChannel(server->address(), grpc::SslCredentials(ssl), arguments),
                "tls-token");
  v1::ServerInfo info;
  const grpc::Status status =
      client.server().GetServerInfo(client.Context().get(), v1::GetServerInfoRequest(), &info);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_TRUE(info.tls());
  // A plain-text client cannot talk to it.
  Client plain(testing::InsecureChannel(server->address()), "tls-token");
  EXPECT_FALSE(plain.server()
                   .GetServerInfo(plain.Context(std::chrono::milliseconds(2000)).get(),
                                  v1::GetServerInfoRequest(), &info)
                   .ok());
  // One of the pair alone is a usage error.
  ServerProcess half;
  std::string error;
  EXPECT_FALSE(half.Start({"--db", db_, "--tls-cert", cert}, &error));
  EXPECT_THAT(error, HasSubstr("--tls-key"));
}

}  // namespace
}  // namespace motiondb
