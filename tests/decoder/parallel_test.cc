// SPDX-License-Identifier: MIT
// The library's one runner (cbrdf/parallel.h): every task once, the thread limit and per-call
// requests, nesting, exceptions, a custom runner, and many loops at once.
#include "cbrdf/parallel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <stdexcept>
#include <thread>
#include <vector>

#include "parallel_for.h"

namespace cbrdf {
namespace {

using internal::parallel_for;
using internal::parallel_rows;
using internal::threads_for;

// Restores the default limit and runner after each test.
class Parallel : public ::testing::Test {
 protected:
  void TearDown() override {
    set_thread_limit(0);
    set_parallel_runner(nullptr);
  }
};

// Counts the tasks running at once; each task lingers so that the pool's threads overlap.
class ConcurrencyProbe {
 public:
  void enter() {
    const int now = ++running_;
    int seen = max_.load();
    while (now > seen && !max_.compare_exchange_weak(seen, now)) {
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    --running_;
  }
  int max() const { return max_.load(); }

 private:
  std::atomic<int> running_{0}, max_{0};
};

TEST_F(Parallel, EveryTaskRunsExactlyOnce) {
  for (int tasks : {0, 1, 2, 7, 1000}) {
    std::vector<std::atomic<int>> runs(static_cast<std::size_t>(tasks));
    parallel_for(tasks, 0, [&](int t) { ++runs[std::size_t(t)]; });
    for (int t = 0; t < tasks; ++t) EXPECT_EQ(runs[std::size_t(t)].load(), 1) << tasks << " " << t;
  }
}

TEST_F(Parallel, LimitDefaultsToHardwareThreadsAndClamps) {
  const int cores = std::max(1, int(std::thread::hardware_concurrency()));
  EXPECT_EQ(thread_limit(), std::min(cores, kMaxThreadLimit));
  set_thread_limit(3);
  EXPECT_EQ(thread_limit(), 3);
  set_thread_limit(100000);
  EXPECT_EQ(thread_limit(), kMaxThreadLimit);
  set_thread_limit(-5);
  EXPECT_EQ(thread_limit(), std::min(cores, kMaxThreadLimit));
}

TEST_F(Parallel, ThreadsForTakesTheSmallestOfRequestLimitAndTasks) {
  set_thread_limit(4);
  EXPECT_EQ(threads_for(100, 0), 4);
  EXPECT_EQ(threads_for(100, 2), 2);
  EXPECT_EQ(threads_for(100, 9), 4);
  EXPECT_EQ(threads_for(3, 0), 3);
  EXPECT_EQ(threads_for(0, 0), 1);
}

// The pool must really run tasks side by side (the limit is above the hardware's on small
// machines, which is allowed) and never more than the limit or the per-call request.
TEST_F(Parallel, ConcurrencyStaysWithinLimitAndRequest) {
  set_thread_limit(3);
  ConcurrencyProbe limited;
  parallel_for(60, 0, [&](int) { limited.enter(); });
  EXPECT_LE(limited.max(), 3);
  EXPECT_GE(limited.max(), 2);

  ConcurrencyProbe requested;
  parallel_for(60, 2, [&](int) { requested.enter(); });
  EXPECT_LE(requested.max(), 2);

  set_thread_limit(1);
  ConcurrencyProbe serial;
  const std::thread::id caller = std::this_thread::get_id();
  parallel_for(20, 8, [&](int) {
    serial.enter();
    EXPECT_EQ(std::this_thread::get_id(), caller);
  });
  EXPECT_EQ(serial.max(), 1);
}

TEST_F(Parallel, RowsAreSplitIntoContiguousBlocksCoveringEveryRow) {
  set_thread_limit(3);
  std::vector<int> owner(100, -1);
  std::atomic<int> blocks{0};
  parallel_rows(100, 0, [&](int begin, int end) {
    const int b = blocks++;
    for (int r = begin; r < end; ++r) owner[std::size_t(r)] = b;
  });
  EXPECT_EQ(blocks.load(), 3);
  for (int r = 0; r < 100; ++r) ASSERT_GE(owner[std::size_t(r)], 0) << r;
  // Blocks are contiguous: the owner changes exactly twice along the rows.
  int changes = 0;
  for (int r = 1; r < 100; ++r) changes += owner[std::size_t(r)] != owner[std::size_t(r - 1)];
  EXPECT_EQ(changes, 2);

  int calls = 0;
  parallel_rows(0, 0, [&](int begin, int end) {
    ++calls;
    EXPECT_EQ(begin, 0);
    EXPECT_EQ(end, 0);
  });
  EXPECT_EQ(calls, 1);
}

TEST_F(Parallel, NestedLoopsRunInlineWithoutDeadlock) {
  set_thread_limit(4);
  std::atomic<int> inner_runs{0};
  std::atomic<bool> inner_left_thread{false};
  parallel_for(8, 0, [&](int) {
    EXPECT_EQ(threads_for(100, 0), 1);
    const std::thread::id outer = std::this_thread::get_id();
    parallel_for(50, 0, [&](int) {
      if (std::this_thread::get_id() != outer) inner_left_thread = true;
      parallel_rows(10, 0, [&](int begin, int end) { inner_runs += end - begin; });
    });
  });
  EXPECT_EQ(inner_runs.load(), 8 * 50 * 10);
  EXPECT_FALSE(inner_left_thread.load());
  // After the nested loops the calling thread is a top-level caller again.
  EXPECT_EQ(threads_for(100, 0), 4);
}

TEST_F(Parallel, LoopsFromManyThreadsAtOnceAllComplete) {
  set_thread_limit(4);
  std::vector<std::thread> callers;
  std::vector<long> sums(6, 0);
  for (int c = 0; c < 6; ++c) {
    callers.emplace_back([&sums, c] {
      for (int rep = 0; rep < 20; ++rep) {
        std::vector<long> parts(200, 0);
        parallel_for(200, 0, [&](int t) { parts[std::size_t(t)] = t; });
        for (long p : parts) sums[std::size_t(c)] += p;
      }
    });
  }
  for (std::thread& t : callers) t.join();
  for (long s : sums) EXPECT_EQ(s, 20L * 199 * 200 / 2);
}

TEST_F(Parallel, FirstExceptionIsRethrownAndLaterLoopsStillWork) {
  set_thread_limit(4);
  std::atomic<int> started{0};
  EXPECT_THROW(parallel_for(1000, 0,
                            [&](int t) {
                              ++started;
                              if (t == 3) throw std::runtime_error("task 3");
                              std::this_thread::sleep_for(std::chrono::microseconds(50));
                            }),
               std::runtime_error);
  EXPECT_LT(started.load(), 1000);  // no further tasks once one has thrown
  // Inline (one thread) the exception propagates as is.
  EXPECT_THROW(parallel_for(5, 1, [](int) { throw std::logic_error("inline"); }), std::logic_error);
  std::atomic<int> runs{0};
  parallel_for(100, 0, [&](int) { ++runs; });
  EXPECT_EQ(runs.load(), 100);
}

TEST_F(Parallel, CustomRunnerIsUsedAndCanBeRemoved) {
  set_thread_limit(4);
  std::atomic<int> runner_calls{0};
  std::atomic<int> runner_tasks{0};
  // A runner that runs the tasks backwards on the calling thread.
  set_parallel_runner([&](int tasks, const std::function<void(int)>& body) {
    ++runner_calls;
    runner_tasks += tasks;
    for (int t = tasks - 1; t >= 0; --t) body(t);
  });
  std::vector<int> order;
  parallel_for(10, 0, [&](int t) {
    order.push_back(t);
    parallel_for(3, 0, [](int) {});  // nested: inline, does not reach the runner
  });
  EXPECT_EQ(runner_calls.load(), 1);
  EXPECT_EQ(runner_tasks.load(), 10);
  ASSERT_EQ(order.size(), 10u);
  EXPECT_EQ(order.front(), 9);
  EXPECT_EQ(order.back(), 0);

  // One thread allowed: inline, not the runner.
  parallel_for(10, 1, [](int) {});
  EXPECT_EQ(runner_calls.load(), 1);

  // Exceptions never reach the runner; the first is rethrown to the caller.
  EXPECT_THROW(parallel_for(10, 0,
                            [](int t) {
                              if (t == 5) throw std::runtime_error("x");
                            }),
               std::runtime_error);
  EXPECT_EQ(runner_calls.load(), 2);

  set_parallel_runner(nullptr);
  parallel_for(10, 0, [](int) {});
  EXPECT_EQ(runner_calls.load(), 2);
}

}  // namespace
}  // namespace cbrdf
