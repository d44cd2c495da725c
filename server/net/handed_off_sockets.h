// Places held for connections handed to a library that closes them itself (gRPC, through
// ExternalConnectionAcceptor, tells nobody when a connection ends): each is given back once its
// descriptor no longer refers to the socket handed off (closed, or reused for another file:
// sockets' inode numbers tell them apart).
//
// Thread-safe.
#ifndef MOTIONDB_SERVER_NET_HANDED_OFF_SOCKETS_H_
#define MOTIONDB_SERVER_NET_HANDED_OFF_SOCKETS_H_

#include <sys/types.h>

#include <mutex>

#include "absl/container/flat_hash_map.h"
#include "server/net/connection_counter.h"

namespace motiondb::server {

class HandedOffSockets {
 public:
  // Holds `slot` while `socket` stays the socket it is now. Call before handing it off.
  void Add(int socket, ConnectionCounter::Slot slot);
  // Gives back the places of the sockets that are gone. O(held) fstat calls.
  void Sweep();
  int held() const;

 private:
  struct Held {
    ino_t inode = 0;
    ConnectionCounter::Slot slot;
  };
  mutable std::mutex mutex_;
  absl::flat_hash_map<int, Held> held_;  // by descriptor; guarded by mutex_
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_NET_HANDED_OFF_SOCKETS_H_
