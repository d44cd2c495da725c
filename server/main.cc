// motiondb-server: the networked motion-search database.
//
//   motiondb-server [--db ./motiondb.sqlite] [--listen 127.0.0.1:50051] [--threads N]
//       [--max-message-mb 256] [--max-bvh-mb 1024] [--auth-token-file FILE]
//       [--tls-cert CERT.pem --tls-key KEY.pem] [--http 127.0.0.1:8080|off] [--web-root DIR]
//       [--http-allowed-hosts HOSTS] [--http-cors-origins ORIGINS] [--quiet]
//       [--cluster ETCD_ENDPOINTS --node-id ID [--role shard|router] [--cluster-name NAME]
//        [--advertise HOST[:PORT]]]
//
// (`--help` lists them with their defaults; they are parsed with CLI11.)
// Runs until SIGTERM or SIGINT, then stops accepting calls, lets running ones finish (up to 10 s)
// and exits 0.
#include <malloc.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/time/time.h"
#include "cluster/cluster_keys.h"
#include "cluster/cluster_node.h"
#include "cluster/node_address.h"
#include "server/grpc/motiondb_server.h"
#include "server/grpc/request_logger.h"
#include "server/grpc/server_options.h"
#include "server/http/http_server.h"
#include "server/net/descriptor_limit.h"
#include "storage/record_limits.h"
#include "util/cli_conventions.h"
#include "util/file_io.h"
#include "util/status_macros.h"
#include "util/token_file.h"

