#include "server/http/connection_loop.h"

#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>

#include <algorithm>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace motiondb::server {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kTickMs = 100;  // how often deadlines are looked at
constexpr int kMaxEvents = 256;
// A refused connection's remaining bytes are read and dropped for this long, at most this many,
// so that closing it does not reset the connection before the client has read the refusal.
constexpr std::chrono::milliseconds kLingerTime{1'000};
constexpr size_t kMaxLingerBytes = 1 << 20;
// A buffer larger than this is given back to the allocator once its request is answered.
constexpr size_t kKeptBufferBytes = 1 << 20;

absl::string_view ReasonPhrase(int status) {
  switch (status) {
    case 400:
      return "Bad Request";
    case 401:
      return "Unauthorized";
    case 403:
      return "Forbidden";
    case 408:
      return "Request Timeout";
    case 411:
      return "Length Required";
    case 413:
      return "Payload Too Large";
    case 415:
      return "Unsupported Media Type";
    case 421:
      return "Misdirected Request";
    case 429:
      return "Too Many Requests";
    case 431:
      return "Request Header Fields Too Large";
    case 503:
      return "Service Unavailable";
    default:
      return "Error";
  }
}

}  // namespace

enum class ConnectionLoop::State {
  kHandshake,  // TLS handshake under way
  kIdle,       // between requests
  kHead,       // a request's head arriving
  kBody,       // its body arriving
  kBusy,       // with a worker (not watched)
  kLinger,     // refused: reading what the client still sends, then closing
};

struct ConnectionLoop::Connection {
  explicit Connection(std::unique_ptr<HttpConnection> io) : io(std::move(io)) {}

  std::unique_ptr<HttpConnection> io;
  State state = State::kIdle;
  Clock::time_point deadline{};
  RequestHead head;
  size_t request_bytes = 0;  // head and body, once the head is read
  std::optional<UploadBudget::Ticket> body_budget;
  int served = 0;
  size_t lingered = 0;
};

ConnectionLoop::ConnectionLoop(const HttpLoopOptions& options, SSL_CTX* tls, UploadBudget& budget,
                               Hooks hooks)
    : options_(options),
      tls_(tls),
      budget_(budget),
      hooks_(std::move(hooks)),
      epoll_(epoll_create1(EPOLL_CLOEXEC)),
      wake_(eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)),
      pool_(options.threads, options.max_waiting) {
  epoll_event event{};
  event.events = EPOLLIN;
  event.data.fd = wake_.get();
  epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, wake_.get(), &event);
  thread_ = std::thread([this] { Run(); });
}

ConnectionLoop::~ConnectionLoop() { Stop(Clock::now()); }

void ConnectionLoop::Wake() {
  const uint64_t one = 1;
  const ssize_t written = ::write(wake_.get(), &one, sizeof(one));
  (void)written;  // an eventfd write fails only when its counter would overflow
}

void ConnectionLoop::Add(AcceptedConnection connection) {
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    arrivals_.push_back(std::move(connection));
  }
  Wake();
}

void ConnectionLoop::BeginStop() {
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    stop_reading_ = true;
  }
  Wake();
}

void ConnectionLoop::Stop(Clock::time_point deadline) {
  if (!thread_.joinable()) return;
  BeginStop();
  {
    std::unique_lock<std::mutex> lock(inbox_mutex_);
    if (!answered_.wait_until(lock, deadline, [this] { return in_workers_ == 0; })) {
      cut_busy_ = true;  // the loop cuts them: the connections are its to touch
    }
  }
  Wake();
  {
    std::unique_lock<std::mutex> lock(inbox_mutex_);
    answered_.wait(lock, [this] { return in_workers_ == 0; });
    exit_ = true;
  }
  Wake();
  thread_.join();
  pool_.Join();
}

