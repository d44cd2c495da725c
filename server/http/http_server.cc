#include "server/http/http_server.h"

#include <sys/socket.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <future>
#include <optional>
#include <regex>
#include <thread>

#include <httplib.h>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "server/grpc/credentials.h"
#include "server/http/api_routes.h"
#include "server/http/api_transcoder.h"
#include "server/http/http_status.h"
#include "server/http/json_transcoding.h"
#include "server/http/tls_context.h"
#include "util/status_macros.h"

#ifndef MOTIONDB_WEB_DIST
#error "MOTIONDB_WEB_DIST must be defined by the build (server/http/CMakeLists.txt)"
#endif

namespace motiondb::server {
namespace {

constexpr char kJson[] = "application/json";
// Enough for a browser's few connections and the tools beside it; each connection holds a
// thread while it is kept alive.
constexpr size_t kMinThreads = 16;
// Requests a connection may carry before it is closed (httplib's default is 5).
constexpr size_t kKeepAliveRequests = 1000;

// The exchange a worker thread serves, from the pre-routing handler (which runs first for
// every request that parsed) to the logger (which runs once it is answered): for its metrics.
struct Exchange {
  std::chrono::steady_clock::time_point start{};
  std::string route;  // as metrics label it
};
thread_local Exchange exchange;

absl::StatusOr<std::pair<std::string, int>> SplitHostPort(const std::string& listen) {
  const size_t colon = listen.rfind(':');
  int port = -1;
  if (colon == std::string::npos || !absl::SimpleAtoi(listen.substr(colon + 1), &port) ||
      port < 0 || port > 65535) {
    return absl::InvalidArgumentError(
        absl::StrCat("--http: '", listen, "' is not HOST:PORT (port 0..65535) or off"));
  }
  std::string host = listen.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);  // [::1]
  }
  return std::make_pair(host, port);
}

std::string Peer(const httplib::Request& request) {
  return absl::StrCat(request.remote_addr, ":", request.remote_port);
}

void Send(const HttpReply& reply, httplib::Response& response) {
  response.status = reply.status;
  for (const auto& [name, value] : reply.headers) response.set_header(name, value);
  response.set_content(reply.body, reply.content_type);
}

void SendError(grpc::StatusCode code, absl::string_view message, httplib::Response& response) {
  response.status = HttpStatusOf(code);
  response.set_content(ErrorJson(code, message), kJson);
}

bool IsApiPath(const std::string& path) { return path == "/v1" || absl::StartsWith(path, "/v1/"); }

// Whether the path needs the token: the API and the metrics hold data; health as the gRPC
// health service; the web UI's files never.
bool NeedsToken(const ServerOptions& options, const std::string& path) {
  if (options.auth_token.empty()) return false;
  if (path == "/healthz" || path == "/readyz") {
    return MethodNeedsToken("/grpc.health.v1.Health/Check", options.health_needs_token);
  }
  return path == "/metrics" || IsApiPath(path);
}

bool Authorized(const ServerOptions& options, const httplib::Request& request) {
  bool authorized = false;
  // Every header is looked at, so that the time does not depend on which one matches.
  for (size_t i = 0; i < request.get_header_value_count("Authorization"); ++i) {
    authorized |=
        BearerTokenMatches(request.get_header_value("Authorization", i), options.auth_token);
  }
  return authorized;
}

// The routes that take a request body, as regular expressions of their paths.
std::vector<std::regex> BodyRoutes() {
  std::vector<std::regex> paths;
  for (const ApiRoute& route : ApiRoutes()) {
    if (route.json_body) paths.emplace_back(route.PathRegex());
  }
  return paths;
}

struct Refusal {
  int status = 0;
  std::string message;
};

