// util/thread_team.h: every stage on every member, ParallelFor's contract on the team, and the
// ordered commits of ParallelForInOrder.
#include "util/thread_team.h"

#include <atomic>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"

namespace motiondb {
namespace {

TEST(ThreadTeam, RunsStageAfterStageOnTheSameThreads) {
  ThreadTeam team(3);
  ASSERT_EQ(team.size(), 3);
  std::vector<std::set<std::thread::id>> ids(3);  // a slot a member
  for (int stage = 0; stage < 50; ++stage) {
    constexpr int64_t kCount = 997;
    std::vector<std::atomic<int>> calls(kCount);
    ASSERT_TRUE(team.ParallelFor(kCount,
                                 [&](int64_t i, int member) {
                                   ++calls[i];
                                   ids[member].insert(std::this_thread::get_id());
                                   return absl::OkStatus();
                                 })
                    .ok());
    for (int64_t i = 0; i < kCount; ++i) ASSERT_EQ(calls[i], 1) << "stage " << stage << ", " << i;
  }
  std::set<std::thread::id> all;
  for (const auto& member : ids) {
    EXPECT_LE(member.size(), 1u) << "a member ran on two threads";
    all.insert(member.begin(), member.end());
  }
  EXPECT_TRUE(ids[0].empty() || *ids[0].begin() == std::this_thread::get_id());
  size_t used = 0;
  for (const auto& member : ids) used += member.size();
  EXPECT_EQ(all.size(), used) << "a thread ran as two members";
}

TEST(ThreadTeam, ReturnsTheLowestFailureAndOneIsTheCallerAlone) {
  ThreadTeam team(4);
  const absl::Status status = team.ParallelFor(1000, [](int64_t i, int) {
    return i % 100 == 37 ? absl::InternalError(absl::StrCat("index ", i)) : absl::OkStatus();
  });
  EXPECT_EQ(status, absl::InternalError("index 37"));
  ThreadTeam alone(1);
  EXPECT_EQ(alone.size(), 1);
  std::set<std::thread::id> ids;
  EXPECT_TRUE(alone
                  .ParallelFor(100,
                               [&](int64_t, int member) {
                                 EXPECT_EQ(member, 0);
                                 ids.insert(std::this_thread::get_id());
                                 return absl::OkStatus();
                               })
                  .ok());
  EXPECT_EQ(ids, std::set<std::thread::id>{std::this_thread::get_id()});
}

TEST(ThreadTeamInOrder, CommitsEachIndexInOrderAfterItsComputeOneAtATime) {
  constexpr int64_t kCount = 20000;
  for (const int threads : {1, 2, 4}) {
    std::vector<std::atomic<bool>> computed(kCount);
    std::vector<int64_t> committed;  // only commits touch it: they never run at once
    std::atomic<int> committing = 0;
    std::atomic<int> overlaps = 0, early = 0;
    // What a compute reads of the commits so far: always at most its own index.
    std::atomic<int64_t> published = 0;
    std::atomic<int> ahead = 0;
    ThreadTeam team(threads);
    ASSERT_TRUE(team.ParallelForInOrder(
                        kCount,
                        [&](int64_t i, int) {
                          if (published.load() > i) ++ahead;
                          computed[i] = true;
                          return absl::OkStatus();
                        },
                        [&](int64_t i, int) {
                          if (++committing > 1) ++overlaps;
                          if (!computed[i]) ++early;
                          committed.push_back(i);
                          published = i + 1;
                          --committing;
                          return absl::OkStatus();
                        })
                    .ok());
    ASSERT_EQ(committed.size(), static_cast<size_t>(kCount)) << threads;
    for (int64_t i = 0; i < kCount; ++i) ASSERT_EQ(committed[i], i) << threads;
    EXPECT_EQ(overlaps, 0) << threads;
    EXPECT_EQ(early, 0) << threads;
    EXPECT_EQ(ahead, 0) << threads;
  }
}

TEST(ThreadTeamInOrder, OneThreadAlternatesComputeAndCommit) {
  std::vector<std::string> calls;
  ThreadTeam team(1);
  ASSERT_TRUE(team.ParallelForInOrder(
                      3,
                      [&](int64_t i, int thread) {
                        EXPECT_EQ(thread, 0);
                        calls.push_back(absl::StrCat("compute ", i));
                        return absl::OkStatus();
                      },
                      [&](int64_t i, int) {
                        calls.push_back(absl::StrCat("commit ", i));
                        return absl::OkStatus();
                      })
                  .ok());
  EXPECT_EQ(calls, (std::vector<std::string>{"compute 0", "commit 0", "compute 1", "commit 1",
                                             "compute 2", "commit 2"}));
}

TEST(ThreadTeamInOrder, AFailureEndsItAndIsReturned) {
  for (const int threads : {1, 2, 4}) {
    ThreadTeam team(threads);
    std::atomic<int64_t> last_commit = -1;
    const absl::Status commit_failed = team.ParallelForInOrder(
        1000, [](int64_t, int) { return absl::OkStatus(); },
        [&](int64_t i, int) {
          if (i == 500) return absl::CancelledError("stop at 500");
          last_commit = i;
          return absl::OkStatus();
        });
    EXPECT_EQ(commit_failed, absl::CancelledError("stop at 500")) << threads;
    EXPECT_EQ(last_commit, 499) << threads;

    std::atomic<int64_t> commits_after = 0;
    const absl::Status compute_failed = team.ParallelForInOrder(
        1000,
        [](int64_t i, int) {
          return i == 300 ? absl::DeadlineExceededError("compute 300") : absl::OkStatus();
        },
        [&](int64_t i, int) {
          if (i >= 300) ++commits_after;
          return absl::OkStatus();
        });
    EXPECT_EQ(compute_failed, absl::DeadlineExceededError("compute 300")) << threads;
    EXPECT_EQ(commits_after, 0) << threads;
  }
}

// A commit that failed once would succeed if tried again (another member's stop has not said
// stop yet): it is not tried again, and its failure is the answer.
TEST(ThreadTeamInOrder, AFailedCommitIsNotTriedAgain) {
  for (const int threads : {1, 2, 4}) {
    ThreadTeam team(threads);
    std::atomic<int> tries = 0;
    std::atomic<int64_t> committed_past = 0;
    const absl::Status status = team.ParallelForInOrder(
        2000, [](int64_t, int) { return absl::OkStatus(); },
        [&](int64_t i, int) {
          if (i == 500 && tries++ == 0) return absl::CancelledError("stopped at 500");
          if (i >= 500) ++committed_past;
          return absl::OkStatus();
        });
    EXPECT_EQ(status, absl::CancelledError("stopped at 500")) << threads;
    EXPECT_EQ(tries, 1) << threads;
    EXPECT_EQ(committed_past, 0) << threads;
  }
}

}  // namespace
}  // namespace motiondb
