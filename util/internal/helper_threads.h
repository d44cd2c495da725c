// Starting the helper threads of a parallel loop, as many as the process can start.
#ifndef MOTIONDB_UTIL_INTERNAL_HELPER_THREADS_H_
#define MOTIONDB_UTIL_INTERNAL_HELPER_THREADS_H_

#include <algorithm>
#include <functional>
#include <system_error>
#include <thread>
#include <vector>

namespace motiondb {

// Starts run(1) .. run(wanted - 1) on threads of their own, added to `helpers`, until one cannot
// be started (the process is out of threads or memory); returns how many run now, the caller
// counted: from 1 to `wanted`.
inline int StartHelpers(int wanted, const std::function<void(int)>& run,
                        std::vector<std::jthread>& helpers) {
  helpers.reserve(std::max(wanted - 1, 0));
  int started = 1;
  try {
    for (; started < wanted; ++started) helpers.emplace_back(run, started);
  } catch (const std::system_error&) {
  }
  return started;
}

}  // namespace motiondb

#endif  // MOTIONDB_UTIL_INTERNAL_HELPER_THREADS_H_
