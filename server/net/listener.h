// A listening TCP port whose connections motiondb accepts itself, for both faces: the gRPC
// port hands them to gRPC (grpc::experimental::ExternalConnectionAcceptor), the HTTP port to
// its own connection loop. What it adds over a library's listener:
// - connections bounded in all and per client address (ConnectionCounter): beyond, a new
//   connection is closed on arrival (after `refuse` has had a word with it);
// - accept errors survived: out of descriptors (EMFILE, ENFILE), a spare descriptor is given up
//   to accept and close the waiting connection, so that the backlog does not wake the loop
//   forever, and the loop keeps accepting once descriptors free up. gRPC 1.51's own listener
//   stopped for good after one EMFILE (grpc/grpc#20418): a flood of idle HTTP sockets left the
//   gRPC port dead until a restart while health said OK;
// - whether the port can accept now (accepting()), for readiness.
//
// Thread-safe; one thread accepts.
#ifndef MOTIONDB_SERVER_NET_LISTENER_H_
#define MOTIONDB_SERVER_NET_LISTENER_H_

#include <sys/socket.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "server/net/connection_counter.h"
#include "server/net/socket_fd.h"

namespace motiondb::server {

struct ListenerOptions {
  // HOST:PORT; [V6]:PORT for an IPv6 address; port 0 picks a free one.
  std::string listen;
  // The face's name in log lines and errors ("gRPC", "HTTP"), and the flag that sets `listen`.
  std::string face;
  std::string flag{};
  ConnectionLimits limits;
  // Free-form log lines (refusals, at most one a second with counts; descriptor exhaustion).
  std::function<void(absl::string_view)> log;
};

struct AcceptedConnection {
  SocketFd socket;           // non-blocking, close-on-exec, TCP_NODELAY
  std::string peer_address;  // without the port; IPv4-mapped IPv6 as IPv4
  int peer_port = 0;
  ConnectionCounter::Slot slot;  // the connection's place; held as long as it is open
};

class Listener {
 public:
  // Takes an accepted connection. Runs on the accepting thread: it must not block.
  using Handler = std::function<void(AcceptedConnection)>;
  // Called with a connection that is refused, just before it is closed (may be empty): the
  // HTTP face writes a 503 to it. Must not block.
  using Refuser = std::function<void(int socket, absl::string_view reason)>;

  // Binds and listens (UNAVAILABLE naming the address when it cannot, INVALID_ARGUMENT for a
  // malformed one). Nothing is accepted before Start.
  static absl::StatusOr<std::unique_ptr<Listener>> Bind(const ListenerOptions& options);
  ~Listener();  // Stop()

  // Starts accepting on a thread of its own. `reclaim` (may be empty) is called about once a
  // second and before a connection is refused, so that places held for connections that have
  // since closed elsewhere (gRPC's) are given back first.
  void Start(Handler handler, Refuser refuse, std::function<void()> reclaim);
  // Stops accepting and closes the port (idempotent). Connections already handed on are not
  // touched.
  void Stop();

  int port() const { return port_; }
  // False while a new connection would be refused: the last accept found no descriptor free
  // (and none is yet), or every place is taken.
  bool accepting() const;
  ConnectionCounter& connections() { return counter_; }

  // Counts since start, for metrics and tests.
  int64_t accepted() const { return accepted_.load(); }
  int64_t refused() const { return refused_.load(); }
  int64_t descriptor_shortages() const { return shortages_.load(); }

 private:
  explicit Listener(const ListenerOptions& options);
  void Run();
  void AcceptReady(int listening);
  void Refuse(SocketFd socket, absl::string_view reason);
  // After an accept failed for want of a descriptor: the waiting connection, taken with the
  // spare descriptor, when descriptors have freed up; else an invalid socket, the connection (if
  // any) closed and the listener starved.
  SocketFd AcceptWithSpare(int listening, sockaddr_storage* address, socklen_t* length);
  void Starved(int error);
  void MaybeReclaim(bool force);
  void LogRefusals(bool force);

  const ListenerOptions options_;
  ConnectionCounter counter_;
  std::vector<SocketFd> listening_;
  SocketFd wake_;   // an eventfd that Stop() signals
  SocketFd spare_;  // given up when descriptors run out (see the class comment)
  int port_ = 0;
  Handler handler_;
  Refuser refuse_;
  std::function<void()> reclaim_;
  std::chrono::steady_clock::time_point last_reclaim_{};
  std::chrono::steady_clock::time_point last_forced_reclaim_{};
  std::chrono::steady_clock::time_point last_refusal_log_{};
  std::string last_refusal_;
  int64_t refusals_unlogged_ = 0;
  std::atomic<bool> starved_{false};
  std::atomic<int64_t> accepted_{0}, refused_{0}, shortages_{0};
  std::thread thread_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_NET_LISTENER_H_
