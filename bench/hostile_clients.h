// What a server on a studio's network meets besides its users (issue 37), run beside the soak's
// mix: slow HTTP clients (a header byte a second), upload streams that send their first message
// and then nothing, and floods of idle connections to both ports from many addresses
// (127.0.0.x), held a few seconds, then closed. Each kind runs on threads of its own until
// Stop(); what they saw is counted for the report.
#ifndef MOTIONDB_BENCH_HOSTILE_CLIENTS_H_
#define MOTIONDB_BENCH_HOSTILE_CLIENTS_H_

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

namespace grpc {
class ClientContext;
}

namespace motiondb::bench {

struct HostileOptions {
  int grpc_port = 0;
  int http_port = 0;
  int slow_clients = 16;  // from 127.0.0.2
  int idle_streams = 8;
  // Every `flood_every`, `flood_addresses` addresses (127.0.0.3 on) open `flood_per_address`
  // connections to each port, hold them `flood_hold`, and close them.
  std::chrono::seconds flood_every{60};
  std::chrono::seconds flood_hold{5};
  int flood_addresses = 16;
  int flood_per_address = 64;
};

class HostileClients {
 public:
  explicit HostileClients(const HostileOptions& options);
  ~HostileClients();  // Stop()
  void Stop();

  // What they saw, one line.
  std::string Report() const;

 private:
  void SlowClient();
  void IdleStream();
  void Flooder();

  const HostileOptions options_;
  std::atomic<bool> stopping_{false};
  std::atomic<int64_t> slow_requests_{0}, slow_408_{0}, slow_refused_{0}, streams_ended_{0},
      floods_{0}, flood_connections_{0};
  std::mutex streams_mutex_;
  std::set<grpc::ClientContext*> streams_;  // the idle streams open; guarded by the mutex
  std::vector<std::thread> threads_;
};

}  // namespace motiondb::bench

#endif  // MOTIONDB_BENCH_HOSTILE_CLIENTS_H_
