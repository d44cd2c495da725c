// What the measurement programs share: elapsed time and percentiles.
#ifndef MOTIONDB_BENCH_MEASURE_H_
#define MOTIONDB_BENCH_MEASURE_H_

#include <algorithm>
#include <chrono>
#include <vector>

namespace motiondb::bench {

using Clock = std::chrono::steady_clock;

inline double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The p-quantile (p in [0, 1]) of `v` by rank; 0 for no values.
inline double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * static_cast<double>(v.size())))];
}

}  // namespace motiondb::bench

#endif  // MOTIONDB_BENCH_MEASURE_H_
