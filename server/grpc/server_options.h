// What motiondb-server is told on its command line (server/main.cc parses the flags).
#ifndef MOTIONDB_SERVER_GRPC_SERVER_OPTIONS_H_
#define MOTIONDB_SERVER_GRPC_SERVER_OPTIONS_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "cluster/clip_router.h"
#include "server/answer_limit.h"
#include "server/net/connection_counter.h"
#include "server/search_runner.h"
#include "server/upload/upload.h"
#include "util/token_file.h"

namespace motiondb::server {

// A cluster router's routing of clip writes (cluster::ClipRouter; server/main.cc's holds the
// cluster node, which joins after the server starts). Thread-safe.
class ClipRouting {
 public:
  virtual ~ClipRouting() = default;
  virtual absl::StatusOr<cluster::ClipRoute> Route(const std::string& clip_name,
                                                   absl::Time deadline) = 0;
  virtual absl::Status Settle(const std::string& clip_name, const cluster::ClipRoute& route,
                              std::optional<int64_t> stored_clip_id) = 0;
  virtual absl::StatusOr<cluster::ClipRoute> Locate(int64_t clip_id, bool refresh) = 0;
  virtual absl::Status ReserveName(const std::string& clip_name, int64_t clip_id,
                                   const cluster::ClipRouter::StillNamed& still_named) = 0;
  virtual absl::Status ReleaseName(const std::string& clip_name, int64_t clip_id) = 0;
  virtual absl::StatusOr<std::vector<cluster::ShardNode>> ShardNodes(bool refresh) = 0;
};

struct ServerOptions {
  // The SQLite file; created when missing (--db).
  std::string db_path = "./motiondb.sqlite";
  // host:port to listen on; port 0 picks a free one, reported by MotionDbServer::port()
  // (--listen).
  std::string listen = "127.0.0.1:50051";
  // Most calls run at once; further calls wait their turn (server/grpc/call_gate.h). 0: no
  // limit (--threads).
  int threads = 0;
  // With `threads`, the most calls waiting; beyond, calls are refused with RESOURCE_EXHAUSTED.
  int max_waiting_calls = 64;
  // Connections the gRPC port holds at once, in all (--max-connections) and from one client
  // address (--max-connections-per-peer); beyond, a new connection is closed on arrival. Both
  // are lowered at start when the open-file limit cannot hold them (server/net/).
  ConnectionLimits connections;
  // A gRPC connection without a call for this long is closed; clients reconnect when they next
  // call (--connection-idle-timeout-s; 0: never).
  int connection_idle_timeout_s = 300;
  // Largest request message, in MiB: gRPC itself refuses larger ones with RESOURCE_EXHAUSTED
  // before any handler runs (--max-message-mb).
  int max_message_mb = 256;
  // Largest answer, in MiB, 1..kMaxAnswerMbCeiling: an answer that could be larger is refused
  // with RESOURCE_EXHAUSTED before it is made (server/answer_limit.h) (--max-answer-mb).
  int max_answer_mb = kDefaultMaxAnswerMb;
  // Largest BVH file accepted by IngestClip, IngestClipStream (all chunks together) and BVH
  // queries (--max-bvh-mb, in MiB).
  UploadLimits uploads;
  // Longest search query, in frames at the space's rate (a stored clip's range, an uploaded
  // file): longer ones are refused with INVALID_ARGUMENT before they are projected
  // (--max-query-frames).
  int max_query_frames = kDefaultMaxQueryFrames;
  // A client stream (IngestClipStream) that sends nothing for this long is ended, releasing
  // its thread (--stream-idle-timeout-s); 0: never.
  int stream_idle_timeout_s = 30;
  // When non-empty, every call must carry the metadata "authorization: Bearer <token>" of one
  // of them, whose scope the method needs (read from --auth-token-file).
  std::vector<ScopedToken> auth_tokens;
  // With a token: the health service needs it too (--health-needs-token); by default probes
  // answer without one.
  bool health_needs_token = false;
  // Threads a background job's searches run on, at a lower priority than calls (0: one per
  // core) (--job-threads).
  int job_threads = 0;
  // For tests only (--test-job-pause-after, hidden): a running job waits after this many of its
  // labels until it is cancelled or the server stops, so that tests see it running whatever
  // the machine's speed; -1: never.
  int test_job_pause_after = -1;
  // PEM certificate chain and private key: both serve TLS, neither plain text (read from
  // --tls-cert and --tls-key).
  std::string tls_cert_pem;
  std::string tls_key_pem;
  // One line per call on stderr (server/grpc/request_logger.h).
  bool log_requests = true;
  // Set on a cluster's shard node (server/main.cc): the node also serves
  // motiondb.shard.v1.ShardService (server/grpc/shard_service.h), storing what this check
  // finds its own. Unset: one node, or a router; no shard service.
  std::function<absl::Status(int64_t clip_id, absl::Time deadline)> check_shard_owner;
  // Set on a cluster's router (server/main.cc): ClipService's ingests go to their clips' shard
  // nodes (server/grpc/routed_clip_service.h) instead of this node's database.
  std::shared_ptr<ClipRouting> clip_routing;
  // A cluster's own token, a secret its nodes share (--cluster-token-file): a router presents it
  // on every call to a shard node in place of its caller's, whom it has checked itself; a shard
  // node grants it scope cluster, which ShardService needs. Empty: a router presents no token,
  // and a shard node's ShardService answers only when it needs none (no auth_tokens).
  std::string cluster_token;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_SERVER_OPTIONS_H_