// A request whose body is refused before it is read: httplib 0.11 checks its payload limit only
// against Content-Length, reads a chunked body and inflates a compressed one whole before any
// handler runs, and reads a POST without a length until the connection ends. So a body comes
// uncompressed with its Content-Length, within `max_body`, and only to a POST route that takes
// one.
std::optional<Refusal> RefuseBody(const httplib::Request& request, size_t max_body,
                                  const std::vector<std::regex>& body_routes) {
  if (request.has_header("Transfer-Encoding")) {
    return Refusal{411, "send the request body with a Content-Length, not a Transfer-Encoding"};
  }
  if (request.has_header("Content-Encoding")) {
    return Refusal{415, "send the request body uncompressed, without a Content-Encoding"};
  }
  const bool takes_body =
      request.method == "POST" &&
      std::any_of(body_routes.begin(), body_routes.end(), [&request](const std::regex& path) {
        return std::regex_match(request.path, path);
      });
  size_t length = 0;
  if (!request.has_header("Content-Length")) {
    if (request.method != "POST") return std::nullopt;
    return Refusal{411, "a POST needs a Content-Length (curl: -d '' for an empty body)"};
  }
  if (!absl::SimpleAtoi(request.get_header_value("Content-Length"), &length)) {
    return Refusal{400, "the Content-Length is not a number"};
  }
  if (length > 0 && !takes_body) {
    return Refusal{413, absl::StrCat(request.method, " ", request.path, " takes no request body")};
  }
  if (length > max_body) {
    return Refusal{413, absl::StrCat("the request body is larger than the ", max_body,
                                     " bytes the server takes (--max-message-mb, base64-encoded)")};
  }
  return std::nullopt;
}

}  // namespace

std::string DefaultWebRoot() { return MOTIONDB_WEB_DIST; }

struct HttpServer::State {
  explicit State(MotionDbServer& server) : server(server) {}

  MotionDbServer& server;
  std::unique_ptr<ApiTranscoder> api;
  std::unique_ptr<httplib::Server> http;
  std::thread listener;
};

HttpServer::HttpServer(std::unique_ptr<State> state) : state_(std::move(state)) {}

HttpServer::~HttpServer() { Stop(); }

void HttpServer::Stop() {
  if (state_->http) state_->http->stop();
  if (state_->listener.joinable()) state_->listener.join();
}