namespace {

// Secrets and certificates are small; anything larger is a wrong path.
constexpr int64_t kMaxSecretFileBytes = int64_t{1} << 20;
// How long running calls may finish after SIGTERM/SIGINT before they are cancelled.
constexpr std::chrono::seconds kShutdownGrace(10);

// What the flags name: the secret files read, the sizes converted.
struct ServerFlags {
  int http_request_timeout_s = 10;
  int min_upload_kbps = 64;
  int max_bvh_mb = 0;
  int max_upload_buffer_mb = 0;
  int max_import_mb = 0;
  int max_import_s = 0;
  std::string auth_token_file, tls_cert, tls_key;
  bool quiet = false;
};

// The cluster a node joins (cluster/); none without --cluster.
struct ClusterFlags {
  std::string etcd;
  std::string advertise;
  std::string token_file;
  motiondb::cluster::ClusterOptions options;
  int lease_s = 5;
};

void AddClusterFlags(CLI::App& app, ClusterFlags* cluster) {
  CLI::Option* etcd = app.add_option("--cluster", cluster->etcd,
                                     "join the cluster kept in this etcd (its members' HOST:PORT, "
                                     "comma-separated); without it, a single node")
                          ->type_name("ETCD_ENDPOINTS");
  app.add_option("--node-id", cluster->options.node.node_id,
                 "with --cluster: this node's id, unique among the cluster's live nodes")
      ->type_name("ID")
      ->needs(etcd);
  motiondb::cli::OneOf(app.add_option("--role", cluster->options.node.role,
                                      "with --cluster: hold shards, or route (a router routes "
                                      "ingests so far: ARCHITECTURE.md)"),
                       {"shard", "router"})
      ->capture_default_str()
      ->needs(etcd);
  app.add_option("--cluster-name", cluster->options.cluster,
                 "with --cluster: the cluster's name, its etcd keys' prefix")
      ->type_name("NAME")
      ->capture_default_str()
      ->needs(etcd);
  app.add_option("--advertise", cluster->advertise,
                 "with --cluster: where other nodes reach this one (HOST, or HOST:PORT when a "
                 "proxy or a Service's port stands between); default: the --listen host at the "
                 "port served, a wildcard host replaced by this machine's name")
      ->type_name("HOST[:PORT]")
      ->needs(etcd);
  app.add_option("--cluster-lease-s", cluster->lease_s,
                 "with --cluster: a node that stops renewing its registration is dropped after "
                 "this long")
      ->type_name("S")
      ->capture_default_str()
      ->check(CLI::Range(2, 3600).description(""))
      ->needs(etcd);
  app.add_option("--cluster-token-file", cluster->token_file,
                 "with --cluster: the cluster's own token, a secret every node is given: a router "
                 "presents it to the shard nodes, a shard node accepts it (scope 'cluster', which "
                 "the routers' calls need) beside --auth-token-file's; given with "
                 "--auth-token-file, and only then")
      ->type_name("FILE")
      ->check(motiondb::cli::ExistingFile())
      ->needs(etcd);
}

// The cluster options the flags give, checked before anything starts.
absl::Status ReadClusterFlags(ClusterFlags* cluster) {
  if (cluster->etcd.empty()) return absl::OkStatus();
  MOTIONDB_ASSIGN_OR_RETURN(cluster->options.etcd.endpoints,
                            motiondb::cluster::ParseEtcdEndpoints(cluster->etcd));
  if (cluster->options.node.node_id.empty()) {
    return absl::InvalidArgumentError("--cluster needs --node-id");
  }
  MOTIONDB_RETURN_IF_ERROR(
      motiondb::cluster::CheckClusterName(cluster->options.cluster, "--cluster-name"));
  MOTIONDB_RETURN_IF_ERROR(
      motiondb::cluster::CheckClusterName(cluster->options.node.node_id, "--node-id"));
  // The port is known once bound (JoinCluster); the rest is checked now.
  MOTIONDB_RETURN_IF_ERROR(
      motiondb::cluster::AdvertisedAddress(cluster->advertise, "", 1, "").status());
  cluster->options.lease_ttl = absl::Seconds(cluster->lease_s);
  cluster->options.log = [](const std::string& line) { motiondb::server::LogLine(line); };
  return absl::OkStatus();
}

// The cluster's own token (--cluster-token-file) into `options`, checked against the client
// tokens already read from `auth_token_file`.
absl::Status ReadClusterToken(const ClusterFlags& cluster, const std::string& auth_token_file,
                              motiondb::server::ServerOptions* options) {
  // Both or neither: a router given the cluster's token but no client tokens would lend that
  // token to every caller.
  if (!cluster.etcd.empty() && auth_token_file.empty() != cluster.token_file.empty()) {
    return absl::InvalidArgumentError(
        "--cluster: --auth-token-file and --cluster-token-file go together (the cluster's token "
        "is what its nodes present to each other, the same file on every node)");
  }
  if (cluster.token_file.empty()) return absl::OkStatus();
  MOTIONDB_ASSIGN_OR_RETURN(std::string token, motiondb::ReadTokenFile(cluster.token_file));
  for (const motiondb::ScopedToken& client_token : options->auth_tokens) {
    if (client_token.token == token) {
      return absl::InvalidArgumentError(
          "--cluster-token-file: the cluster's token is also one of --auth-token-file's; it must "
          "be a secret of its own, which no client holds");
    }
  }
  options->cluster_token = std::move(token);
  return absl::OkStatus();
}

// The cluster node once it has joined, for a shard's checks and a router's routes: the server
// starts serving first, since the node advertises the port it listens on.
class JoinedNode final : public motiondb::server::ClipRouting {
 public:
  void Join(std::shared_ptr<motiondb::cluster::ClusterNode> node) {
    std::lock_guard<std::mutex> lock(mutex_);
    node_ = std::move(node);
  }
  // A call under way may hold the node a moment longer; it leaves the cluster when that ends.
  void Leave() {
    std::lock_guard<std::mutex> lock(mutex_);
    node_.reset();
    left_ = true;
  }
  absl::Status CheckClipOwner(int64_t clip_id, absl::Time deadline) const {
    MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<motiondb::cluster::ClusterNode> node, Get());
    return node->CheckClipOwner(clip_id, deadline);
  }
  absl::StatusOr<motiondb::cluster::ClipRoute> Route(const std::string& clip_name,
                                                     absl::Time deadline) override {
    MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<motiondb::cluster::ClusterNode> node, Get());
    return node->RouteClip(clip_name, deadline);
  }
  absl::Status Settle(const std::string& clip_name, const motiondb::cluster::ClipRoute& route,
                      std::optional<int64_t> stored_clip_id) override {
    MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<motiondb::cluster::ClusterNode> node, Get());
    return node->SettleClip(clip_name, route, stored_clip_id);
  }
  absl::StatusOr<motiondb::cluster::ClipRoute> Locate(int64_t clip_id, bool refresh) override {
    MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<motiondb::cluster::ClusterNode> node, Get());
    return node->LocateClip(clip_id, refresh);
  }
  absl::Status ReserveName(const std::string& clip_name, int64_t clip_id,
                           const motiondb::cluster::ClipRouter::StillNamed& still_named) override {
    MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<motiondb::cluster::ClusterNode> node, Get());
    return node->ReserveClipName(clip_name, clip_id, still_named);
  }
  absl::Status ReleaseName(const std::string& clip_name, int64_t clip_id) override {
    MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<motiondb::cluster::ClusterNode> node, Get());
    return node->ReleaseClipName(clip_name, clip_id);
  }
  absl::StatusOr<std::vector<motiondb::cluster::ShardNode>> ShardNodes(bool refresh) override {
    MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<motiondb::cluster::ClusterNode> node, Get());
    return node->ShardNodes(refresh);
  }

 private:
  absl::StatusOr<std::shared_ptr<motiondb::cluster::ClusterNode>> Get() const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (node_ != nullptr) return node_;
    return absl::UnavailableError(left_ ? "this node has left its cluster (it is stopping)"
                                        : "this node is not in its cluster yet");
  }

  mutable std::mutex mutex_;
  std::shared_ptr<motiondb::cluster::ClusterNode> node_;
  bool left_ = false;
};

