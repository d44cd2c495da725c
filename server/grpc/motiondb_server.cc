#include "server/grpc/motiondb_server.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/server_builder.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "grpc/health/v1/health.pb.h"
#include "server/catalog.h"
#include "server/grpc/access_control.h"
#include "server/grpc/call_gate.h"
#include "server/grpc/clip_service.h"
#include "server/grpc/credentials.h"
#include "server/grpc/edit_service.h"
#include "server/grpc/job_service.h"
#include "server/grpc/label_service.h"
#include "server/grpc/request_logger.h"
#include "server/grpc/routed_clip_service.h"
#include "server/grpc/search_service.h"
#include "server/grpc/server_info_service.h"
#include "server/grpc/shard_service.h"
#include "server/grpc/space_service.h"
#include "server/index_registry.h"
#include "server/jobs/job_runner.h"
#include "server/net/handed_off_sockets.h"
#include "server/net/listener.h"
#include "server/search_runner.h"
#include "storage/database.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::server {

// Declared in dependency order, so that destruction runs the other way: the gRPC server goes
// first, while everything its handlers use still exists.
struct MotionDbServer::State {
  ServerOptions options;
  std::unique_ptr<storage::Database> database;
  IndexRegistry registry;
  std::unique_ptr<Catalog> catalog;
  std::unique_ptr<SearchRunner> runner;
  std::unique_ptr<JobRunner> jobs;  // its worker uses the runner, the registry and the database
  std::unique_ptr<UploadBudget> uploads;
  std::unique_ptr<ServerMetrics> metrics;
  std::unique_ptr<RequestLog> request_log;
  std::unique_ptr<AccessControl> access;
  std::unique_ptr<CallGate> gate;
  std::unique_ptr<StreamWatchdog> watchdog;
  std::unique_ptr<v1::ClipService::Service> clips;  // routed on a cluster's router
  std::unique_ptr<SpaceServiceImpl> spaces;
  std::unique_ptr<SearchServiceImpl> search;
  std::unique_ptr<LabelServiceImpl> labels;
  std::unique_ptr<JobServiceImpl> job_service;
  std::unique_ptr<ServerInfoServiceImpl> info;
  std::unique_ptr<EditServiceImpl> edits;
  std::unique_ptr<ShardServiceImpl> shard;  // on a cluster's shard node only
  // The port: accepted here, handed to gRPC (see StartListening).
  std::unique_ptr<Listener> listener;
  HandedOffSockets handed_off;
  std::unique_ptr<grpc::experimental::ExternalConnectionAcceptor> acceptor;
  std::unique_ptr<grpc::Server> server;
};

MotionDbServer::MotionDbServer(std::unique_ptr<State> state) : state_(std::move(state)) {}

MotionDbServer::~MotionDbServer() {
  if (state_->listener) state_->listener->Stop();
  if (state_->metrics) state_->metrics->SetConnectionSource(kGrpcFace, nullptr);
  if (state_->server) {
    state_->server->Shutdown(std::chrono::system_clock::now());
    state_->server->Wait();
  }
}