void ConnectionLoop::Run() {
  epoll_event events[kMaxEvents];
  for (;;) {
    const int ready = epoll_wait(epoll_.get(), events, kMaxEvents, kTickMs);
    for (int i = 0; i < ready; ++i) {
      if (events[i].data.fd == wake_.get()) {
        uint64_t count = 0;
        const ssize_t got = ::read(wake_.get(), &count, sizeof(count));
        (void)got;  // drained; the inbox says what woke the loop
        continue;
      }
      OnEvent(events[i].data.fd, events[i].events);
    }
    TakeInbox();
    {
      std::lock_guard<std::mutex> lock(inbox_mutex_);
      if (exit_) break;
    }
    ExpireDeadlines();
  }
  for (auto& [socket, connection] : connections_)
    epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, socket, nullptr);
  connections_.clear();
  open_ = 0;
}

void ConnectionLoop::TakeInbox() {
  std::vector<AcceptedConnection> arrivals;
  std::vector<std::pair<int, bool>> answers;
  bool stop_reading = false, cut_busy = false;
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    arrivals.swap(arrivals_);
    answers.swap(answers_);
    stop_reading = stop_reading_;
    cut_busy = cut_busy_;
  }
  if (stop_reading && !stopped_reading_) {
    stopped_reading_ = true;
    std::vector<int> idle;
    for (const auto& [socket, connection] : connections_) {
      if (connection->state != State::kBusy) idle.push_back(socket);
    }
    for (const int socket : idle) Close(socket);
  }
  for (AcceptedConnection& accepted : arrivals) {
    if (stopped_reading_) continue;  // closed as it goes out of scope
    Register(std::move(accepted));
  }
  for (const auto& [socket, keep] : answers) OnAnswered(socket, keep);
  if (cut_busy) {
    for (auto& [socket, connection] : connections_) {
      if (connection->state == State::kBusy) connection->io->Cut();
    }
  }
}

void ConnectionLoop::Register(AcceptedConnection accepted) {
  const int socket = accepted.socket.get();
  auto connection =
      std::make_unique<Connection>(std::make_unique<HttpConnection>(std::move(accepted), tls_));
  // A new connection's first request is due as soon as a head would be.
  connection->state = tls_ != nullptr ? State::kHandshake : State::kIdle;
  connection->deadline =
      Clock::now() + (tls_ != nullptr ? options_.handshake_timeout : options_.head_timeout);
  connections_[socket] = std::move(connection);
  ++open_;
  Watch(socket, /*writable=*/false, /*first=*/true);
}

void ConnectionLoop::Watch(int socket, bool writable, bool first) {
  epoll_event event{};
  event.events = writable ? EPOLLOUT : EPOLLIN;
  event.data.fd = socket;
  epoll_ctl(epoll_.get(), first ? EPOLL_CTL_ADD : EPOLL_CTL_MOD, socket, &event);
}

void ConnectionLoop::OnEvent(int socket, uint32_t /*events*/) {
  const auto found = connections_.find(socket);
  if (found == connections_.end()) return;
  Connection& connection = *found->second;
  switch (connection.state) {
    case State::kHandshake: {
      const HttpConnection::Io io = connection.io->Handshake();
      if (io == HttpConnection::Io::kWantRead || io == HttpConnection::Io::kWantWrite) {
        Watch(socket, io == HttpConnection::Io::kWantWrite, /*first=*/false);
        return;
      }
      if (io != HttpConnection::Io::kDone) {
        Close(socket);
        return;
      }
      Watch(socket, /*writable=*/false, /*first=*/false);
      connection.state = State::kIdle;
      connection.deadline = Clock::now() + options_.head_timeout;
      ReadMore(connection);  // TLS may hold the request's first bytes already
      return;
    }
    case State::kLinger: {
      const size_t before = connection.io->buffer().size();
      const HttpConnection::Io io = connection.io->Read(before + (64 << 10));
      connection.lingered += connection.io->buffer().size() - before;
      connection.io->buffer().clear();
      if (io == HttpConnection::Io::kClosed || io == HttpConnection::Io::kFailed ||
          connection.lingered > kMaxLingerBytes) {
        Close(socket);
      }
      return;
    }
    case State::kBusy:
      return;
    default:
      ReadMore(connection);
  }
}

