#include "server/http/http_server.h"

#include <openssl/ssl.h>
#include <sys/socket.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <optional>
#include <regex>
#include <thread>

#include <httplib.h>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "server/grpc/credentials.h"
#include "server/grpc/request_logger.h"
#include "server/grpc/status_conversion.h"
#include "server/http/api_routes.h"
#include "server/http/api_transcoder.h"
#include "server/http/chunked_file.h"
#include "server/http/head_checks.h"
#include "server/http/http_exchange.h"
#include "server/http/http_status.h"
#include "server/http/json_transcoding.h"
#include "server/http/request_checks.h"
#include "server/http/tls_context.h"
#include "server/net/listener.h"
#include "util/status_macros.h"

#ifndef MOTIONDB_WEB_DIST
#error "MOTIONDB_WEB_DIST must be defined by the build (server/http/CMakeLists.txt)"
#endif

namespace motiondb::server {
namespace {

constexpr char kJson[] = "application/json";

// The exchange a worker thread serves, from the pre-routing handler (which runs first for
// every request that parsed) to the logger (which runs once it is answered): for its metrics.
struct Exchange {
  std::chrono::steady_clock::time_point start{};
  std::string route;                      // as metrics label it
  TokenScope scope = TokenScope::kAdmin;  // what the caller's token holds
};
thread_local Exchange exchange;

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

std::vector<absl::string_view> AuthorizationHeaders(const httplib::Request& request) {
  std::vector<absl::string_view> headers;
  const auto [first, last] = request.headers.equal_range("Authorization");
  for (auto it = first; it != last; ++it) headers.push_back(it->second);
  return headers;
}

// The caller's right to `method` `path`, from its Authorization headers; nullopt when allowed,
// with `scope` set to what its token holds.
std::optional<HttpRefusal> CheckAccess(MotionDbServer& server, absl::string_view method,
                                       absl::string_view path, absl::string_view address,
                                       const std::vector<absl::string_view>& authorization,
                                       TokenScope* scope) {
  const std::optional<TokenScope> needed =
      NeededScope(method, path, server.options().health_needs_token);
  *scope = TokenScope::kAdmin;
  if (!needed) return std::nullopt;
  const AccessControl::Verdict verdict =
      server.access().Decide(absl::StrCat(method, " ", path), *needed, address, authorization,
                             "send the header 'Authorization: Bearer <token>'");
  *scope = verdict.scope;
  if (verdict.status.ok()) return std::nullopt;
  HttpRefusal refusal{HttpStatusOf(verdict.status.error_code()), verdict.status.error_message()};
  if (verdict.status.error_code() == grpc::StatusCode::UNAUTHENTICATED) {
    refusal.headers.emplace_back("WWW-Authenticate", "Bearer");
  }
  return refusal;
}

}  // namespace

std::string DefaultWebRoot() { return MOTIONDB_WEB_DIST; }

struct SslContextFree {
  void operator()(SSL_CTX* context) const { SSL_CTX_free(context); }
};

// Declared in the order they are needed, so that destruction runs the other way: the loop (and
// its workers, which use the router and the transcoder) goes before them.
struct HttpServer::State {
  explicit State(MotionDbServer& server) : server(server) {}

