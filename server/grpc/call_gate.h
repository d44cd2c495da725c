// Admission of calls: the caller's right to make it (server/grpc/access_control.h), then, when
// the server runs at most N at once (--threads), a place: a call beyond N waits in line (first
// come, first served) until a slot frees, its deadline passes or the client cancels; only past
// `max_waiting` waiting calls is it refused with RESOURCE_EXHAUSTED.
//
// Why not gRPC's own thread quota (ResourceQuota::SetMaxThreads): it refuses calls even below
// its limit, because its poller accounting races with finishing calls (grpc/grpc#32680; seen
// here as "Server Threadpool Exhausted" with 5 calls at a quota of 10), and it never queues, so
// a burst of N + 1 cheap calls fails one of them.
//
// Thread-safe.
#ifndef MOTIONDB_SERVER_GRPC_CALL_GATE_H_
#define MOTIONDB_SERVER_GRPC_CALL_GATE_H_

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>

#include <grpcpp/server_context.h>
#include <grpcpp/support/status.h>

#include "server/grpc/access_control.h"

namespace motiondb::server {

class CallGate {
 public:
  // `max_running` 0: no limit (every call runs at once, as gRPC's thread pool allows).
  // `access` null: every call may run (tests of admission alone); it must outlive the gate.
  CallGate(int max_running, int max_waiting, const AccessControl* access = nullptr)
      : max_running_(max_running), max_waiting_(max_waiting), access_(access) {}

  // Runs `call` once allowed and admitted; otherwise the refusal: the access check's
  // (UNAUTHENTICATED, PERMISSION_DENIED, RESOURCE_EXHAUSTED), RESOURCE_EXHAUSTED when the line
  // is full, DEADLINE_EXCEEDED or CANCELLED when the call ends while waiting.
  grpc::Status Run(const grpc::ServerContext* context, const std::function<grpc::Status()>& call);
  // The access check alone, for what must be refused before it reads its client's stream (an
  // upload, which reads before it takes a place: waiting for bytes holds no place).
  grpc::Status Allowed(const grpc::ServerContext* context) const;

  int max_running() const { return max_running_; }
  // Calls waiting now (for the request log and tests).
  int waiting() const;

 private:
  // True once admitted (a slot is then held); false with `refusal` set otherwise.
  bool Enter(const grpc::ServerContext* context, grpc::Status* refusal);
  void Leave();

  const int max_running_;
  const int max_waiting_;
  const AccessControl* const access_;
  mutable std::mutex mutex_;
  std::condition_variable freed_;
  int running_ = 0;
  uint64_t next_ticket_ = 0;
  std::deque<uint64_t> line_;  // tickets of the waiting calls, first come first
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_CALL_GATE_H_
