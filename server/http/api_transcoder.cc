#include "server/http/api_transcoder.h"

#include <future>
#include <set>

#include <grpcpp/client_context.h>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "grpc/health/v1/health.pb.h"
#include "motiondb/v1/clip_service.pb.h"
#include "server/grpc/access_control.h"
#include "server/grpc/request_logger.h"
#include "server/http/http_status.h"
#include "server/http/json_answer.h"
#include "server/http/json_transcoding.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

using google::protobuf::Message;
using google::protobuf::MethodDescriptor;

std::unique_ptr<Message> NewMessage(const google::protobuf::Descriptor* type) {
  return std::unique_ptr<Message>(
      google::protobuf::MessageFactory::generated_factory()->GetPrototype(type)->New());
}

HttpReply ErrorReply(grpc::StatusCode code, absl::string_view message) {
  HttpReply reply;
  reply.status = HttpStatusOf(code);
  reply.body = ErrorJson(code, message);
  return reply;
}

// Content-Disposition for a download: the plain-ASCII name for old clients and the exact one
// percent-encoded (RFC 6266, 5987).
std::string Attachment(absl::string_view file_name) {
  std::string ascii, encoded;
  for (const unsigned char c : file_name) {
    const bool plain = absl::ascii_isalnum(c) || c == '.' || c == '_' || c == '-';
    ascii += plain ? static_cast<char>(c) : '_';
    absl::StrAppend(&encoded,
                    plain ? std::string(1, static_cast<char>(c)) : absl::StrFormat("%%%02X", c));
  }
  return absl::StrCat("attachment; filename=\"", ascii, "\"; filename*=UTF-8''", encoded);
}

// An export's media type, by the extension of the file name it suggests.
std::string ContentType(absl::string_view file_name) {
  if (absl::EndsWith(file_name, ".glb")) return "model/gltf-binary";
  if (absl::EndsWith(file_name, ".gltf")) return "model/gltf+json";
  return "text/plain; charset=utf-8";
}

// A file whose request did not convert: no call, the error its reply.
class RefusedFile final : public FileStream {
 public:
  explicit RefusedFile(HttpReply error) : error_(std::move(error)) {}
  const HttpReply& head() const override { return error_; }
  bool Next(std::string*) override { return false; }
  bool ok() const override { return false; }

 private:
  HttpReply error_;
};

class ExportStream final : public FileStream {
 public:
  // `context` prepared (deadline, peer); reads the first message.
  ExportStream(std::unique_ptr<grpc::ClientContext> context, v1::ClipService::Stub& stub,
               const v1::ExportClipRequest& request)
      : context_(std::move(context)), reader_(stub.ExportClipStream(context_.get(), request)) {
    if (!reader_->Read(&message_)) {
      Finish();
      const grpc::Status status =
          status_.ok() ? grpc::Status(grpc::StatusCode::INTERNAL, "the export sent nothing")
                       : status_;
      head_ = ErrorReply(status.error_code(), status.error_message());
      return;
    }
    head_.content_type = ContentType(message_.file_name());
    head_.headers.push_back({"Content-Disposition", Attachment(message_.file_name())});
    pending_ = std::move(*message_.mutable_bvh());
  }

  ~ExportStream() override {
    if (finished_) return;
    context_->TryCancel();
    while (reader_->Read(&message_)) {
    }
    Finish();
  }

  const HttpReply& head() const override { return head_; }

  bool Next(std::string* piece) override {
    while (pending_.empty()) {
      if (finished_ || !reader_->Read(&message_)) {
        Finish();
        return false;
      }
      pending_ = std::move(*message_.mutable_bvh());
    }
    *piece = std::move(pending_);
    pending_.clear();
    return true;
  }

  bool ok() const override { return finished_ && status_.ok(); }

 private:
  void Finish() {
    if (finished_) return;
    finished_ = true;
    status_ = reader_->Finish();
  }

  std::unique_ptr<grpc::ClientContext> context_;
  std::unique_ptr<grpc::ClientReader<v1::ExportClipResponse>> reader_;
  v1::ExportClipResponse message_;
  HttpReply head_;
  std::string pending_;  // a piece read and not yet given
  bool finished_ = false;
  grpc::Status status_;
};

}  // namespace

ApiTranscoder::ApiTranscoder(std::shared_ptr<grpc::Channel> channel, double call_timeout_s,
                             int64_t max_answer_bytes)
    : stub_(channel),
      clips_(v1::ClipService::NewStub(channel)),
      call_timeout_(call_timeout_s),
      max_answer_bytes_(max_answer_bytes) {}

absl::StatusOr<std::unique_ptr<ApiTranscoder>> ApiTranscoder::Create(
    std::shared_ptr<grpc::Channel> channel, double call_timeout_s, int64_t max_answer_bytes) {
  auto transcoder = std::unique_ptr<ApiTranscoder>(
      new ApiTranscoder(std::move(channel), call_timeout_s, max_answer_bytes));
  for (const ApiRoute& route : ApiRoutes()) {
    const MethodDescriptor* method =
        google::protobuf::DescriptorPool::generated_pool()->FindMethodByName(route.rpc);
    if (method == nullptr) {
      return absl::InternalError(absl::StrCat("route ", route.Name(), ": no method ", route.rpc));
    }
    transcoder->methods_[route.rpc] = method;
  }
  return transcoder;
}