  MotionDbServer& server;
  std::unique_ptr<ApiTranscoder> api;
  HttpRouter router;
  std::unique_ptr<SSL_CTX, SslContextFree> tls;  // null: plain HTTP
  std::unique_ptr<Listener> listener;
  std::unique_ptr<ConnectionLoop> loop;
};

HttpServer::HttpServer(std::unique_ptr<State> state) : state_(std::move(state)) {}

HttpServer::~HttpServer() {
  state_->server.metrics().SetConnectionSource(kHttpFace, nullptr);
  Stop(std::chrono::steady_clock::now());
}

void HttpServer::BeginStop() {
  state_->listener->Stop();
  state_->loop->BeginStop();
}

void HttpServer::Stop(std::chrono::steady_clock::time_point deadline) {
  BeginStop();
  state_->router.StopStreaming();
  state_->loop->Stop(deadline);
}

int HttpServer::port() const { return state_->listener->port(); }

namespace {

// The checks of a request's head, before its body is read (the connection loop's hook).
std::optional<HttpRefusal> CheckHead(MotionDbServer& server, const RequestChecks& checks,
                                     size_t max_body, const std::vector<std::regex>& body_routes,
                                     const RequestHead& head, const HttpConnection& connection) {
  const RequestFacts facts = RequestFacts::Of(head);
  std::optional<HttpRefusal> refusal;
  // A listed origin's preflight carries no token (httplib answers it).
  if (!checks.ListedPreflight(facts)) {
    TokenScope scope;
    refusal = CheckAccess(server, head.method, head.path, connection.peer_address(),
                          head.Values("authorization"), &scope);
  }
  if (!refusal) refusal = RefuseBody(head, max_body, body_routes);
  if (!refusal) refusal = checks.Refuse(facts);
  // So that a listed origin's page can read why.
  if (refusal) {
    for (auto& header : checks.CorsHeaders(facts)) refusal->headers.push_back(std::move(header));
  }
  return refusal;
}

// The request and access checks again on httplib's own reading of the request (the loop's came
// first, on its own), a listed origin's preflight answered and its CORS headers, the scope
// granted for the call, the metrics' bookkeeping and JSON bodies for the library's own errors.
void AddHooks(MotionDbServer& server, RequestChecks checks, httplib::Server& http) {
  http.set_pre_routing_handler([&server, checks = std::move(checks)](
                                   const httplib::Request& request, httplib::Response& response) {
    // Until a route's handler names itself.
    exchange = {std::chrono::steady_clock::now(), IsApiPath(request.path) ? "unmatched" : "static"};
    const RequestFacts facts = RequestFacts::Of(request);
    for (const auto& [name, value] : checks.CorsHeaders(facts)) response.set_header(name, value);
    std::optional<HttpRefusal> refusal;
    if (!checks.ListedPreflight(facts)) {
      refusal = CheckAccess(server, request.method, request.path, request.remote_addr,
                            AuthorizationHeaders(request), &exchange.scope);
    }
    if (!refusal) refusal = checks.Refuse(facts);
    if (!refusal && checks.ListedPreflight(facts)) {
      exchange.route = "preflight";
      response.status = 204;
      return httplib::Server::HandlerResponse::Handled;
    }
    if (!refusal) return httplib::Server::HandlerResponse::Unhandled;
    exchange.route = "refused";
    response.status = refusal->status;
    for (const auto& [name, value] : refusal->headers) response.set_header(name, value);
    response.set_content(ErrorJson(CodeOfHttpStatus(refusal->status), refusal->message), kJson);
    server.request_log().WriteLine(absl::StrCat(request.method, " ", request.path),
                                   StatusCodeName(CodeOfHttpStatus(refusal->status)), 0.0,
                                   absl::StrCat("http:", Peer(request)), refusal->message);
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
      call.scope = std::string(TokenScopeName(exchange.scope));
      if (route.bvh_file) return SendChunkedFile(api.OpenFile(route, call), response);
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
  http.Get("/readyz",
           [&api, &server](const httplib::Request& request, httplib::Response& response) {
             exchange.route = "GET /readyz";
             // Not ready while the gRPC port cannot take a connection (out of descriptors, or
             // full).
             const bool ready = server.accepting() && api.Ready(Peer(request));
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

absl::StatusOr<std::unique_ptr<SSL_CTX, SslContextFree>> NewTlsContext(
    const ServerOptions& options) {
  if (options.tls_cert_pem.empty()) return nullptr;
  std::unique_ptr<SSL_CTX, SslContextFree> context(SSL_CTX_new(TLS_server_method()));
  if (context == nullptr) return absl::InternalError("HTTPS could not be set up (SSL_CTX_new)");
  SSL_CTX_set_min_proto_version(context.get(), TLS1_2_VERSION);
  MOTIONDB_RETURN_IF_ERROR(LoadPemIntoContext(options.tls_cert_pem, options.tls_key_pem, *context));
  return context;
}

// A refusal written to a connection the port will not take (plain HTTP only: a TLS client would
// read it as garbage). Best effort: the socket is new, its buffer empty.
void RefuseConnection(int socket, absl::string_view reason) {
  const std::string body =
      ErrorJson(grpc::StatusCode::UNAVAILABLE,
                absl::StrCat("the server takes no more connections: ", reason, "; retry later"));
  const std::string response = absl::StrCat(
      "HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/json\r\nContent-Length: ",
      body.size(), "\r\nRetry-After: 1\r\nConnection: close\r\n\r\n", body);
  const ssize_t written =
      ::send(socket, response.data(), response.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  (void)written;
}

}  // namespace

absl::StatusOr<std::unique_ptr<HttpServer>> HttpServer::Start(const HttpOptions& options,
                                                              MotionDbServer& server) {
  MOTIONDB_ASSIGN_OR_RETURN(RequestChecks checks,
                            RequestChecks::Create(options.allowed_hosts, options.cors_origins));
  auto state = std::make_unique<State>(server);
  MOTIONDB_ASSIGN_OR_RETURN(state->api,
                            ApiTranscoder::Create(server.InProcessChannel(), options.call_timeout_s,
                                                  int64_t{server.options().max_answer_mb} << 20));
  MOTIONDB_ASSIGN_OR_RETURN(state->tls, NewTlsContext(server.options()));
  HttpRouter& router = state->router;
  router.set_keep_alive_max_count(options.loop.max_requests_per_connection);
  router.set_keep_alive_timeout(
      std::chrono::duration_cast<std::chrono::seconds>(options.loop.idle_timeout).count());
  // A JSON body carries a BVH file in base64: 4/3 of the largest message, and room for the rest.
  const size_t max_body =
      (static_cast<size_t>(server.options().max_message_mb) << 20) / 3 * 4 + (size_t{1} << 20);
  router.set_payload_max_length(max_body);
  AddHooks(server, checks, router);
  AddApiRoutes(*state->api, router);
  AddOperationsRoutes(*state->api, server, router);
  const std::string web_root = options.web_root.empty() ? DefaultWebRoot() : options.web_root;
  AddWebRoot(web_root, router);

  MOTIONDB_ASSIGN_OR_RETURN(
      state->listener,
      Listener::Bind(ListenerOptions{.listen = options.listen,
                                     .face = "HTTP",
                                     .flag = "--http",
                                     .limits = options.connections,
                                     .log = [](absl::string_view line) { LogLine(line); }}));
  ConnectionLoop::Hooks hooks;
  hooks.check_head = [&server, checks = std::move(checks), max_body,
                      body_routes = BodyRoutePaths()](const RequestHead& head,
                                                      const HttpConnection& connection) {
    return CheckHead(server, checks, max_body, body_routes, head, connection);
  };
  const std::chrono::milliseconds stall = options.loop.write_stall_timeout;
  hooks.answer = [&router, stall](HttpConnection& connection, absl::string_view request,
                                  bool last) {
    return router.Answer(connection, request, last, stall);
  };
  hooks.refused = [&server](const HttpConnection& connection, const RequestHead* head,
                            const HttpRefusal& refusal) {
    server.metrics().CountHttp("refused", refusal.status, 0.0);
    server.request_log().WriteLine(
        head != nullptr ? absl::StrCat(head->method, " ", head->path) : "HTTP request",
        StatusCodeName(CodeOfHttpStatus(refusal.status)), 0.0,
        absl::StrCat("http:", connection.peer()), refusal.message);
  };
  hooks.error_body = [](const HttpRefusal& refusal) {
    return ErrorJson(CodeOfHttpStatus(refusal.status), refusal.message);
  };
  state->loop = std::make_unique<ConnectionLoop>(options.loop, state->tls.get(),
                                                 server.upload_budget(), std::move(hooks));
  ConnectionLoop& loop = *state->loop;
  state->listener->Start(
      [&loop](AcceptedConnection connection) { loop.Add(std::move(connection)); },
      state->tls ? Listener::Refuser() : Listener::Refuser(&RefuseConnection),
      /*reclaim=*/nullptr);
  Listener& listener = *state->listener;
  server.metrics().SetConnectionSource(kHttpFace,
                                       [&listener] { return listener.connections().open(); });
  LogLine(absl::StrCat("HTTP on ", options.listen, " (http port ", state->listener->port(), ")",
                       server.options().tls_cert_pem.empty() ? ", plain text" : ", HTTPS",
                       "; web UI from ", web_root, WebRootIsBuilt(web_root) ? "" : " (not built)"));
  return std::unique_ptr<HttpServer>(new HttpServer(std::move(state)));
}

}  // namespace motiondb::server
