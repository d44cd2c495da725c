// A socket descriptor closed when its owner goes: accepted connections change hands (listener,
// HTTP connection, gRPC) and none may leak on an early return.
#ifndef MOTIONDB_SERVER_NET_SOCKET_FD_H_
#define MOTIONDB_SERVER_NET_SOCKET_FD_H_

#include <unistd.h>

#include <utility>

namespace motiondb::server {

class SocketFd {
 public:
  SocketFd() = default;
  explicit SocketFd(int fd) : fd_(fd) {}
  SocketFd(SocketFd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  SocketFd& operator=(SocketFd&& other) noexcept {
    if (this != &other) {
      Reset();
      fd_ = std::exchange(other.fd_, -1);
    }
    return *this;
  }
  ~SocketFd() { Reset(); }

  int get() const { return fd_; }
  bool valid() const { return fd_ >= 0; }
  // The descriptor, no longer closed by this (given to gRPC, which closes it).
  int Release() { return std::exchange(fd_, -1); }
  void Reset() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_NET_SOCKET_FD_H_
