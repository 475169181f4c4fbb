// Pooled threads (core/util/thread_pool.h) and fork_join/parallel_for over
// them: every task runs at once (tasks that wait on each other finish),
// parked threads are reused, exceptions come back to the joiner, nested
// forks do not deadlock.
#include <gtest/gtest.h>

#include <atomic>
#include <barrier>
#include <chrono>
#include <cstddef>
#include <memory>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "core/util/parallel.h"
#include "core/util/thread_pool.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_thread_pool {

using namespace accelviz;

TEST(ThreadPool, TaskRunsOnAnotherThreadAndJoinWaitsForIt) {
  std::thread::id ran_on;
  int value = 0;
  const auto task = [&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ran_on = std::this_thread::get_id();
    value = 42;
  };
  PooledTask t(task);
  t.join();
  EXPECT_EQ(value, 42);
  EXPECT_NE(ran_on, std::this_thread::get_id());
}

TEST(ThreadPool, EveryTaskRunsAtOnce) {
  // Four tasks and this thread meet at a barrier: only when all five run at
  // the same time does any of them get past it (a pool that queued tasks
  // behind busy threads would hang here; the test's timeout catches that).
  constexpr int kTasks = 4;
  std::barrier meet(kTasks + 1);
  std::atomic<int> past{0};
  const auto task = [&] {
    meet.arrive_and_wait();
    past.fetch_add(1);
  };
  std::vector<std::unique_ptr<PooledTask>> tasks;
  for (int i = 0; i < kTasks; ++i) tasks.push_back(std::make_unique<PooledTask>(task));
  meet.arrive_and_wait();
  for (auto& t : tasks) t->join();
  EXPECT_EQ(past.load(), kTasks);
}

TEST(ThreadPool, ParkedThreadsAreReused) {
  // A thread is parked again before its task's joiner wakes, so a loop of
  // two-thread forks keeps using the same pooled thread.
  std::atomic<int> calls{0};
  auto part = [&](unsigned) { calls.fetch_add(1); };
  fork_join(2, part);
  const std::size_t started = PooledTask::started_threads();
  EXPECT_GE(PooledTask::parked_threads(), 1u);
  std::set<std::thread::id> ids;
  std::mutex m;
  auto where = [&](unsigned index) {
    calls.fetch_add(1);
    if (index == 1) {
      const std::lock_guard lock(m);
      ids.insert(std::this_thread::get_id());
    }
  };
  for (int round = 0; round < 200; ++round) fork_join(2, where);
  EXPECT_EQ(calls.load(), 2 + 400);
  EXPECT_EQ(PooledTask::started_threads(), started);
  EXPECT_EQ(ids.size(), 1u);
}

TEST(ThreadPool, NestedForksThatWaitOnEachOtherFinish) {
  // Each level forks the next and waits for it, eight deep, while the
  // outer levels' threads are busy waiting: a pool that handed a fork to a
  // busy thread would deadlock.
  std::atomic<int> depth_reached{0};
  struct Level {
    std::atomic<int>& reached;
    int depth;
    void operator()() const {
      reached.fetch_add(1);
      if (depth == 0) return;
      const Level next{reached, depth - 1};
      PooledTask t(next);
      t.join();
    }
  };
  const Level top{depth_reached, 8};
  top();
  EXPECT_EQ(depth_reached.load(), 9);
}

TEST(ThreadPool, ExceptionsReachTheJoinerAfterEveryPartEnded) {
  std::atomic<int> ended{0};
  auto parts = [&](unsigned index) {
    std::this_thread::sleep_for(std::chrono::milliseconds(index == 2 ? 30 : 1));
    ended.fetch_add(1);
    if (index == 1) throw std::runtime_error("part one failed");
  };
  try {
    fork_join(3, parts);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "part one failed");
  }
  EXPECT_EQ(ended.load(), 3);  // the slow part had ended before the rethrow

  const auto throws = [] { throw std::logic_error("task"); };
  PooledTask t(throws);
  EXPECT_THROW(t.join(), std::logic_error);
}

TEST(ThreadPool, ParallelForCoversTheRangeOnceFromPooledThreads) {
  for (unsigned threads : {1u, 2u, 3u, 7u})
    for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{999}, std::size_t{100000}}) {
      std::vector<std::atomic<int>> hits(n);
      parallel_for(n, threads, 64, [&](std::size_t b, std::size_t e, unsigned ti) {
        EXPECT_LT(ti, threads);
        for (std::size_t i = b; i < e; ++i) hits[i].fetch_add(1);
      });
      for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(hits[i].load(), 1) << "threads " << threads << " index " << i;
    }
}

}  // namespace unity_test_thread_pool
