// Running the items of a batch on several threads: the calling thread and `threads - 1` more,
// which inherit its scheduling priority (Linux copies a thread's nice value to the threads it
// starts), so that work started by a low-priority thread stays low-priority.
#ifndef MOTIONDB_UTIL_PARALLEL_FOR_H_
#define MOTIONDB_UTIL_PARALLEL_FOR_H_

#include <cstdint>
#include <functional>

#include "absl/status/status.h"

namespace motiondb {

// The number of threads `requested` asks for: itself when positive, else one per core.
int ThreadsFor(int requested);

// Calls body(index, thread) once for every index in [0, count), on min(threads, count) threads
// (fewer when no more can be started) numbered 0 (the caller) to threads - 1; indices are handed
// out in increasing order, one at a time, so that body may keep per-thread state in slots indexed
// by `thread`. After a call fails, no further index is handed out; the calls under way finish.
// Returns the failure of the lowest index that failed (so that the outcome does not depend on
// timing), or OK. `body` must be safe to call from several threads at once.
absl::Status ParallelFor(int64_t count, int threads,
                         const std::function<absl::Status(int64_t index, int thread)>& body);

// Work cut into a few large contiguous pieces, one a thread, for loops that cannot fail.
// How many pieces to cut `count` items into for `threads` (0: one a core): one a thread, but
// none smaller than `min_piece` items (a thread costs tens of microseconds to start), except
// the single piece of fewer than `min_piece` items.
int PieceCount(int64_t count, int64_t min_piece, int threads);
// Calls body(piece, begin, end) for each of the `pieces` nearly equal ranges, in order, that
// cover [0, count), each on its own thread (the caller's is piece 0's; when no thread can be
// started, the caller's too). The same count and pieces always give the same ranges.
void ForEachPiece(int64_t count, int pieces,
                  const std::function<void(int piece, int64_t begin, int64_t end)>& body);

}  // namespace motiondb

#endif  // MOTIONDB_UTIL_PARALLEL_FOR_H_
