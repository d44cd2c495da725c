#include "server/net/listener.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>

#include <cerrno>
#include <cstring>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"

namespace motiondb::server {
namespace {

// Connections taken from the backlog on one wake-up before the loop looks at Stop() again.
constexpr int kAcceptsPerWake = 256;
// How often reclaim runs at most, and the loop wakes without a connection.
constexpr std::chrono::milliseconds kReclaimInterval{100};
constexpr int kTickMs = 1000;
// Refusals are told at most this often, with a count of those not told.
constexpr std::chrono::seconds kRefusalLogInterval{1};
// After a failed accept with no spare descriptor to give up, the loop rests this long rather
// than spin.
constexpr std::chrono::milliseconds kStarvedPause{10};

struct HostPort {
  std::string host;
  std::string port;
};

absl::StatusOr<HostPort> SplitListen(const std::string& listen, const std::string& flag) {
  const size_t colon = listen.rfind(':');
  int port = -1;
  if (colon == std::string::npos || !absl::SimpleAtoi(listen.substr(colon + 1), &port) ||
      port < 0 || port > 65535) {
    return absl::InvalidArgumentError(
        absl::StrCat(flag, ": '", listen, "' is not HOST:PORT (port 0..65535)"));
  }
  std::string host = listen.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);  // [::1]
  }
  return HostPort{host, std::to_string(port)};
}

int PortOf(int socket) {
  sockaddr_storage address{};
  socklen_t length = sizeof(address);
  if (getsockname(socket, reinterpret_cast<sockaddr*>(&address), &length) != 0) return 0;
  if (address.ss_family == AF_INET) {
    return ntohs(reinterpret_cast<const sockaddr_in&>(address).sin_port);
  }
  return ntohs(reinterpret_cast<const sockaddr_in6&>(address).sin6_port);
}

// The address without its port; an IPv4-mapped IPv6 address (a dual-stack port's IPv4 client)
// as IPv4, so that one client counts as one whichever way it came.
std::pair<std::string, int> PeerOf(const sockaddr_storage& address) {
  char text[INET6_ADDRSTRLEN] = {};
  if (address.ss_family == AF_INET) {
    const auto& v4 = reinterpret_cast<const sockaddr_in&>(address);
    inet_ntop(AF_INET, &v4.sin_addr, text, sizeof(text));
    return {text, ntohs(v4.sin_port)};
  }
  const auto& v6 = reinterpret_cast<const sockaddr_in6&>(address);
  if (IN6_IS_ADDR_V4MAPPED(&v6.sin6_addr)) {
    inet_ntop(AF_INET, &v6.sin6_addr.s6_addr[12], text, sizeof(text));
  } else {
    inet_ntop(AF_INET6, &v6.sin6_addr, text, sizeof(text));
  }
  return {text, ntohs(v6.sin6_port)};
}

SocketFd OpenSpare() { return SocketFd(::open("/dev/null", O_RDONLY | O_CLOEXEC)); }

}  // namespace

Listener::Listener(const ListenerOptions& options) : options_(options), counter_(options.limits) {}

Listener::~Listener() { Stop(); }

