// libFuzzer target: the HTTP face's JSON API (server/http/api_transcoder.h) on a real server
// in this process over a small real library (tests/fuzz/fuzz_library.h): a route, its path
// values, query parameters (the route's names and any field path) and body, as cpp-httplib
// hands them over, converted to the route's gRPC request, called in-process and answered as
// JSON. Routes that write are left out, so that every input meets the same library. No answer
// may be a 5xx (an INTERNAL or UNKNOWN status) or a body that is not JSON; nothing may crash or
// trip a sanitizer. A 504 is the deadline's answer to a call that was slow, not wrong: under
// sanitizers on a loaded machine a whole clip's poses can take longer than the 0.2 s given.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "server/grpc/motiondb_server.h"
#include "server/http/api_routes.h"
#include "server/http/api_transcoder.h"
#include "tests/fuzz/fuzz_library.h"

namespace {

using motiondb::server::ApiRoute;

struct HttpFace {
  std::unique_ptr<motiondb::server::MotionDbServer> server;
  std::unique_ptr<motiondb::server::ApiTranscoder> transcoder;
  std::vector<const ApiRoute*> routes;  // those that only read
};

HttpFace& TheHttpFace() {
  static HttpFace* const face = [] {
    auto made = new HttpFace;
    motiondb::server::ServerOptions options;
    options.db_path = motiondb::fuzz::TheFuzzLibrary().path;
    options.listen = "127.0.0.1:0";
    options.log_requests = false;
    auto server = motiondb::server::MotionDbServer::Start(options);
    if (!server.ok()) {
      std::fprintf(stderr, "http fuzzer: %s\n", server.status().ToString().c_str());
      std::abort();
    }
    made->server = *std::move(server);
    // A deadline as the server's default, shorter: large but valid parameters are slow, not
    // wrong.
    auto transcoder = motiondb::server::ApiTranscoder::Create(made->server->InProcessChannel(), 0.2,
                                                              int64_t{options.max_answer_mb} << 20);
    if (!transcoder.ok()) std::abort();
    made->transcoder = *std::move(transcoder);
    for (const ApiRoute& route : motiondb::server::ApiRoutes()) {
      if (route.http_method == "GET" || route.path == "/v1/search") made->routes.push_back(&route);
    }
    return made;
  }();
  return *face;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  HttpFace& face = TheHttpFace();
  FuzzedDataProvider input(data, size);
  const ApiRoute& route =
      *face.routes[input.ConsumeIntegralInRange<size_t>(0, face.routes.size() - 1)];
  motiondb::server::HttpCall call;
  for (size_t i = 0; i < route.PathNames().size(); ++i) {
    call.path_values.push_back(input.ConsumeRandomLengthString(24));
  }
  const int parameters = input.ConsumeIntegralInRange(0, 4);
  for (int i = 0; i < parameters; ++i) {
    std::string name = input.ConsumeRandomLengthString(24);
    if (!route.fields.empty() && input.ConsumeBool()) {
      name = route.fields[input.ConsumeIntegralInRange<size_t>(0, route.fields.size() - 1)].first;
    }
    call.query.emplace(std::move(name), input.ConsumeRandomLengthString(32));
  }
  if (route.json_body) call.body = input.ConsumeRemainingBytesAsString();
  call.peer = "fuzz";
  motiondb::server::HttpReply reply;
  if (route.bvh_file) {
    // The export's stream read to its end, its head the reply (a piece of text after it).
    const std::unique_ptr<motiondb::server::FileStream> file =
        face.transcoder->OpenFile(route, call);
    std::string piece;
    while (file->Next(&piece)) {
    }
    reply = file->head();
  } else {
    reply = face.transcoder->Call(route, call);
  }
  if (reply.status >= 500 && reply.status != 504) {
    std::fprintf(stderr, "%s answered %d: %s\n", route.Name().c_str(), reply.status,
                 reply.body.c_str());
    std::abort();
  }
  if (reply.content_type == "application/json" && !nlohmann::json::accept(reply.body)) {
    std::fprintf(stderr, "%s answered a body that is not JSON: %s\n", route.Name().c_str(),
                 reply.body.c_str());
    std::abort();
  }
  return 0;
}
