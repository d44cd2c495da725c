#include "server/net/handed_off_sockets.h"

#include <sys/stat.h>

namespace motiondb::server {
namespace {

// The socket's inode, or 0 when the descriptor is closed or not a socket.
ino_t SocketInode(int socket) {
  struct stat status {};
  if (fstat(socket, &status) != 0 || !S_ISSOCK(status.st_mode)) return 0;
  return status.st_ino;
}

}  // namespace

void HandedOffSockets::Add(int socket, ConnectionCounter::Slot slot) {
  const ino_t inode = SocketInode(socket);
  std::lock_guard<std::mutex> lock(mutex_);
  // A descriptor number seen before was closed in between: its old place goes back now.
  held_[socket] = Held{inode, std::move(slot)};
}

void HandedOffSockets::Sweep() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto it = held_.begin(); it != held_.end();) {
    const auto current = it++;
    if (SocketInode(current->first) != current->second.inode) held_.erase(current);
  }
}

int HandedOffSockets::held() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(held_.size());
}

}  // namespace motiondb::server
