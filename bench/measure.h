// What the measurement programs share: elapsed time, percentiles, memory, the corpus folder.
#ifndef MOTIONDB_BENCH_MEASURE_H_
#define MOTIONDB_BENCH_MEASURE_H_

#include <sys/types.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "testing/corpus_paths.h"

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

// A field of /proc/PID/status in MiB (VmRSS: resident now; VmHWM: its peak).
inline double StatusMiB(pid_t pid, const std::string& field) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::atof(line.c_str() + field.size() + 1) / 1024;
  }
  return 0;
}

// The shared mocap folder, as the tests find it.
using testing::MocapRoot;

}  // namespace motiondb::bench

#endif  // MOTIONDB_BENCH_MEASURE_H_