// Joins the cluster as the node at `server`'s port: ready (health, /readyz) only while
// registered.
absl::StatusOr<std::unique_ptr<motiondb::cluster::ClusterNode>> JoinCluster(
    ClusterFlags& cluster, const std::string& listen, motiondb::server::MotionDbServer& server) {
  MOTIONDB_ASSIGN_OR_RETURN(
      cluster.options.node.address,
      motiondb::cluster::AdvertisedAddress(cluster.advertise, listen, server.port(),
                                           motiondb::cluster::MachineHostName()));
  server.SetServing(false);
  return motiondb::cluster::ClusterNode::Start(
      cluster.options, [&server](bool registered) { server.SetServing(registered); });
}

void AddHttpFlags(CLI::App& app, motiondb::server::HttpOptions* http, ServerFlags* flags) {
  app.add_option("--http", http->listen,
                 "serve the JSON API, /metrics and the web UI over HTTP here (off: not at all; "
                 "the token and TLS of gRPC apply)")
      ->type_name("HOST:PORT")
      ->capture_default_str();
  app.add_option("--web-root", http->web_root, "the built web UI served at /")
      ->type_name("DIR")
      ->default_str(motiondb::server::DefaultWebRoot());
  app.add_option("--http-allowed-hosts", http->allowed_hosts,
                 "Host header names HTTP answers to beside IP addresses and localhost, "
                 "comma-separated, without ports; * for any")
      ->type_name("HOSTS")
      ->delimiter(',');
  app.add_option("--http-cors-origins", http->cors_origins,
                 "origins whose pages may call the API (CORS), comma-separated, e.g. "
                 "https://studio.example; none by default")
      ->type_name("ORIGINS")
      ->delimiter(',');
  app.add_option("--http-timeout-s", http->call_timeout_s,
                 "an HTTP API call still running after this long ends with 504")
      ->type_name("S")
      ->capture_default_str()
      ->check(motiondb::cli::NumberAbove(0));
  http->loop.threads =
      std::max(http->loop.threads, 2 * static_cast<int>(std::thread::hardware_concurrency()));
  app.add_option("--http-threads", http->loop.threads,
                 "HTTP requests answered at once (each arrived whole)")
      ->type_name("N")
      ->capture_default_str()
      ->check(CLI::Range(1, 4096).description(""));
  app.add_option("--http-max-waiting", http->loop.max_waiting,
                 "HTTP requests waiting for --http-threads; beyond, 503")
      ->type_name("N")
      ->capture_default_str()
      ->check(CLI::Range(0, 1 << 16).description(""));
  app.add_option("--http-max-connections", http->connections.max_connections,
                 "HTTP connections held at once; beyond, new ones get 503")
      ->type_name("N")
      ->capture_default_str()
      ->check(CLI::Range(1, 1 << 20).description(""));
  app.add_option("--http-request-timeout-s", flags->http_request_timeout_s,
                 "an HTTP request's head must arrive within this of its first byte (408)")
      ->type_name("S")
      ->capture_default_str()
      ->check(CLI::Range(1, 3600).description(""));
}