namespace {

// The body and token checks, the metrics' bookkeeping and JSON bodies for the library's own
// errors. The pre-routing handler runs once the headers are read, before httplib reads a body.
void AddHooks(MotionDbServer& server, size_t max_body, httplib::Server& http) {
  http.set_pre_routing_handler([&server, max_body, body_routes = BodyRoutes()](
                                   const httplib::Request& request, httplib::Response& response) {
    // Until a route's handler names itself.
    exchange = {std::chrono::steady_clock::now(), IsApiPath(request.path) ? "unmatched" : "static"};
    if (const std::optional<Refusal> refusal = RefuseBody(request, max_body, body_routes)) {
      exchange.route = "refused";
      response.status = refusal->status;
      // The body is left unread, so the connection cannot carry another request.
      response.set_header("Connection", "close");
      response.set_content(ErrorJson(CodeOfHttpStatus(refusal->status), refusal->message), kJson);
      return httplib::Server::HandlerResponse::Handled;
    }
    if (!NeedsToken(server.options(), request.path) || Authorized(server.options(), request)) {
      return httplib::Server::HandlerResponse::Unhandled;
    }
    exchange.route = "refused";
    response.set_header("WWW-Authenticate", "Bearer");
    SendError(grpc::StatusCode::UNAUTHENTICATED,
              "missing or wrong bearer token: send the header 'Authorization: Bearer <token>'",
              response);
    server.request_log().WriteLine(absl::StrCat(request.method, " ", request.path),
                                   "UNAUTHENTICATED", 0.0, absl::StrCat("http:", Peer(request)));
    return httplib::Server::HandlerResponse::Handled;
  });
  http.set_error_handler(httplib::Server::HandlerWithResponse(
      [](const httplib::Request& request, httplib::Response& response) {
        if (!response.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
        const std::string message =
            response.status == 404
                ? absl::StrCat("no route or file for ", request.method, " ", request.path)
                : absl::StrCat("HTTP status ", response.status);
        response.set_content(ErrorJson(CodeOfHttpStatus(response.status), message), kJson);
        return httplib::Server::HandlerResponse::Handled;
      }));
  // Counted before the answer is written (httplib's logger runs after), so that a scrape sent
  // once an answer arrived counts it.
  http.set_post_routing_handler([&server](const httplib::Request&, httplib::Response& response) {
    const double seconds =
        exchange.start == std::chrono::steady_clock::time_point{}
            ? 0.0
            : std::chrono::duration<double>(std::chrono::steady_clock::now() - exchange.start)
                  .count();
    server.metrics().CountHttp(exchange.route.empty() ? "unmatched" : exchange.route,
                               response.status, seconds);
    exchange = {};
  });
}

void AddApiRoutes(const ApiTranscoder& api, httplib::Server& http) {
  for (const ApiRoute& route : ApiRoutes()) {
    httplib::Server::Handler handler = [&api, &route](const httplib::Request& request,
                                                      httplib::Response& response) {
      exchange.route = route.Name();
      HttpCall call;
      for (size_t i = 1; i < request.matches.size(); ++i) {
        call.path_values.push_back(request.matches[i].str());
      }
      // A body route's request is its JSON; httplib also parses a body sent as a form (curl -d
      // without a Content-Type) into the parameters, which would then name no field.
      if (!route.json_body) call.query.insert(request.params.begin(), request.params.end());
      call.body = request.body;
      call.peer = Peer(request);
      Send(api.Call(route, call), response);
    };
    const std::string pattern = route.PathRegex();
    if (route.http_method == "GET") http.Get(pattern, std::move(handler));
    if (route.http_method == "POST") http.Post(pattern, std::move(handler));
    if (route.http_method == "DELETE") http.Delete(pattern, std::move(handler));
  }
}

void AddOperationsRoutes(const ApiTranscoder& api, MotionDbServer& server, httplib::Server& http) {
  http.Get("/metrics", [&server](const httplib::Request&, httplib::Response& response) {
    exchange.route = "GET /metrics";
    response.set_content(server.metrics().Render(), "text/plain; version=0.0.4; charset=utf-8");
  });
  http.Get("/healthz", [](const httplib::Request&, httplib::Response& response) {
    exchange.route = "GET /healthz";
    response.set_content("ok", "text/plain");
  });
  http.Get("/readyz", [&api](const httplib::Request& request, httplib::Response& response) {
    exchange.route = "GET /readyz";
    const bool ready = api.Ready(Peer(request));
    response.status = ready ? 200 : 503;
    response.set_content(ready ? "ready" : "not ready", "text/plain");
  });
}

// A web root counts as built when it holds the page: an image built without the npm registry
// ships an empty one.
bool WebRootIsBuilt(const std::string& root) {
  return std::filesystem::is_regular_file(std::filesystem::path(root) / "index.html");
}

// The web UI's files from `root`, or, when it is not built, a 404 at / saying how to build it.
void AddWebRoot(const std::string& root, httplib::Server& http) {
  if (WebRootIsBuilt(root) && http.set_mount_point("/", root)) {
    // Beyond httplib's own table: source maps and a charset for text.
    http.set_file_extension_and_mimetype_mapping("html", "text/html; charset=utf-8");
    http.set_file_extension_and_mimetype_mapping("js", "text/javascript; charset=utf-8");
    http.set_file_extension_and_mimetype_mapping("mjs", "text/javascript; charset=utf-8");
    http.set_file_extension_and_mimetype_mapping("css", "text/css; charset=utf-8");
    http.set_file_extension_and_mimetype_mapping("map", "application/json");
    return;
  }
  http.Get("/", [root](const httplib::Request&, httplib::Response& response) {
    SendError(grpc::StatusCode::NOT_FOUND,
              absl::StrCat("the web UI is not built: ", root,
                           " holds no index.html (scripts/start.sh builds it: npm ci and npm run "
                           "build in web/; or pass --web-root DIR)"),
              response);
  });
}

absl::StatusOr<std::unique_ptr<httplib::Server>> NewHttpServer(const ServerOptions& options) {
  if (options.tls_cert_pem.empty()) return std::make_unique<httplib::Server>();
  absl::Status loaded;
  auto https = std::make_unique<httplib::SSLServer>([&](SSL_CTX& context) {
    loaded = LoadPemIntoContext(options.tls_cert_pem, options.tls_key_pem, context);
    return loaded.ok();
  });
  if (!loaded.ok()) return loaded;
  if (!https->is_valid()) return absl::InvalidArgumentError("HTTPS could not be set up");
  return https;
}

}  // namespace

absl::StatusOr<std::unique_ptr<HttpServer>> HttpServer::Start(const HttpOptions& options,
                                                              MotionDbServer& server) {
  MOTIONDB_ASSIGN_OR_RETURN(const auto host_port, SplitHostPort(options.listen));
  auto state = std::make_unique<State>(server);
  MOTIONDB_ASSIGN_OR_RETURN(
      state->api, ApiTranscoder::Create(server.InProcessChannel(), options.call_timeout_s));
  MOTIONDB_ASSIGN_OR_RETURN(state->http, NewHttpServer(server.options()));
  httplib::Server& http = *state->http;
  const size_t threads = std::max<size_t>(kMinThreads, 2 * std::thread::hardware_concurrency());
  http.new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
  // SO_REUSEADDR alone: httplib's default adds SO_REUSEPORT, which would let a second server
  // share a port in use instead of failing to start.
  http.set_socket_options([](int socket) {
    const int yes = 1;
    setsockopt(socket, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  });
  // httplib writes a response's headers and body apart; with Nagle's algorithm the body waits
  // for the client's delayed ACK, 40 ms on Linux (measured: every search and scrape took 44 ms
  // more).
  http.set_tcp_nodelay(true);
  http.set_keep_alive_max_count(kKeepAliveRequests);
  // A JSON body carries a BVH file in base64: 4/3 of the largest message, and room for the rest.
  const size_t max_body =
      (static_cast<size_t>(server.options().max_message_mb) << 20) / 3 * 4 + (size_t{1} << 20);
  http.set_payload_max_length(max_body);
  AddHooks(server, max_body, http);
  AddApiRoutes(*state->api, http);
  AddOperationsRoutes(*state->api, server, http);
  const std::string web_root = options.web_root.empty() ? DefaultWebRoot() : options.web_root;
  AddWebRoot(web_root, http);

  const auto& [host, port] = host_port;
  const int bound =
      port == 0 ? http.bind_to_any_port(host) : (http.bind_to_port(host, port) ? port : -1);
  if (bound <= 0) {
    return absl::UnavailableError(absl::StrCat("cannot listen on ", options.listen,
                                               " for HTTP (address in use or not local)"));
  }
  std::promise<void> listened;
  std::future<void> ended = listened.get_future();
  state->listener = std::thread([&http, listened = std::move(listened)]() mutable {
    http.listen_after_bind();
    listened.set_value();
  });
  // stop() does nothing until the loop runs; wait for it, so that Stop() always ends it. A
  // loop that ended by itself (its socket failed) is joined: no thread outlives the error.
  while (!http.is_running()) {
    if (ended.wait_for(std::chrono::milliseconds(1)) == std::future_status::ready) {
      state->listener.join();
      return absl::UnavailableError(absl::StrCat("HTTP on ", options.listen, " did not start"));
    }
  }
  LogLine(absl::StrCat("HTTP on ", options.listen, " (http port ", bound, ")",
                       server.options().tls_cert_pem.empty() ? ", plain text" : ", HTTPS",
                       "; web UI from ", web_root, WebRootIsBuilt(web_root) ? "" : " (not built)"));
  return std::unique_ptr<HttpServer>(new HttpServer(std::move(state)));
}

}  // namespace motiondb::server
