// Calls per second and their latencies from several client threads, as the server benchmarks
// measure them (bench/server_bench.cc, bench/http_bench.cc), and their gRPC clients.
#ifndef MOTIONDB_BENCH_THROUGHPUT_H_
#define MOTIONDB_BENCH_THROUGHPUT_H_

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "bench/measure.h"

namespace motiondb::bench {

struct Throughput {
  double qps = 0;
  std::vector<double> latencies_ms;
};

// `threads` workers call `call(worker, k)` for their k-th call until `seconds` have passed
// (after a warm-up of a tenth of a second that is not counted).
template <typename CallFn>
absl::StatusOr<Throughput> Measure(int threads, double seconds, CallFn call) {
  std::atomic<bool> failed{false};
  std::string failure;
  std::vector<std::vector<double>> latencies(threads);
  std::vector<int64_t> counted(threads, 0);
  const Clock::time_point warm = Clock::now() + std::chrono::milliseconds(100);
  const Clock::time_point end =
      warm + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  std::vector<std::thread> workers;
  for (int t = 0; t < threads; ++t) {
    workers.emplace_back([&, t] {
      for (int64_t k = 0; !failed; ++k) {
        const Clock::time_point start = Clock::now();
        if (start >= end) break;
        const absl::Status status = call(t, k);
        if (!status.ok()) {
          if (!failed.exchange(true)) failure = status.ToString();
          break;
        }
        if (start >= warm) {
          latencies[t].push_back(
              std::chrono::duration<double, std::milli>(Clock::now() - start).count());
          ++counted[t];
        }
      }
    });
  }
  for (std::thread& worker : workers) worker.join();
  if (failed) return absl::InternalError(failure);
  Throughput result;
  int64_t total = 0;
  for (int t = 0; t < threads; ++t) {
    total += counted[t];
    result.latencies_ms.insert(result.latencies_ms.end(), latencies[t].begin(), latencies[t].end());
  }
  result.qps = static_cast<double>(total) / seconds;
  return result;
}

inline absl::Status FromGrpc(const grpc::Status& status, const std::string& what) {
  if (status.ok()) return absl::OkStatus();
  return absl::InternalError(absl::StrCat(what, ": ", status.error_message()));
}

// Its own connection, as a separate client process would have.
inline std::shared_ptr<grpc::Channel> OwnConnection(const std::string& address) {
  grpc::ChannelArguments arguments;
  arguments.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
  arguments.SetMaxReceiveMessageSize(-1);
  return grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), arguments);
}

// Adds one turn of `turns` to `total`.
inline void Add(const Throughput& part, int turns, Throughput& total) {
  total.qps += part.qps / turns;
  total.latencies_ms.insert(total.latencies_ms.end(), part.latencies_ms.begin(),
                            part.latencies_ms.end());
}

}  // namespace motiondb::bench

#endif  // MOTIONDB_BENCH_THROUGHPUT_H_