void AddFlags(CLI::App& app, motiondb::server::ServerOptions* options, ServerFlags* flags) {
  const CLI::Validator existing_file = motiondb::cli::ExistingFile();
  app.add_option("--db", options->db_path, "SQLite database, created when missing")
      ->type_name("FILE")
      ->capture_default_str();
  app.add_option("--listen", options->listen, "address to serve on (port 0 picks one)")
      ->type_name("HOST:PORT")
      ->capture_default_str();
  // A whole-number flag in [min, max] whose help shows its default.
  const auto number = [&app](const char* name, int& value, const char* help, const char* unit,
                             int min, int max) {
    app.add_option(name, value, help)
        ->type_name(unit)
        ->capture_default_str()
        ->check(CLI::Range(min, max).description(""));
  };
  number("--threads", options->threads, "most calls run at once (0: no limit)", "N", 0, 1 << 16);
  number("--max-waiting", options->max_waiting_calls,
         "with --threads: most calls waiting their turn", "N", 0, 1 << 16);
  number("--max-connections", options->connections.max_connections,
         "gRPC connections held at once; beyond, new ones are closed", "N", 1, 1 << 20);
  number("--max-connections-per-peer", options->connections.max_per_peer,
         "connections one client address holds at once, on each port", "N", 1, 1 << 20);
  number("--connection-idle-timeout-s", options->connection_idle_timeout_s,
         "close a gRPC connection without a call for this long (0: never)", "S", 0, 1 << 20);
  number("--min-upload-kbps", flags->min_upload_kbps,
         "an upload (a stream's chunks, an HTTP body) slower than this on average, after its "
         "first --http-request-timeout-s, is ended",
         "KIB_S", 1, 1 << 20);
  number("--max-message-mb", options->max_message_mb, "largest request message, in MiB", "MB", 1,
         2047);
  number("--max-answer-mb", options->max_answer_mb,
         "largest answer, in MiB: larger ones are refused before they are made", "MB", 1,
         motiondb::server::kMaxAnswerMbCeiling);
  flags->max_bvh_mb = static_cast<int>(options->uploads.max_bvh_bytes >> 20);
  number("--max-bvh-mb", flags->max_bvh_mb,
         "largest motion file upload (BVH, FBX, glTF), streamed or not, in MiB", "MB", 1, 1 << 20);
  app.add_option("--scene-importer", options->uploads.scene_importer,
                 "the program that reads FBX and glTF uploads, in a process of its own (default: "
                 "motiondb-scene-import beside this program)")
      ->type_name("PATH");
  flags->max_import_mb = static_cast<int>(options->uploads.max_import_bytes >> 20);
  number("--max-import-mb", flags->max_import_mb,
         "memory (address space) an FBX or glTF file's reading may take, in MiB", "MB", 64,
         1 << 20);
  flags->max_import_s = static_cast<int>(
      std::chrono::duration_cast<std::chrono::seconds>(options->uploads.max_import_time).count());
  number("--max-import-s", flags->max_import_s,
         "longest an FBX or glTF file's reading may take, in seconds", "S", 1, 1 << 20);
  number("--max-uploads", options->uploads.max_uploads, "most ingests in progress at once", "N", 1,
         1 << 16);
  flags->max_upload_buffer_mb = static_cast<int>(options->uploads.max_buffered_bytes >> 20);
  number("--max-upload-buffer-mb", flags->max_upload_buffer_mb,
         "most bytes the ingests in progress hold together, in MiB", "MB", 1, 1 << 20);
  number("--max-query-frames", options->max_query_frames,
         "longest search query, in frames at the space's rate", "N", 1, 1 << 20);
  number("--job-threads", options->job_threads,
         "threads a background job searches on, below calls' priority (0: one per core)", "N", 0,
         1024);
  number("--stream-idle-timeout-s", options->stream_idle_timeout_s,
         "end a client stream silent for this long (0: never)", "S", 0, 1 << 20);
  app.add_option("--auth-token-file", flags->auth_token_file,
                 "require 'authorization: Bearer <token>' of a token in FILE: one bare token "
                 "(every right), or lines 'SCOPE TOKEN' with SCOPE read, write or admin")
      ->type_name("FILE")
      ->check(existing_file);
  CLI::Option* cert = app.add_option("--tls-cert", flags->tls_cert, "serve TLS: certificate chain")
                          ->type_name("CERT.pem")
                          ->check(existing_file);
  CLI::Option* key = app.add_option("--tls-key", flags->tls_key, "... and private key (PEM)")
                         ->type_name("KEY.pem")
                         ->check(existing_file);
  cert->needs(key);
  key->needs(cert);
  app.add_flag("--health-needs-token", options->health_needs_token,
               "with a token file: the health service needs the token too");
  app.add_flag("--quiet", flags->quiet, "no per-request log lines");
  // Hidden (no group): for tests only, see ServerOptions::test_job_pause_after.
  app.add_option("--test-job-pause-after", options->test_job_pause_after)->group("");
  app.footer(
      "With --threads, further calls wait their turn (first come, first served, until their\n"
      "deadline); beyond --max-waiting they are refused with RESOURCE_EXHAUSTED. The token\n"
      "file's surrounding whitespace is ignored.");
}

