// util/parallel_for.h: every index once, per-thread slots, and the failure that does not depend
// on timing.
#include "util/parallel_for.h"

#include <sys/resource.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"

namespace motiondb {
namespace {

TEST(ParallelFor, CallsEveryIndexOnceOnTheThreadsAsked) {
  constexpr int64_t kCount = 5000;
  std::vector<std::atomic<int>> calls(kCount);
  std::vector<std::set<std::thread::id>> ids(4);  // a slot a thread: no lock needed
  ASSERT_TRUE(ParallelFor(kCount, 4, [&](int64_t i, int thread) {
                ++calls[i];
                ids[thread].insert(std::this_thread::get_id());
                return absl::OkStatus();
              }).ok());
  for (int64_t i = 0; i < kCount; ++i) ASSERT_EQ(calls[i], 1) << "index " << i;
  std::set<std::thread::id> all;
  size_t used = 0;
  for (const auto& slot : ids) {
    EXPECT_LE(slot.size(), 1u) << "a thread number was used by two threads";
    used += slot.size();
    all.insert(slot.begin(), slot.end());
  }
  EXPECT_EQ(all.size(), used) << "a thread ran under two thread numbers";
  // The caller runs as thread 0 (when it got an index at all: the others may take them all).
  for (size_t t = 1; t < ids.size(); ++t) {
    EXPECT_FALSE(ids[t].contains(std::this_thread::get_id())) << "the caller ran as thread " << t;
  }
}

TEST(ParallelFor, NoIndicesNoCallsAndOneThreadIsTheCaller) {
  bool called = false;
  EXPECT_TRUE(ParallelFor(0, 4, [&](int64_t, int) {
                called = true;
                return absl::OkStatus();
              }).ok());
  EXPECT_FALSE(called);
  std::set<std::thread::id> ids;
  EXPECT_TRUE(ParallelFor(100, 1, [&](int64_t, int thread) {
                EXPECT_EQ(thread, 0);
                ids.insert(std::this_thread::get_id());
                return absl::OkStatus();
              }).ok());
  EXPECT_EQ(ids, std::set<std::thread::id>{std::this_thread::get_id()});
}

// Indices are handed out in order, so the lowest failing one always runs and its failure is the
// one returned, whichever thread fails first; no index is handed out after a failure.
TEST(ParallelFor, ReturnsTheLowestFailureAndStopsHandingOut) {
  for (int threads : {1, 2, 8}) {
    std::atomic<int64_t> calls{0};
    const absl::Status status = ParallelFor(100000, threads, [&](int64_t i, int) {
      ++calls;
      if (i == 37 || i == 38 || i == 900) {
        return absl::InvalidArgumentError(absl::StrCat("index ", i));
      }
      return absl::OkStatus();
    });
    EXPECT_EQ(status, absl::InvalidArgumentError("index 37")) << threads << " threads";
    // On one thread exactly up to the failure; on more, how many run before the others see
    // it depends on the scheduler.
    if (threads == 1) {
      EXPECT_EQ(calls, 38);
    }
  }
}

TEST(ThreadsFor, ZeroIsOnePerCore) {
  EXPECT_EQ(ThreadsFor(3), 3);
  EXPECT_EQ(ThreadsFor(0), static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
}

TEST(PieceCount, OneAThreadButNoneSmallerThanAsked) {
  EXPECT_EQ(PieceCount(1200, 128, 2), 2);
  EXPECT_EQ(PieceCount(1200, 128, 64), 9);  // 1200 / 128: no piece under 128
  EXPECT_EQ(PieceCount(100, 128, 4), 1);
  EXPECT_EQ(PieceCount(0, 128, 4), 1);
  EXPECT_EQ(PieceCount(1000, 1, 0), ThreadsFor(0));
  for (int64_t count = 0; count < 3000; count += 37) {
    const int pieces = PieceCount(count, 128, 64);
    if (pieces > 1) {
      EXPECT_GE(count / pieces, 128) << count;
    }
  }
}

TEST(ForEachPiece, CoversTheRangeInOrderOnePieceAThread) {
  for (const int pieces : {1, 3, 7}) {
    std::vector<std::pair<int64_t, int64_t>> ranges(pieces);
    std::vector<std::thread::id> threads(pieces);
    ForEachPiece(100, pieces, [&](int piece, int64_t begin, int64_t end) {
      ranges[piece] = {begin, end};
      threads[piece] = std::this_thread::get_id();
    });
    EXPECT_EQ(ranges.front().first, 0);
    EXPECT_EQ(ranges.back().second, 100);
    for (int i = 0; i < pieces; ++i) {
      EXPECT_GE(ranges[i].second - ranges[i].first, 100 / pieces) << i;
      if (i > 0) {
        EXPECT_EQ(ranges[i].first, ranges[i - 1].second) << i;
      }
    }
    EXPECT_EQ(threads[0], std::this_thread::get_id());
    EXPECT_EQ(std::set<std::thread::id>(threads.begin(), threads.end()).size(),
              static_cast<size_t>(pieces));
  }
}

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif

// Leaves the process no room for a thread's stack (glibc maps one of RLIMIT_STACK, 8 MiB by
// default): the address space is capped at its size now plus 256 KiB for the heap.
bool LimitAddressSpaceToCurrent() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmSize:", 0) != 0) continue;
    const rlim_t bytes = std::strtoull(line.c_str() + 7, nullptr, 10) * 1024;
    rlimit limit;
    if (getrlimit(RLIMIT_AS, &limit) != 0) return false;
    limit.rlim_cur = bytes + (256 << 10);
    return setrlimit(RLIMIT_AS, &limit) == 0;
  }
  return false;
}

// With no thread to be had, the caller does all of the work itself, rather than failing or
// dropping the items the threads would have taken. In a child process, whose address space the
// test caps.
TEST(ParallelForDeathTest, TheCallerDoesEverythingWhenNoThreadCanStart) {
  if (kAddressSanitizer) GTEST_SKIP() << "ASan's shadow memory leaves no address space to cap";
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        if (!LimitAddressSpaceToCurrent()) {
          std::fputs("cannot cap the address space\n", stderr);
          std::_Exit(2);
        }
        constexpr int64_t kCount = 1000;
        const std::thread::id caller = std::this_thread::get_id();
        std::vector<std::atomic<int>> calls(kCount);
        std::atomic<bool> elsewhere{false};
        const absl::Status status = ParallelFor(kCount, 4, [&](int64_t i, int thread) {
          ++calls[i];
          if (thread != 0 || std::this_thread::get_id() != caller) elsewhere = true;
          return absl::OkStatus();
        });
        std::vector<std::atomic<int>> covered(kCount);
        ForEachPiece(kCount, 4, [&](int, int64_t begin, int64_t end) {
          for (int64_t i = begin; i < end; ++i) ++covered[i];
          if (std::this_thread::get_id() != caller) elsewhere = true;
        });
        for (int64_t i = 0; i < kCount; ++i) {
          if (calls[i] != 1 || covered[i] != 1) {
            std::fprintf(stderr, "index %lld ran %d / %d times\n", static_cast<long long>(i),
                         calls[i].load(), covered[i].load());
            std::_Exit(1);
          }
        }
        if (elsewhere) std::fputs("a thread started: the cap did not hold\n", stderr);
        std::_Exit(status.ok() && !elsewhere ? 0 : 1);
      },
      ::testing::ExitedWithCode(0), "");
}

}  // namespace
}  // namespace motiondb