absl::StatusOr<std::unique_ptr<MotionDbServer>> MotionDbServer::Start(
    const ServerOptions& options) {
  if (options.max_message_mb < 1 || options.max_message_mb > 2047) {
    return absl::InvalidArgumentError("--max-message-mb must be in 1..2047");
  }
  if (options.max_query_frames < 1) {
    return absl::InvalidArgumentError("--max-query-frames must be at least 1");
  }
  if (options.max_answer_mb < 1 || options.max_answer_mb > kMaxAnswerMbCeiling) {
    return absl::InvalidArgumentError(
        absl::StrCat("--max-answer-mb must be in 1..", kMaxAnswerMbCeiling));
  }
  if (options.threads < 0) {
    return absl::InvalidArgumentError("--threads must be 0 (no limit) or positive");
  }
  auto state = std::make_unique<State>();
  State& s = *state;
  s.options = options;
  MOTIONDB_ASSIGN_OR_RETURN(s.database, storage::Database::Open(options.db_path));
  s.catalog = std::make_unique<Catalog>(*s.database, s.registry,
                                        /*cluster_shard=*/bool(options.check_shard_owner));
  const auto load_start = std::chrono::steady_clock::now();
  MOTIONDB_RETURN_IF_ERROR(s.catalog->LoadIndices());
  const auto spaces = s.registry.All();
  int64_t frames = 0;
  for (const auto& space : spaces) frames += space->index ? space->index->total_frames() : 0;
  LogLine(absl::StrFormat(
      "loaded %d space indices (%d frames) from %s in %.0f ms", spaces.size(), frames,
      options.db_path,
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - load_start)
          .count()));

  s.runner = std::make_unique<SearchRunner>(s.registry, *s.database, options.uploads,
                                            options.max_query_frames);
  s.jobs = std::make_unique<JobRunner>(
      *s.database, s.registry, *s.runner,
      JobRunnerOptions{.threads = options.job_threads,
                       .test_pause_after = options.test_job_pause_after});
  s.uploads = std::make_unique<UploadBudget>(options.uploads);
  s.metrics = std::make_unique<ServerMetrics>(s.registry, *s.database, *s.uploads);
  s.request_log = std::make_unique<RequestLog>(options.log_requests, *s.metrics);
  std::vector<ScopedToken> tokens = options.auth_tokens;
  if (options.check_shard_owner && !options.cluster_token.empty()) {
    tokens.push_back({.scope = TokenScope::kCluster, .token = options.cluster_token});
  }
  s.access = std::make_unique<AccessControl>(AccessOptions{.tokens = std::move(tokens)});
  s.gate = std::make_unique<CallGate>(options.threads, options.max_waiting_calls, s.access.get());
  s.watchdog = std::make_unique<StreamWatchdog>(
      StreamLimits{.idle_timeout = std::chrono::seconds(options.stream_idle_timeout_s),
                   .min_bytes_per_s = options.uploads.min_bytes_per_s,
                   .rate_grace = options.uploads.rate_grace});
  const AnswerLimit answers(int64_t{options.max_answer_mb} << 20);
  if (options.clip_routing) {
    s.clips = std::make_unique<RoutedClipServiceImpl>(
        options.uploads, *s.uploads, *s.watchdog, *s.gate, answers,
        int64_t{options.max_message_mb} << 20, options.clip_routing, options.cluster_token);
  } else {
    s.clips = std::make_unique<ClipServiceImpl>(*s.database, *s.catalog, options.uploads, answers,
                                                *s.uploads, *s.watchdog, *s.metrics, *s.gate);
  }
  s.spaces =
      std::make_unique<SpaceServiceImpl>(*s.database, *s.catalog, s.registry, answers, *s.gate);
  s.search = std::make_unique<SearchServiceImpl>(*s.runner, answers, *s.metrics, *s.gate);
  s.labels = std::make_unique<LabelServiceImpl>(*s.database, answers, *s.gate);
  s.job_service = std::make_unique<JobServiceImpl>(*s.jobs, *s.gate);
  s.info = std::make_unique<ServerInfoServiceImpl>(*s.database, s.registry, s.options, *s.access,
                                                   *s.gate);
  s.edits = std::make_unique<EditServiceImpl>(
      EditContext{*s.database, *s.catalog, s.registry, options.max_query_frames, answers}, *s.gate);
  if (options.check_shard_owner) {
    s.shard = std::make_unique<ShardServiceImpl>(*s.catalog, options.uploads, *s.uploads,
                                                 *s.metrics, *s.gate, options.check_shard_owner);
  }

  MOTIONDB_ASSIGN_OR_RETURN(
      const std::shared_ptr<grpc::ServerCredentials> credentials,
      MakeServerCredentials(options.tls_cert_pem, options.tls_key_pem, *s.access,
                            options.health_needs_token, *s.request_log));
  // Reflection describes services from the generated descriptor pool, which holds health.proto
  // only if its generated code is linked in; naming a message of it makes sure it is.
  (void)grpc::health::v1::HealthCheckRequest::descriptor();
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();

  // The port is ours (server/net/listener.h: connection limits, accept errors survived);
  // gRPC is handed each connection, with the port's credentials (TLS, the token check).
  MOTIONDB_ASSIGN_OR_RETURN(s.listener, Listener::Bind(ListenerOptions{
                                            .listen = options.listen,
                                            .face = "gRPC",
                                            .flag = "--listen",
                                            .limits = options.connections,
                                            .log = [](absl::string_view line) { LogLine(line); }}));
  grpc::ServerBuilder builder;
  s.acceptor = builder.experimental().AddExternalConnectionAcceptor(
      grpc::ServerBuilder::experimental_type::ExternalConnectionType::FROM_FD, credentials);
  // A connection that has not finished its handshake (TLS, HTTP/2 preface) by then is closed:
  // a silent socket must not hold its place for gRPC's default two minutes.
  builder.AddChannelArgument(GRPC_ARG_SERVER_HANDSHAKE_TIMEOUT_MS, 10'000);
  if (options.connection_idle_timeout_s > 0) {
    builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_IDLE_MS,
                               options.connection_idle_timeout_s * 1000);
  }
  builder.RegisterService(s.clips.get());
  builder.RegisterService(s.spaces.get());
  builder.RegisterService(s.search.get());
  builder.RegisterService(s.labels.get());
  builder.RegisterService(s.job_service.get());
  builder.RegisterService(s.info.get());
  builder.RegisterService(s.edits.get());
  if (s.shard) builder.RegisterService(s.shard.get());
  builder.SetMaxReceiveMessageSize(options.max_message_mb << 20);
  // Always: the metrics count every call, whether or not lines are written.
  std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>> loggers;
  loggers.push_back(std::make_unique<RequestLoggerFactory>(*s.request_log));
  loggers.push_back(std::make_unique<AccessInterceptorFactory>(*s.access));
  builder.experimental().SetInterceptorCreators(std::move(loggers));
  s.server = builder.BuildAndStart();
  if (s.server == nullptr) {
    return absl::UnavailableError(absl::StrCat("cannot serve gRPC on ", options.listen,
                                               " (an unusable TLS certificate or key?)"));
  }
  const int port = s.listener->port();
  s.listener->Start(
      [&s](AcceptedConnection connection) {
        grpc::experimental::ExternalConnectionAcceptor::NewConnectionParameters handed;
        handed.fd = connection.socket.get();
        s.handed_off.Add(handed.fd, std::move(connection.slot));
        connection.socket.Release();  // gRPC closes it
        s.acceptor->HandleNewConnection(&handed);
      },
      /*refuse=*/nullptr, [&s] { s.handed_off.Sweep(); });
  s.metrics->SetConnectionSource(kGrpcFace, [&s] { return s.listener->connections().open(); });
  LogLine(absl::StrCat("motiondb-server ", MOTIONDB_VERSION, " listening on ", options.listen,
                       port != 0 ? absl::StrCat(" (port ", port, ")") : "",
                       options.tls_cert_pem.empty() ? ", plain text" : ", TLS",
                       options.auth_tokens.empty() ? "" : ", bearer token required"));
  auto server = std::unique_ptr<MotionDbServer>(new MotionDbServer(std::move(state)));
  server->port_ = port;
  return server;
}