void ApiTranscoder::Prepare(grpc::ClientContext* context, absl::string_view peer,
                            absl::string_view scope) const {
  context->set_deadline(
      std::chrono::system_clock::now() +
      std::chrono::duration_cast<std::chrono::system_clock::duration>(call_timeout_));
  context->AddMetadata(kHttpPeerMetadata, std::string(peer));
  if (!scope.empty()) context->AddMetadata(kHttpScopeMetadata, std::string(scope));
}

grpc::Status ApiTranscoder::Invoke(const MethodDescriptor& method, const Message& request,
                                   Message* response, absl::string_view peer,
                                   absl::string_view scope) const {
  grpc::ClientContext context;
  Prepare(&context, peer, scope);
  std::promise<grpc::Status> done;
  stub_.UnaryCall(&context, absl::StrCat("/", method.service()->full_name(), "/", method.name()),
                  grpc::StubOptions(), &request, response,
                  [&done](grpc::Status status) { done.set_value(std::move(status)); });
  return done.get_future().get();
}

absl::Status ApiTranscoder::FillRequest(const ApiRoute& route, const HttpCall& call,
                                        Message* request) const {
  if (route.json_body) MOTIONDB_RETURN_IF_ERROR(MergeJson(call.body, request));
  // A name the route gives a field of its own, or the field's own dotted name.
  const auto field_of = [&route](const std::string& name) {
    for (const auto& [alias, field] : route.fields) {
      if (alias == name) return field;
    }
    return name;
  };
  const std::vector<std::string> names = route.PathNames();
  // A query parameter may not name a field the path gives (DELETE /v1/clips/3?clip_id=77).
  std::set<std::string> from_path;
  for (const std::string& name : names) {
    from_path.insert(FieldName(field_of(name), *request->GetDescriptor()));
  }
  for (const auto& [name, value] : call.query) {
    const std::string field = FieldName(field_of(name), *request->GetDescriptor());
    if (from_path.count(field) > 0) {
      return absl::InvalidArgumentError(absl::StrCat("parameter '", name, "': the path gives ",
                                                     field, "; it cannot be a query parameter"));
    }
    MOTIONDB_RETURN_IF_ERROR(SetField(field_of(name), value, request));
  }
  for (size_t i = 0; i < names.size() && i < call.path_values.size(); ++i) {
    MOTIONDB_RETURN_IF_ERROR(SetField(field_of(names[i]), call.path_values[i], request));
  }
  return absl::OkStatus();
}

HttpReply ApiTranscoder::Call(const ApiRoute& route, const HttpCall& call) const {
  const MethodDescriptor& method = *methods_.at(route.rpc);
  const std::unique_ptr<Message> request = NewMessage(method.input_type());
  if (const absl::Status filled = FillRequest(route, call, request.get()); !filled.ok()) {
    return ErrorReply(grpc::StatusCode::INVALID_ARGUMENT, filled.message());
  }
  const std::unique_ptr<Message> response = NewMessage(method.output_type());
  const grpc::Status status = Invoke(method, *request, response.get(), call.peer, call.scope);
  if (!status.ok()) return ErrorReply(status.error_code(), status.error_message());
  absl::StatusOr<std::string> json = AnswerJson(*response, static_cast<size_t>(max_answer_bytes_));
  if (!json.ok()) {
    return ErrorReply(grpc::StatusCode::RESOURCE_EXHAUSTED,
                      absl::StrCat(json.status().message(),
                                   ", the server's answer limit (--max-answer-mb), "
                                   "though its gRPC answer is within it: ask for less "
                                   "(a range, a smaller page), or call the gRPC method"));
  }
  HttpReply reply;
  reply.body = *std::move(json);
  return reply;
}

std::unique_ptr<FileStream> ApiTranscoder::OpenFile(const ApiRoute& route,
                                                    const HttpCall& call) const {
  v1::ExportClipRequest request;
  if (const absl::Status filled = FillRequest(route, call, &request); !filled.ok()) {
    return std::make_unique<RefusedFile>(
        ErrorReply(grpc::StatusCode::INVALID_ARGUMENT, filled.message()));
  }
  auto context = std::make_unique<grpc::ClientContext>();
  Prepare(context.get(), call.peer, call.scope);
  return std::make_unique<ExportStream>(std::move(context), *clips_, request);
}

bool ApiTranscoder::Ready(absl::string_view peer) const {
  const MethodDescriptor* check = grpc::health::v1::HealthCheckRequest::descriptor()
                                      ->file()
                                      ->FindServiceByName("Health")
                                      ->FindMethodByName("Check");
  grpc::health::v1::HealthCheckRequest request;  // "": the server as a whole
  grpc::health::v1::HealthCheckResponse response;
  return Invoke(*check, request, &response, peer, "").ok() &&
         response.status() == grpc::health::v1::HealthCheckResponse::SERVING;
}

}  // namespace motiondb::server