// Lowers the ports' connection limits, when the open-file limit cannot hold them both beside
// what the process needs otherwise, and says so; limits given on the command line are kept
// (with a warning: the ports then survive running out of descriptors, refusing meanwhile).
void FitConnectionsToDescriptors(const CLI::App& app, motiondb::server::ConnectionLimits& grpc,
                                 motiondb::server::ConnectionLimits* http) {
  const int descriptors = motiondb::server::RaiseOpenFileLimit();
  const int64_t wanted = int64_t{grpc.max_connections} + (http ? http->max_connections : 0);
  const int64_t room = std::max(descriptors - motiondb::server::kReservedDescriptors, 2);
  if (wanted <= room) return;
  if (app.count("--max-connections") > 0 || app.count("--http-max-connections") > 0) {
    motiondb::server::LogLine(absl::StrCat(
        "the open-file limit (", descriptors, ") holds about ", room,
        " connections beside the server's own files, fewer than the ", wanted,
        " the connection limits allow: past it, new connections are refused until descriptors "
        "free up (raise `ulimit -n`)"));
    return;
  }
  grpc.max_connections =
      static_cast<int>(std::max<int64_t>(1, grpc.max_connections * room / wanted));
  if (http) {
    http->max_connections =
        static_cast<int>(std::max<int64_t>(1, http->max_connections * room / wanted));
  }
  for (auto* limits : {&grpc, http}) {
    if (limits) limits->max_per_peer = std::min(limits->max_per_peer, limits->max_connections);
  }
  motiondb::server::LogLine(
      absl::StrCat("the open-file limit (", descriptors, ") holds ", room,
                   " connections beside the server's own files: --max-connections lowered to ",
                   grpc.max_connections,
                   http ? absl::StrCat(", --http-max-connections to ", http->max_connections) : "",
                   " (raise `ulimit -n` to keep them)"));
}

