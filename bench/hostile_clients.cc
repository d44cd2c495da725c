#include "bench/hostile_clients.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <grpcpp/grpcpp.h>

#include "absl/strings/str_cat.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "testing/server_process.h"

namespace motiondb::bench {
namespace {

// A connection to 127.0.0.1:`port` from `source`; -1 when it fails (the server out of
// descriptors may not take it).
int Connect(int port, const std::string& source) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  sockaddr_in from{};
  from.sin_family = AF_INET;
  inet_pton(AF_INET, source.c_str(), &from.sin_addr);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&from), sizeof(from)) != 0 ||
      ::connect(fd, reinterpret_cast<sockaddr*>(&to), sizeof(to)) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

}  // namespace

HostileClients::HostileClients(const HostileOptions& options) : options_(options) {
  for (int i = 0; i < options_.slow_clients; ++i) threads_.emplace_back([this] { SlowClient(); });
  for (int i = 0; i < options_.idle_streams; ++i) threads_.emplace_back([this] { IdleStream(); });
  threads_.emplace_back([this] { Flooder(); });
}

HostileClients::~HostileClients() { Stop(); }

void HostileClients::Stop() {
  {
    std::lock_guard<std::mutex> lock(streams_mutex_);
    stopping_ = true;
    for (grpc::ClientContext* stream : streams_) stream->TryCancel();
  }
  for (std::thread& thread : threads_) {
    if (thread.joinable()) thread.join();
  }
}

// Sends a request's head a byte a second, as long as the server takes it, then reads its answer.
void HostileClients::SlowClient() {
  const std::string head = "GET /healthz HTTP/1.1\r\nHost: soak\r\nX-Slow: ";
  while (!stopping_) {
    const int fd = Connect(options_.http_port, "127.0.0.2");
    if (fd < 0) {
      std::this_thread::sleep_for(std::chrono::seconds(1));
      continue;
    }
    ++slow_requests_;
    for (size_t i = 0; !stopping_; ++i) {
      if (::send(fd, &head[i % head.size()], 1, MSG_NOSIGNAL) != 1) break;
      pollfd watched{fd, POLLIN, 0};
      if (::poll(&watched, 1, 1000) > 0) {  // the server answered (408) or closed
        char answer[64] = {};
        if (::recv(fd, answer, sizeof(answer) - 1, 0) > 0 &&
            std::string(answer).find(" 408 ") != std::string::npos) {
          ++slow_408_;
        } else {
          // Refused on arrival (a limit, or a flood ran the server out of descriptors).
          ++slow_refused_;
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
        break;
      }
    }
    ::close(fd);
  }
}

// Opens an ingest stream, sends its first message, then nothing until the server ends it.
void HostileClients::IdleStream() {
  const auto channel = testing::InsecureChannel(absl::StrCat("127.0.0.1:", options_.grpc_port));
  auto clips = v1::ClipService::NewStub(channel);
  while (!stopping_) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(120));
    {
      std::lock_guard<std::mutex> lock(streams_mutex_);
      if (stopping_) return;
      streams_.insert(&context);
    }
    v1::IngestClipResponse response;
    auto writer = clips->IngestClipStream(&context, &response);
    v1::IngestClipStreamRequest first;
    first.set_file_name("idle.bvh");
    first.set_chunk("HIERARCHY\n");
    writer->Write(first);
    const grpc::Status status = writer->Finish();
    if (status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED) ++streams_ended_;
    std::lock_guard<std::mutex> lock(streams_mutex_);
    streams_.erase(&context);
  }
}

void HostileClients::Flooder() {
  auto next = std::chrono::steady_clock::now() + options_.flood_every / 2;
  while (!stopping_) {
    if (std::chrono::steady_clock::now() < next) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      continue;
    }
    next += options_.flood_every;
    ++floods_;
    std::vector<int> held;
    for (int a = 0; a < options_.flood_addresses && !stopping_; ++a) {
      const std::string source = absl::StrCat("127.0.0.", 3 + a);
      for (int i = 0; i < options_.flood_per_address; ++i) {
        for (const int port : {options_.grpc_port, options_.http_port}) {
          const int fd = Connect(port, source);
          if (fd >= 0) held.push_back(fd);
        }
      }
    }
    flood_connections_ += static_cast<int64_t>(held.size());
    const auto release = std::chrono::steady_clock::now() + options_.flood_hold;
    while (!stopping_ && std::chrono::steady_clock::now() < release) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    for (const int fd : held) ::close(fd);
  }
}

std::string HostileClients::Report() const {
  return absl::StrCat("hostile: ", slow_requests_.load(), " slow requests (", slow_408_.load(),
                      " answered 408, ", slow_refused_.load(), " refused on arrival), ",
                      streams_ended_.load(), " idle streams ended by the server, ", floods_.load(),
                      " floods of ", flood_connections_.load(), " connections in all");
}

}  // namespace motiondb::bench
