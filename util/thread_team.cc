#include "util/thread_team.h"

#include <algorithm>
#include <mutex>

#include "absl/cleanup/cleanup.h"

#include "util/internal/helper_threads.h"
#include "util/internal/index_handout.h"
#include "util/status_macros.h"

namespace motiondb {

ThreadTeam::ThreadTeam(int threads) {
  StartHelpers(
      threads, [this](int member) { Help(member); }, helpers_);
}

ThreadTeam::~ThreadTeam() {
  closing_ = true;
  helpers_.clear();  // joined here, while what they read is alive
}

void ThreadTeam::Help(int member) {
  uint64_t seen = 0;
  for (;;) {
    while (stages_.load(std::memory_order_acquire) == seen) {
      if (closing_.load(std::memory_order_acquire)) return;
      std::this_thread::yield();
    }
    seen = stages_.load(std::memory_order_acquire);
    // Joins the stage open now, if any: a helper that starts late, or that the machine did not
    // run for a while, joins no stage the caller has closed, which goes on without it.
    uint32_t state = stage_state_.load(std::memory_order_acquire);
    bool joined = false;
    while (!joined && (state & kStageClosed) == 0) {
      joined = stage_state_.compare_exchange_weak(state, state + 1, std::memory_order_acq_rel);
    }
    if (!joined) continue;
    // The stage joined can be one opened after `seen` was read, and then joined again once seen:
    // a stage's members share out its work, so running it twice only looks for more.
    (*stage_)(member);
    stage_state_.fetch_sub(1, std::memory_order_release);
  }
}

void ThreadTeam::RunStage(const std::function<void(int member)>& stage) {
  if (helpers_.empty()) {
    stage(0);
    return;
  }
  stage_ = &stage;
  stage_state_.store(0, std::memory_order_release);  // open, no helper in it yet
  stages_.fetch_add(1, std::memory_order_release);
  // Closed and left by every helper before the stage's state goes, even when the caller's part
  // throws.
  const absl::Cleanup close = [this] {
    stage_state_.fetch_or(kStageClosed, std::memory_order_acq_rel);
    while ((stage_state_.load(std::memory_order_acquire) & ~kStageClosed) != 0) {
      std::this_thread::yield();
    }
  };
  stage(0);
}

absl::Status ThreadTeam::ParallelFor(
    int64_t count, const std::function<absl::Status(int64_t index, int member)>& body) {
  IndexHandout handout(count);
  RunStage([&](int member) { handout.Run(member, body); });
  return handout.failure();
}

absl::Status ThreadTeam::ParallelForInOrder(
    int64_t count, const std::function<absl::Status(int64_t index, int member)>& compute,
    const std::function<absl::Status(int64_t index, int member)>& commit) {
  std::vector<std::atomic<bool>> computed(static_cast<size_t>(std::max<int64_t>(count, 0)));
  std::mutex committing;
  std::atomic<int64_t> next_commit{0};  // written under `committing`
  absl::Status commit_failure;          // under `committing`; once set, nothing more commits
  // Commits every computed index from next_commit on; the failure, if a commit failed (now or
  // before: a failed commit is not tried again by another member, whose stop may not have said
  // stop yet).
  const auto commit_ready = [&](int member) {
    for (int64_t i = next_commit; commit_failure.ok() && i < count && computed[i];
         i = ++next_commit) {
      commit_failure = commit(i, member);
    }
    return commit_failure;
  };
  const absl::Status status = ParallelFor(count, [&](int64_t index, int member) -> absl::Status {
    MOTIONDB_RETURN_IF_ERROR(compute(index, member));
    computed[index] = true;
    // A member that finds another committing goes on computing: the committer takes this index
    // too if it gets there, else the next member to finish or the caller's last sweep does.
    while (committing.try_lock()) {
      const absl::Status committed = commit_ready(member);
      committing.unlock();
      MOTIONDB_RETURN_IF_ERROR(committed);
      const int64_t next = next_commit;
      if (next >= count || !computed[next]) break;
    }
    return absl::OkStatus();
  });
  const std::lock_guard<std::mutex> lock(committing);
  if (!commit_failure.ok()) return commit_failure;
  MOTIONDB_RETURN_IF_ERROR(status);
  return commit_ready(0);
}

}  // namespace motiondb