// Reads the files the flags name into `options`.
absl::Status ReadFlagFiles(const ServerFlags& flags, motiondb::server::ServerOptions* options) {
  options->uploads.max_bvh_bytes = int64_t{flags.max_bvh_mb} << 20;
  options->uploads.max_buffered_bytes = int64_t{flags.max_upload_buffer_mb} << 20;
  options->uploads.max_import_bytes = int64_t{flags.max_import_mb} << 20;
  options->uploads.max_import_time = std::chrono::seconds(flags.max_import_s);
  options->uploads.min_bytes_per_s = flags.min_upload_kbps * 1024.0;
  options->uploads.rate_grace = std::chrono::seconds(flags.http_request_timeout_s);
  if (!flags.auth_token_file.empty()) {
    MOTIONDB_ASSIGN_OR_RETURN(options->auth_tokens,
                              motiondb::ReadScopedTokenFile(flags.auth_token_file));
  }
  if (!flags.tls_cert.empty()) {
    MOTIONDB_ASSIGN_OR_RETURN(options->tls_cert_pem,
                              motiondb::ReadFileBytes(flags.tls_cert, kMaxSecretFileBytes));
    MOTIONDB_ASSIGN_OR_RETURN(options->tls_key_pem,
                              motiondb::ReadFileBytes(flags.tls_key, kMaxSecretFileBytes));
  }
  options->log_requests = !flags.quiet;
  return absl::OkStatus();
}

}  // namespace

