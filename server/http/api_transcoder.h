// The JSON API's calls: an HTTP request on a route (server/http/api_routes.h) becomes the
// route's gRPC request message, which goes to the server's own services in-process, and the
// answer comes back as JSON (or a file), so that an answer here is the gRPC answer.
//
// Thread-safe.
#ifndef MOTIONDB_SERVER_HTTP_API_TRANSCODER_H_
#define MOTIONDB_SERVER_HTTP_API_TRANSCODER_H_

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>
#include <grpcpp/channel.h>
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/impl/codegen/proto_utils.h>  // serializes google::protobuf::Message for the stub

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "server/http/api_routes.h"

namespace motiondb::server {

struct HttpReply {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;  // beyond Content-Type
};

// What an HTTP request carries, as the HTTP library parsed it.
struct HttpCall {
  std::vector<std::string> path_values;           // one per placeholder of the route, decoded
  std::multimap<std::string, std::string> query;  // GET and DELETE routes
  std::string body;
  std::string peer;   // the client's address, for the request log
  std::string scope;  // what the caller's token holds ("read", ...), for GetServerInfo
};

// A file sent as a server-streaming call sends it (ExportClipStream): the reply's status and
// headers from the call's first message (or, when the call fails first, the whole error reply),
// then the file's pieces as they arrive. Destroyed before its end, it cancels the call, so that
// the server stops writing.
class FileStream {
 public:
  virtual ~FileStream() = default;
  // Status 200 with the file's headers (and no body), or the error reply.
  virtual const HttpReply& head() const = 0;
  // The next piece of the file (never empty); false at the end, or when the call failed after
  // its first message (ok() false: the file is cut short).
  virtual bool Next(std::string* piece) = 0;
  virtual bool ok() const = 0;
};

class ApiTranscoder {
 public:
  // Calls through `channel`, each with a deadline `call_timeout_s` from its start; answers whose
  // JSON would pass `max_answer_bytes` are refused. INTERNAL when a route names a method that no
  // linked service has.
  static absl::StatusOr<std::unique_ptr<ApiTranscoder>> Create(
      std::shared_ptr<grpc::Channel> channel, double call_timeout_s, int64_t max_answer_bytes);

  // The route's call (not a bvh_file route's): its request from the path values and the query
  // parameters, or the body (json_body); 400 with the error body for a request that does not
  // convert, else the call's status mapped (server/http/http_status.h) with the answer or the error
  // body (429, RESOURCE_EXHAUSTED, when the answer's JSON would pass the answer limit).
  HttpReply Call(const ApiRoute& route, const HttpCall& call) const;

  // A bvh_file route's call, ExportClipStream, its request made as Call makes it.
  std::unique_ptr<FileStream> OpenFile(const ApiRoute& route, const HttpCall& call) const;

  // Whether the server serves (the standard health service's overall status is SERVING).
  bool Ready(absl::string_view peer) const;

 private:
  using GenericStub =
      grpc::TemplatedGenericStub<google::protobuf::Message, google::protobuf::Message>;

  ApiTranscoder(std::shared_ptr<grpc::Channel> channel, double call_timeout_s,
                int64_t max_answer_bytes);
  // A call's context: its deadline, the HTTP peer for the request log, and the scope of the
  // caller's token (empty: none) for the access check.
  void Prepare(grpc::ClientContext* context, absl::string_view peer, absl::string_view scope) const;
  // Calls `method` in-process and waits for its answer.
  grpc::Status Invoke(const google::protobuf::MethodDescriptor& method,
                      const google::protobuf::Message& request, google::protobuf::Message* response,
                      absl::string_view peer, absl::string_view scope) const;
  absl::Status FillRequest(const ApiRoute& route, const HttpCall& call,
                           google::protobuf::Message* request) const;

  mutable GenericStub stub_;  // UnaryCall is not const, but the stub keeps no per-call state
  std::unique_ptr<v1::ClipService::Stub> clips_;  // the file routes' streaming calls
  const std::chrono::duration<double> call_timeout_;
  const int64_t max_answer_bytes_;
  std::map<std::string, const google::protobuf::MethodDescriptor*> methods_;  // by rpc name
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_HTTP_API_TRANSCODER_H_
