// The HTTP face's connections between requests: one thread reads every connection without
// blocking, and hands a request to a worker (server/http/worker_pool.h) only once it has arrived
// whole, head and body. So a slow or silent client costs a socket and its bytes, never a worker:
// 16 clients sending a header byte a second once held every worker, /healthz included, and kept
// SIGTERM from ending the server for 110 s. What the loop enforces, before a worker sees
// anything:
// - the head within `head_timeout` of its first byte, at most 64 KiB and 100 fields
//   (server/http/request_head.h), then `Hooks::check_head` (the token, the body's rules);
// - a body only with a Content-Length, counted in the uploads' budget
// (server/upload/upload_budget.h)
//   from before it is read until it is whole, arriving at `min_body_rate` or faster (after a
//   grace of `head_timeout`);
// - `idle_timeout` between a connection's requests, `handshake_timeout` for TLS;
// - a bounded line for the workers: a request that finds it full is refused with 503 at once.
// A refusal is written by the loop itself (`Connection: close`); the connection is closed after
// the client's remaining bytes have been read for a moment, so that the client sees the answer.
//
// Thread-safe: Add() from the accepting thread, the answers on workers, the rest on its thread.
#ifndef MOTIONDB_SERVER_HTTP_CONNECTION_LOOP_H_
#define MOTIONDB_SERVER_HTTP_CONNECTION_LOOP_H_

#include <openssl/ssl.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/string_view.h"
#include "server/http/http_connection.h"
#include "server/http/request_head.h"
#include "server/http/worker_pool.h"
#include "server/net/listener.h"
#include "server/net/socket_fd.h"
#include "server/upload/upload_budget.h"

namespace motiondb::server {

struct HttpLoopOptions {
  std::chrono::milliseconds handshake_timeout{10'000};
  // A request's head must arrive whole within this of its first byte (a whole-request
  // deadline, not one per read: a byte every few seconds does not keep it alive).
  std::chrono::milliseconds head_timeout{10'000};
  // A connection waits this long for its next request, then closes.
  std::chrono::milliseconds idle_timeout{5'000};
  // A body must arrive at this many bytes a second or faster, after `head_timeout`'s grace.
  double min_body_rate = 64 << 10;
  // Requests a connection carries before it is closed.
  int max_requests_per_connection = 1000;
  // How long a worker waits for a client to take a byte of its answer before giving up.
  std::chrono::milliseconds write_stall_timeout{30'000};
  int threads = 16;       // workers
  int max_waiting = 256;  // complete requests waiting for a worker; beyond, 503
};

struct HttpRefusal {
  HttpRefusal(int status, std::string message,
              std::vector<std::pair<std::string, std::string>> headers = {})
      : status(status), message(std::move(message)), headers(std::move(headers)) {}

  int status;
  std::string message;
  std::vector<std::pair<std::string, std::string>> headers;  // beyond the usual ones
};

class ConnectionLoop {
 public:
  struct Hooks {
    // A request whose head has arrived, before its body is read: a refusal, or nullopt to go on.
    std::function<std::optional<HttpRefusal>(const RequestHead&, const HttpConnection&)> check_head;
    // Answers a whole request (`request`: its head and body as sent) on a worker; `last` when the
    // connection will close after it. Returns whether the connection may carry another.
    std::function<bool(HttpConnection&, absl::string_view request, bool last)> answer;
    // A request the loop refused itself, for the log and the metrics; `head` is null when the
    // request's head had not arrived (or did not parse).
    std::function<void(const HttpConnection&, const RequestHead* head, const HttpRefusal&)> refused;
    // The body of a refusal (JSON).
    std::function<std::string(const HttpRefusal&)> error_body;
  };

  // `tls` (may be null: plain HTTP) and `budget` must outlive the loop.
  ConnectionLoop(const HttpLoopOptions& options, SSL_CTX* tls, UploadBudget& budget, Hooks hooks);
  ~ConnectionLoop();  // Stop(now)
  ConnectionLoop(const ConnectionLoop&) = delete;
  ConnectionLoop& operator=(const ConnectionLoop&) = delete;

  // Takes a new connection (any thread).
  void Add(AcceptedConnection connection);
  // Reads no more requests: every connection not being answered is closed, and those being
  // answered close once answered.
  void BeginStop();
  // BeginStop(), then waits for the answers under way until `deadline`, then cuts the
  // connections of those still writing, and returns once every worker is done.
  void Stop(std::chrono::steady_clock::time_point deadline);

  int open_connections() const { return open_.load(); }
  int busy_workers() const { return pool_.busy(); }

 private:
  struct Connection;
  enum class State;

  void Run();
  void TakeInbox();
  void Register(AcceptedConnection accepted);
  void OnEvent(int socket, uint32_t events);
  void ReadMore(Connection& connection);
  void Advance(Connection& connection);
  bool ReadHead(Connection& connection);
  void Dispatch(Connection& connection);
  void OnAnswered(int socket, bool keep);
  void Refuse(Connection& connection, const HttpRefusal& refusal);
  void Linger(Connection& connection);
  void Close(int socket);
  void Watch(int socket, bool writable, bool first);
  void ExpireDeadlines();
  void Wake();

  const HttpLoopOptions options_;
  SSL_CTX* const tls_;
  UploadBudget& budget_;
  const Hooks hooks_;
  SocketFd epoll_;
  SocketFd wake_;
  absl::flat_hash_map<int, std::unique_ptr<Connection>> connections_;  // the loop's thread only
  std::chrono::steady_clock::time_point last_expiry_{};
  bool stopped_reading_ = false;  // the loop's thread only

  std::mutex inbox_mutex_;
  std::condition_variable answered_;           // signalled when a worker is done, with inbox_mutex_
  std::vector<AcceptedConnection> arrivals_;   // guarded by inbox_mutex_
  std::vector<std::pair<int, bool>> answers_;  // guarded by inbox_mutex_
  int in_workers_ = 0;                         // guarded by inbox_mutex_
  bool stop_reading_ = false;                  // guarded by inbox_mutex_
  bool cut_busy_ = false;                      // guarded by inbox_mutex_
  bool exit_ = false;                          // guarded by inbox_mutex_

  std::atomic<int> open_{0};
  WorkerPool pool_;
  std::thread thread_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_HTTP_CONNECTION_LOOP_H_