int main(int argc, char** argv) {
  // Block the stop signals before any thread exists (gRPC's threads inherit the mask), so that
  // only sigwait() below receives them, outside of any signal handler.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  signal(SIGPIPE, SIG_IGN);  // a vanished client must not kill the server
#ifdef __GLIBC__
  // glibc's defaults keep the memory a growing library frees: each thread that contends for
  // malloc gets an arena of its own (up to 8 a core), every arena keeps what it frees, and
  // after the first large free glibc raises its mmap threshold (up to 32 MiB), so that upload
  // buffers and index copies come from the arenas too. One arena a core, and blocks from 2 MiB
  // always mapped (returned when freed), with index_registry.cc's trimming:
  // bench/notes/2026-12-05-memory-growth.md. Up to 32 MiB free at the top of each arena (so up to
  // 32 MiB a core when idle) stays mapped (128 KiB once the mmap threshold is set), so that an
  // export's or an edit's buffers (0.5-2 MB for 10 s at 120 fps) are reused from call to call, not
  // faulted in afresh: that was a fifth of their time (issue 16). MALLOC_ARENA_MAX,
  // MALLOC_MMAP_THRESHOLD_ and MALLOC_TRIM_THRESHOLD_ in the environment still rule.
  if (std::getenv("MALLOC_ARENA_MAX") == nullptr) {
    mallopt(M_ARENA_MAX, static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
  }
  if (std::getenv("MALLOC_MMAP_THRESHOLD_") == nullptr) mallopt(M_MMAP_THRESHOLD, 2 << 20);
  if (std::getenv("MALLOC_TRIM_THRESHOLD_") == nullptr) mallopt(M_TRIM_THRESHOLD, 32 << 20);
#endif

  CLI::App app(
      "motiondb-server: the networked motion-search database. Runs until SIGTERM or SIGINT, then\n"
      "stops accepting calls, lets running ones finish (up to 10 s) and exits 0.",
      "motiondb-server");
  motiondb::server::ServerOptions options;
  ServerFlags flags;
  AddFlags(app, &options, &flags);
  motiondb::server::HttpOptions http_options;
  AddHttpFlags(app, &http_options, &flags);
  ClusterFlags cluster;
  AddClusterFlags(app, &cluster);
  if (const std::optional<int> exit_code = motiondb::cli::ParseCommandLine(app, argc, argv)) {
    return *exit_code;
  }
  if (const absl::Status status = ReadFlagFiles(flags, &options); !status.ok()) {
    return motiondb::cli::UsageError(app, std::string(status.message()));
  }
  if (const absl::Status status = ReadClusterFlags(&cluster); !status.ok()) {
    return motiondb::cli::UsageError(app, std::string(status.message()));
  }
  if (const absl::Status status = ReadClusterToken(cluster, flags.auth_token_file, &options);
      !status.ok()) {
    return motiondb::cli::UsageError(app, std::string(status.message()));
  }
  if (!cluster.etcd.empty() && !flags.tls_cert.empty()) {
    return motiondb::cli::UsageError(
        app,
        "--cluster with --tls-cert: a cluster's nodes call each other in plain text (TLS "
        "between them is to come); run the cluster on a private network");
  }
  http_options.loop.head_timeout = std::chrono::seconds(flags.http_request_timeout_s);
  http_options.loop.min_body_rate = options.uploads.min_bytes_per_s;
  http_options.connections.max_per_peer = options.connections.max_per_peer;
  FitConnectionsToDescriptors(app, options.connections,
                              http_options.listen != "off" ? &http_options.connections : nullptr);
  const auto joined_node = std::make_shared<JoinedNode>();
  cluster.options.max_clip_name_bytes = motiondb::storage::kMaxNameBytes;
  if (!cluster.etcd.empty() && cluster.options.node.role == "shard") {
    options.check_shard_owner = [joined_node](int64_t clip_id, absl::Time deadline) {
      return joined_node->CheckClipOwner(clip_id, deadline);
    };
  }
  if (!cluster.etcd.empty() && cluster.options.node.role == "router") {
    options.clip_routing = joined_node;
  }
  absl::StatusOr<std::unique_ptr<motiondb::server::MotionDbServer>> server =
      motiondb::server::MotionDbServer::Start(options);
  if (!server.ok()) {
    std::cerr << "motiondb-server: " << server.status().message() << "\n";
    return 1;
  }
  std::unique_ptr<motiondb::server::HttpServer> http;
  if (http_options.listen != "off") {
    absl::StatusOr<std::unique_ptr<motiondb::server::HttpServer>> started =
        motiondb::server::HttpServer::Start(http_options, **server);
    if (!started.ok()) {
      std::cerr << "motiondb-server: " << started.status().message() << "\n";
      return 1;
    }
    http = *std::move(started);
  }
  if (!cluster.etcd.empty()) {
    absl::StatusOr<std::unique_ptr<motiondb::cluster::ClusterNode>> joined =
        JoinCluster(cluster, options.listen, **server);
    if (!joined.ok()) {
      std::cerr << "motiondb-server: " << joined.status().message() << "\n";
      return 1;
    }
    joined_node->Join(*std::move(joined));
  }
  int signal_number = 0;
  sigwait(&stop_signals, &signal_number);
  motiondb::server::LogLine(absl::StrCat(
      "received ", signal_number == SIGTERM ? "SIGTERM" : "SIGINT", "; shutting down"));
  // The HTTP face stops reading first (slow clients' half-sent requests closed), then gRPC lets
  // the calls under way, the HTTP face's among them, finish within the grace; what the HTTP
  // face still writes then is cut at the same deadline.
  const auto steady_deadline = std::chrono::steady_clock::now() + kShutdownGrace;
  // Leaving the cluster first (its lease revoked) tells the others at once, and ends the
  // registration's readiness changes before Shutdown() turns the health NOT_SERVING (unless a
  // call under way holds the node: it leaves when that call ends).
  joined_node->Leave();
  if (http) http->BeginStop();
  (*server)->Shutdown(std::chrono::system_clock::now() + kShutdownGrace);
  if (http) http->Stop(steady_deadline);
  http.reset();
  (*server)->Wait();
  server->reset();
  motiondb::server::LogLine("stopped");
  return 0;
}