void ConnectionLoop::ReadMore(Connection& connection) {
  const int socket = connection.io->socket();
  // Twice at most: once the head is read, the body may be there already.
  for (int round = 0; round < 2; ++round) {
    const State before = connection.state;
    const size_t up_to =
        connection.state == State::kBody ? connection.request_bytes : kMaxRequestHeadBytes + 1;
    const HttpConnection::Io io = connection.io->Read(up_to);
    if (io == HttpConnection::Io::kClosed || io == HttpConnection::Io::kFailed) {
      // A client gone mid-request has nobody to answer.
      Close(socket);
      return;
    }
    Advance(connection);
    if (!connections_.contains(socket) || connection.state == before ||
        connection.state != State::kBody) {
      return;
    }
  }
}

void ConnectionLoop::Advance(Connection& connection) {
  std::string& buffer = connection.io->buffer();
  if (connection.state == State::kIdle) {
    if (buffer.empty()) return;
    connection.state = State::kHead;
    connection.deadline = Clock::now() + options_.head_timeout;
  }
  if (connection.state == State::kHead && !ReadHead(connection)) return;
  if (connection.state == State::kBody && buffer.size() >= connection.request_bytes) {
    Dispatch(connection);
  }
}

// Moves a connection whose head is complete to kBody; false when the head is incomplete or the
// request was refused.
bool ConnectionLoop::ReadHead(Connection& connection) {
  std::string& buffer = connection.io->buffer();
  switch (ParseRequestHead(buffer, &connection.head)) {
    case HeadParse::kIncomplete:
      return false;
    case HeadParse::kTooLarge:
      Refuse(connection, {431, absl::StrCat("the request head is larger than the server takes (",
                                            kMaxRequestHeadBytes >> 10, " KiB, ", kMaxRequestFields,
                                            " fields)")});
      return false;
    case HeadParse::kMalformed:
      Refuse(connection, {400, "the request head is malformed"});
      return false;
    case HeadParse::kComplete:
      break;
  }
  RequestHead& head = connection.head;
  std::string problem;
  const std::optional<size_t> length = ContentLength(head, &problem);
  if (!length) {
    Refuse(connection, {400, problem});
    return false;
  }
  if (std::optional<HttpRefusal> refusal = hooks_.check_head(head, *connection.io)) {
    Refuse(connection, *refusal);
    return false;
  }
  if (*length > 0) {
    absl::StatusOr<UploadBudget::Ticket> ticket = budget_.Admit();
    absl::Status reserved =
        ticket.ok() ? ticket->Reserve(static_cast<int64_t>(*length)) : ticket.status();
    if (!reserved.ok()) {
      Refuse(connection, {503, std::string(reserved.message()), {{"Retry-After", "1"}}});
      return false;
    }
    connection.body_budget.emplace(*std::move(ticket));
    const auto rate_time = std::chrono::milliseconds(
        static_cast<int64_t>(1000.0 * static_cast<double>(*length) / options_.min_body_rate));
    connection.deadline = Clock::now() + std::max(options_.head_timeout, rate_time);
    for (const absl::string_view expect : head.Values("expect")) {
      if (absl::EqualsIgnoreCase(expect, "100-continue")) {
        connection.io->TryWrite("HTTP/1.1 100 Continue\r\n\r\n");
      }
    }
  }
  if (head.Has("expect")) {
    const std::string kept = WithoutExpect(absl::string_view(buffer).substr(0, head.bytes));
    buffer.replace(0, head.bytes, kept);
    head.bytes = kept.size();
  }
  connection.request_bytes = head.bytes + *length;
  connection.state = State::kBody;
  return true;
}

