#include "util/parallel_for.h"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

#include "util/status_macros.h"

namespace motiondb {
namespace {

// Starts run(1) .. run(wanted - 1) on threads of their own, added to `helpers`, until one cannot
// be started (the process is out of threads or memory); returns how many run now, the caller
// counted: from 1 to `wanted`.
int StartHelpers(int wanted, const std::function<void(int)>& run,
                 std::vector<std::jthread>& helpers) {
  helpers.reserve(std::max(wanted - 1, 0));
  int started = 1;
  try {
    for (; started < wanted; ++started) helpers.emplace_back(run, started);
  } catch (const std::system_error&) {
  }
  return started;
}

}  // namespace

int ThreadsFor(int requested) {
  if (requested > 0) return requested;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

absl::Status ParallelFor(int64_t count, int threads,
                         const std::function<absl::Status(int64_t index, int thread)>& body) {
  const int used = static_cast<int>(std::clamp<int64_t>(threads, 1, std::max<int64_t>(count, 1)));
  std::atomic<int64_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;
  int64_t failed_index = count;  // the lowest failed index, under `mutex`
  absl::Status failure;
  const auto run = [&](int thread) {
    for (int64_t i = next++; i < count && !failed.load(std::memory_order_relaxed); i = next++) {
      absl::Status status = body(i, thread);
      if (status.ok()) continue;
      const std::lock_guard<std::mutex> lock(mutex);
      if (i < failed_index) {
        failed_index = i;
        failure = std::move(status);
      }
      failed = true;
    }
  };
  {
    // Whatever threads started, they and the caller hand out every index between them.
    std::vector<std::jthread> helpers;
    StartHelpers(used, run, helpers);
    run(0);
  }
  return failure;
}

absl::Status ParallelForInOrder(
    int64_t count, int threads,
    const std::function<absl::Status(int64_t index, int thread)>& compute,
    const std::function<absl::Status(int64_t index, int thread)>& commit) {
  std::vector<std::atomic<bool>> computed(static_cast<size_t>(std::max<int64_t>(count, 0)));
  std::mutex committing;
  std::atomic<int64_t> next_commit{0};  // written under `committing`
  absl::Status commit_failure;          // under `committing`
  // Commits every computed index from next_commit on; false once a commit failed.
  const auto commit_ready = [&](int thread) {
    for (int64_t i = next_commit; i < count && computed[i]; i = ++next_commit) {
      commit_failure = commit(i, thread);
      if (!commit_failure.ok()) return false;
    }
    return true;
  };
  absl::Status status = ParallelFor(count, threads, [&](int64_t index, int thread) -> absl::Status {
    MOTIONDB_RETURN_IF_ERROR(compute(index, thread));
    computed[index] = true;
    // A thread that finds another committing goes on computing: the committer takes this index
    // too if it gets there, else the next thread to finish or the caller's last sweep does.
    while (committing.try_lock()) {
      const bool ok = commit_ready(thread);
      committing.unlock();
      if (!ok) return absl::AbortedError("an earlier commit failed");
      const int64_t next = next_commit;
      if (next >= count || !computed[next]) break;
    }
    return absl::OkStatus();
  });
  const std::lock_guard<std::mutex> lock(committing);
  if (!commit_failure.ok()) return commit_failure;
  MOTIONDB_RETURN_IF_ERROR(status);
  commit_ready(0);
  return commit_failure;
}

int PieceCount(int64_t count, int64_t min_piece, int threads) {
  const int64_t piece = std::max<int64_t>(min_piece, 1);
  return static_cast<int>(std::clamp<int64_t>(count / piece, 1, ThreadsFor(threads)));
}

void ForEachPiece(int64_t count, int pieces,
                  const std::function<void(int piece, int64_t begin, int64_t end)>& body) {
  const auto run = [&](int piece) {
    body(piece, count * piece / pieces, count * (piece + 1) / pieces);
  };
  std::vector<std::jthread> helpers;
  const int started = StartHelpers(pieces, run, helpers);
  // The caller runs the pieces no thread took, after its own.
  run(0);
  for (int piece = started; piece < pieces; ++piece) run(piece);
}

}  // namespace motiondb