absl::StatusOr<std::unique_ptr<Listener>> Listener::Bind(const ListenerOptions& options) {
  absl::StatusOr<HostPort> host_port = SplitListen(options.listen, options.flag);
  if (!host_port.ok()) return host_port.status();
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const char* host = host_port->host.empty() ? nullptr : host_port->host.c_str();
  if (const int error = getaddrinfo(host, host_port->port.c_str(), &hints, &found); error != 0) {
    return absl::InvalidArgumentError(absl::StrCat(options.flag, ": cannot resolve '",
                                                   options.listen, "': ", gai_strerror(error)));
  }
  auto listener = std::unique_ptr<Listener>(new Listener(options));
  std::string failure = "no address";
  // Every address the host names ("localhost": 127.0.0.1 and ::1), all on the port the first
  // was given when the port is 0.
  for (const addrinfo* address = found; address != nullptr; address = address->ai_next) {
    SocketFd socket(
        ::socket(address->ai_family, address->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
    if (!socket.valid()) continue;
    const int yes = 1;
    // SO_REUSEADDR only: SO_REUSEPORT would let a second server share a port in use instead of
    // failing to start.
    setsockopt(socket.get(), SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
    if (address->ai_family == AF_INET6) {
      // "[::]" serves IPv4 clients too, as gRPC's own listener did.
      const int no = 0;
      setsockopt(socket.get(), IPPROTO_IPV6, IPV6_V6ONLY, &no, sizeof(no));
    }
    sockaddr_storage bound{};
    std::memcpy(&bound, address->ai_addr, address->ai_addrlen);
    if (listener->port_ != 0) {
      reinterpret_cast<sockaddr_in&>(bound).sin_port = htons(listener->port_);  // same offset
    }
    if (::bind(socket.get(), reinterpret_cast<const sockaddr*>(&bound), address->ai_addrlen) != 0 ||
        ::listen(socket.get(), SOMAXCONN) != 0) {
      failure = std::strerror(errno);
      continue;
    }
    if (listener->port_ == 0) listener->port_ = PortOf(socket.get());
    listener->listening_.push_back(std::move(socket));
  }
  freeaddrinfo(found);
  if (listener->listening_.empty()) {
    return absl::UnavailableError(
        absl::StrCat("cannot listen on ", options.listen, " for ", options.face, ": ", failure));
  }
  listener->wake_ = SocketFd(eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
  listener->spare_ = OpenSpare();
  if (!listener->wake_.valid() || !listener->spare_.valid()) {
    return absl::UnavailableError(
        absl::StrCat(options.face, ": no descriptor for the listener: ", std::strerror(errno)));
  }
  return listener;
}

void Listener::Start(Handler handler, Refuser refuse, std::function<void()> reclaim) {
  handler_ = std::move(handler);
  refuse_ = std::move(refuse);
  reclaim_ = std::move(reclaim);
  thread_ = std::thread([this] { Run(); });
}

void Listener::Stop() {
  if (wake_.valid()) {
    const uint64_t one = 1;
    const ssize_t written = ::write(wake_.get(), &one, sizeof(one));
    (void)written;  // an eventfd write fails only when the counter would overflow
  }
  if (thread_.joinable()) thread_.join();
  listening_.clear();
}

bool Listener::accepting() const { return !starved_.load() && !counter_.full(); }

void Listener::Run() {
  std::vector<pollfd> watched;
  for (const SocketFd& socket : listening_) watched.push_back({socket.get(), POLLIN, 0});
  watched.push_back({wake_.get(), POLLIN, 0});
  for (;;) {
    const int ready = ::poll(watched.data(), watched.size(), kTickMs);
    if (watched.back().revents != 0) break;  // Stop()
    if (ready > 0) {
      for (size_t i = 0; i + 1 < watched.size(); ++i) {
        if (watched[i].revents != 0) AcceptReady(watched[i].fd);
      }
    }
    MaybeReclaim(/*force=*/false);
    LogRefusals(/*force=*/false);
    if (starved_.load()) {
      // Descriptors may have freed up without a new connection to show it.
      if (!spare_.valid()) spare_ = OpenSpare();
      SocketFd probe(::fcntl(wake_.get(), F_DUPFD_CLOEXEC, 0));
      if (probe.valid() && spare_.valid()) starved_ = false;
    }
  }
  LogRefusals(/*force=*/true);
}

void Listener::AcceptReady(int listening) {
  for (int i = 0; i < kAcceptsPerWake; ++i) {
    sockaddr_storage address{};
    socklen_t length = sizeof(address);
    SocketFd socket(::accept4(listening, reinterpret_cast<sockaddr*>(&address), &length,
                              SOCK_NONBLOCK | SOCK_CLOEXEC));
    if (!socket.valid() &&
        (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM)) {
      socket = AcceptWithSpare(listening, &address, &length);
      // The backlog is empty, or its connection was closed for want of descriptors.
      if (!socket.valid()) return;
    }
    if (!socket.valid()) {
      // EAGAIN: the backlog is empty; ECONNABORTED, EINTR, a network error the connection
      // carried (EPROTO, ENETDOWN, ...): that connection only.
      if (errno == EAGAIN || errno == EWOULDBLOCK) return;
      continue;
    }
    starved_ = false;
    const int yes = 1;
    setsockopt(socket.get(), IPPROTO_TCP, TCP_NODELAY, &yes, sizeof(yes));
    auto [peer, peer_port] = PeerOf(address);
    std::string refusal;
    std::optional<ConnectionCounter::Slot> slot = counter_.TryAdmit(peer, &refusal);
    if (!slot) {
      MaybeReclaim(/*force=*/true);
      slot = counter_.TryAdmit(peer, &refusal);
    }
    if (!slot) {
      Refuse(std::move(socket), refusal);
      continue;
    }
    ++accepted_;
    handler_(AcceptedConnection{std::move(socket), std::move(peer), peer_port, std::move(*slot)});
  }
}

void Listener::Refuse(SocketFd socket, absl::string_view reason) {
  // The refuser has its word before the count moves, so that whoever sees the count sees it
  // told (a test that read the count first saw the refuser not yet called).
  if (refuse_) refuse_(socket.get(), reason);
  ++refused_;
  ++refusals_unlogged_;
  last_refusal_ = std::string(reason);
  LogRefusals(/*force=*/false);
}

SocketFd Listener::AcceptWithSpare(int listening, sockaddr_storage* address, socklen_t* length) {
  const int error = errno;
  if (!spare_.valid()) spare_ = OpenSpare();
  if (!spare_.valid()) {
    Starved(error);
    std::this_thread::sleep_for(kStarvedPause);
    return SocketFd();
  }
  // Linux takes the descriptor before it looks at the backlog, so the backlog may be empty, and
  // a connection may have come as descriptors freed up: take it with the spare's descriptor, and
  // keep it when the spare can be had again.
  spare_.Reset();
  SocketFd socket(::accept4(listening, reinterpret_cast<sockaddr*>(address), length,
                            SOCK_NONBLOCK | SOCK_CLOEXEC));
  spare_ = OpenSpare();
  if (socket.valid() && spare_.valid()) return socket;
  Starved(error);
  if (socket.valid()) {
    // Left in the backlog it would wake the loop again at once: closed.
    socket.Reset();
    spare_ = OpenSpare();
  }
  if (!spare_.valid()) std::this_thread::sleep_for(kStarvedPause);
  return SocketFd();
}

void Listener::Starved(int error) {
  // starved_ before the count, so that a reader who sees the count sees the listener starved.
  const bool already = starved_.exchange(true);
  ++shortages_;
  if (already || !options_.log) return;
  options_.log(absl::StrCat(options_.face, ": cannot accept a connection: ", std::strerror(error),
                            "; refusing connections until descriptors free up (raise "
                            "`ulimit -n`, or lower the connection limits)"));
}

void Listener::MaybeReclaim(bool force) {
  if (!reclaim_) return;
  const auto now = std::chrono::steady_clock::now();
  // Before a refusal at most every kReclaimInterval (a flood refuses thousands a second), else
  // once a second.
  auto& last = force ? last_forced_reclaim_ : last_reclaim_;
  if (now - last < (force ? kReclaimInterval : std::chrono::milliseconds(kTickMs))) return;
  last = now;
  reclaim_();
}

void Listener::LogRefusals(bool force) {
  if (refusals_unlogged_ == 0 || !options_.log) return;
  const auto now = std::chrono::steady_clock::now();
  if (!force && now - last_refusal_log_ < kRefusalLogInterval) return;
  last_refusal_log_ = now;
  options_.log(absl::StrCat(options_.face, ": refused ", refusals_unlogged_,
                            refusals_unlogged_ == 1 ? " connection" : " connections", " (",
                            last_refusal_, ")"));
  refusals_unlogged_ = 0;
}

}  // namespace motiondb::server