void MotionDbServer::Shutdown(std::chrono::system_clock::time_point deadline) {
  state_->listener->Stop();
  // Health turns NOT_SERVING first, so load balancers and waiting clients look elsewhere.
  if (grpc::HealthCheckServiceInterface* health = state_->server->GetHealthCheckService()) {
    health->SetServingStatus(false);
  }
  // Jobs are asked to end first, as interrupted, so that their watchers see the end before the
  // calls close; the worker is joined only after the server shut down, so that a job slow to
  // notice does not hold the shutdown past its deadline.
  state_->jobs->RequestStop();
  state_->server->Shutdown(deadline);
  state_->jobs->Stop();
}

void MotionDbServer::Wait() { state_->server->Wait(); }

void MotionDbServer::SetServing(bool serving) {
  if (grpc::HealthCheckServiceInterface* health = state_->server->GetHealthCheckService()) {
    health->SetServingStatus(serving);
  }
}

std::shared_ptr<grpc::Channel> MotionDbServer::InProcessChannel() const {
  grpc::ChannelArguments arguments;
  // Responses are limited by what the services make, as on the network (gRPC clients default
  // to 4 MiB, less than a long clip's poses).
  arguments.SetMaxReceiveMessageSize(-1);
  return state_->server->InProcessChannel(arguments);
}

bool MotionDbServer::accepting() const { return state_->listener->accepting(); }

ServerMetrics& MotionDbServer::metrics() const { return *state_->metrics; }

UploadBudget& MotionDbServer::upload_budget() const { return *state_->uploads; }

AccessControl& MotionDbServer::access() const { return *state_->access; }

RequestLog& MotionDbServer::request_log() const { return *state_->request_log; }

const ServerOptions& MotionDbServer::options() const { return state_->options; }

}  // namespace motiondb::server
