#include "util/parallel_for.h"

#include <algorithm>
#include <thread>
#include <vector>

#include "util/internal/helper_threads.h"
#include "util/internal/index_handout.h"

namespace motiondb {

int ThreadsFor(int requested) {
  if (requested > 0) return requested;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

absl::Status ParallelFor(int64_t count, int threads,
                         const std::function<absl::Status(int64_t index, int thread)>& body) {
  const int used = static_cast<int>(std::clamp<int64_t>(threads, 1, std::max<int64_t>(count, 1)));
  IndexHandout handout(count);
  const auto run = [&](int thread) { handout.Run(thread, body); };
  {
    // Whatever threads started, they and the caller hand out every index between them.
    std::vector<std::jthread> helpers;
    StartHelpers(used, run, helpers);
    run(0);
  }
  return handout.failure();
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