void ConnectionLoop::Dispatch(Connection& connection) {
  const int socket = connection.io->socket();
  // The budget bounds bodies while they arrive; once whole, the answer's own limits hold (an
  // ingest's, in-process, counts its file again).
  connection.body_budget.reset();
  connection.state = State::kBusy;
  epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, socket, nullptr);
  const bool last = connection.served + 1 >= options_.max_requests_per_connection;
  HttpConnection* io = connection.io.get();
  const size_t length = connection.request_bytes;
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    ++in_workers_;
  }
  const bool posted = pool_.TryPost([this, io, socket, length, last] {
    const bool keep =
        hooks_.answer(*io, absl::string_view(io->buffer()).substr(0, length), last) && !last;
    {
      std::lock_guard<std::mutex> lock(inbox_mutex_);
      answers_.emplace_back(socket, keep);
      --in_workers_;
    }
    answered_.notify_all();
    Wake();
  });
  if (posted) return;
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    --in_workers_;
  }
  Watch(socket, /*writable=*/false, /*first=*/true);
  Refuse(connection,
         {503,
          absl::StrCat("the server is busy: ", options_.max_waiting,
                       " requests wait for a worker already (--http-max-waiting); retry later"),
          {{"Retry-After", "1"}}});
}

void ConnectionLoop::OnAnswered(int socket, bool keep) {
  const auto found = connections_.find(socket);
  if (found == connections_.end()) return;
  Connection& connection = *found->second;
  ++connection.served;
  if (!keep || stopped_reading_) {
    Close(socket);
    return;
  }
  std::string& buffer = connection.io->buffer();
  buffer.erase(0, connection.request_bytes);
  if (buffer.capacity() > kKeptBufferBytes) buffer.shrink_to_fit();
  connection.request_bytes = 0;
  connection.head = RequestHead{};
  connection.state = State::kIdle;
  connection.deadline = Clock::now() + options_.idle_timeout;
  Watch(socket, /*writable=*/false, /*first=*/true);
  ReadMore(connection);  // a request sent behind the last may be here already
}

void ConnectionLoop::Refuse(Connection& connection, const HttpRefusal& refusal) {
  const bool head_read = connection.state == State::kBody ||
                         (connection.state == State::kHead && !connection.head.method.empty());
  if (hooks_.refused)
    hooks_.refused(*connection.io, head_read ? &connection.head : nullptr, refusal);
  const std::string body = hooks_.error_body(refusal);
  std::string response = absl::StrFormat(
      "HTTP/1.1 %d %s\r\nContent-Type: application/json\r\nContent-Length: %d\r\n"
      "Connection: close\r\n",
      refusal.status, ReasonPhrase(refusal.status), body.size());
  for (const auto& [name, value] : refusal.headers)
    absl::StrAppend(&response, name, ": ", value, "\r\n");
  absl::StrAppend(&response, "\r\n", body);
  connection.io->TryWrite(response);
  Linger(connection);
}

void ConnectionLoop::Linger(Connection& connection) {
  connection.body_budget.reset();
  connection.io->buffer().clear();
  connection.io->buffer().shrink_to_fit();
  ::shutdown(connection.io->socket(), SHUT_WR);
  connection.state = State::kLinger;
  connection.lingered = 0;
  connection.deadline = Clock::now() + kLingerTime;
}

void ConnectionLoop::Close(int socket) {
  epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, socket, nullptr);
  if (connections_.erase(socket) > 0) --open_;
}

void ConnectionLoop::ExpireDeadlines() {
  const Clock::time_point now = Clock::now();
  if (now - last_expiry_ < std::chrono::milliseconds(kTickMs)) return;
  last_expiry_ = now;
  std::vector<int> expired;
  for (const auto& [socket, connection] : connections_) {
    if (connection->state != State::kBusy && now >= connection->deadline) expired.push_back(socket);
  }
  for (const int socket : expired) {
    Connection& connection = *connections_.at(socket);
    if (connection.state == State::kHead || connection.state == State::kBody) {
      Refuse(connection,
             {408, absl::StrFormat("the request did not arrive in time: its head within %d s, "
                                   "its body at %d KiB/s or faster",
                                   options_.head_timeout.count() / 1000,
                                   static_cast<int>(options_.min_body_rate) >> 10)});
    } else {
      Close(socket);  // idle, a handshake that never finished, or done lingering
    }
  }
}

}  // namespace motiondb::server
