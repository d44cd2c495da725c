// A few threads that share the stages of one short piece of work (a search of a few
// milliseconds): started once, before the work that needs them, and kept awake between its
// stages. Why not ParallelFor (util/parallel_for.h) for each stage: on this machine's virtual
// CPUs a thread started, or woken from sleep, begins running tens to hundreds of microseconds
// later, which a stage of a millisecond cannot pay three times over
// (bench/notes/2026-12-07-both-cores.md). A team's helpers start while the caller does its
// first serial work and spin (yielding the core to anything else that wants it) between stages
// until the team is destroyed.
//
// Not thread-safe: one caller drives a team; its stages run on the team's threads. A stage that
// throws on the caller is closed and left by the helpers first; one that throws on a helper ends
// the process, as ParallelFor's would.
#ifndef MOTIONDB_UTIL_THREAD_TEAM_H_
#define MOTIONDB_UTIL_THREAD_TEAM_H_

#include <atomic>
#include <cstdint>
#include <functional>
#include <thread>
#include <vector>

#include "absl/status/status.h"

namespace motiondb {

class ThreadTeam {
 public:
  // The caller and `threads` - 1 helpers (fewer when no more can be started).
  explicit ThreadTeam(int threads);
  ~ThreadTeam();
  ThreadTeam(const ThreadTeam&) = delete;
  ThreadTeam& operator=(const ThreadTeam&) = delete;

  // The threads that run each stage, the caller included: member 0 is the caller.
  int size() const { return static_cast<int>(helpers_.size()) + 1; }

  // ParallelFor's contract (util/parallel_for.h) on the team's threads: body(index, member)
  // for every index, handed out in increasing order; the lowest failed index's failure.
  absl::Status ParallelFor(int64_t count,
                           const std::function<absl::Status(int64_t index, int member)>& body);

  // For speculative work: compute(index, member) for every index as ParallelFor calls body, and
  // commit(index, member) for every index in increasing order, each after its own compute and
  // the previous index's commit, never two at once, on whichever member finds it ready (a
  // commit can run beside later indices' computes), inside that member's own call, so that a
  // member's state is never used by two threads. With one thread: compute(0), commit(0),
  // compute(1), commit(1), ... The caller's compute reads what the commits so far have
  // published (a bound, a threshold); its commit sees everything before it committed, and is
  // where the caller redoes a compute whose reading has changed since. After a failure no
  // further index is computed or committed, nor a failed commit tried again; returns the
  // commit's failure, else the compute's of the lowest index, or OK.
  absl::Status ParallelForInOrder(
      int64_t count, const std::function<absl::Status(int64_t index, int member)>& compute,
      const std::function<absl::Status(int64_t index, int member)>& commit);

 private:
  // Runs stage(member) on the caller and on every helper that joins it before the caller is
  // done with it; returns when they all have. A stage must share its work out between however
  // many members run it (ParallelFor's handout does).
  void RunStage(const std::function<void(int member)>& stage);
  void Help(int member);

  static constexpr uint32_t kStageClosed = uint32_t{1} << 31;

  std::vector<std::jthread> helpers_;
  const std::function<void(int)>* stage_ = nullptr;  // written before the stage opens
  std::atomic<uint64_t> stages_{0};                  // stages opened
  // kStageClosed once the caller is done with the stage; below it, the helpers in it.
  std::atomic<uint32_t> stage_state_{kStageClosed};
  std::atomic<bool> closing_{false};
};

}  // namespace motiondb

#endif  // MOTIONDB_UTIL_THREAD_TEAM_H_
