// How many connections a port holds, in all and from each client address, against its limits.
// A connection is counted from its admission until its Slot is destroyed.
//
// Why per address: a flood from one client (a script gone wrong, 20,000 idle sockets) must
// leave room for everyone else; the total keeps the process's descriptors for what it needs.
//
// Thread-safe.
#ifndef MOTIONDB_SERVER_NET_CONNECTION_COUNTER_H_
#define MOTIONDB_SERVER_NET_CONNECTION_COUNTER_H_

#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "absl/container/flat_hash_map.h"

namespace motiondb::server {

struct ConnectionLimits {
  // Connections the port holds at once; beyond, new ones are closed on arrival.
  int max_connections = 1024;
  // Connections from one client address at once (every port of it).
  int max_per_peer = 64;
};

class ConnectionCounter {
 public:
  explicit ConnectionCounter(const ConnectionLimits& limits);
  ConnectionCounter(const ConnectionCounter&) = delete;
  ConnectionCounter& operator=(const ConnectionCounter&) = delete;

  // One admitted connection's place, given back when destroyed (which may happen after the
  // counter is gone: the place then goes nowhere).
  class Slot {
   public:
    Slot() = default;
    Slot(Slot&& other) noexcept = default;
    Slot& operator=(Slot&& other) noexcept;
    ~Slot();

   private:
    friend class ConnectionCounter;
    struct Shared;
    Slot(std::shared_ptr<Shared> shared, std::string peer)
        : shared_(std::move(shared)), peer_(std::move(peer)) {}
    void Release();

    std::shared_ptr<Shared> shared_;
    std::string peer_;
  };

  // A slot for a connection from `peer` (an address without port), or nullopt with `refusal`
  // saying which limit is reached.
  std::optional<Slot> TryAdmit(const std::string& peer, std::string* refusal);

  int open() const;
  int open_from(const std::string& peer) const;
  bool full() const;
  const ConnectionLimits& limits() const { return limits_; }

 private:
  const ConnectionLimits limits_;
  std::shared_ptr<Slot::Shared> shared_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_NET_CONNECTION_COUNTER_H_
