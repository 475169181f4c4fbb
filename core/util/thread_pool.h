#pragma once
// Parked threads for the library's fork-join work (parallel_for, the BVH
// builder's subtrees, the LBVH's sort): a thread that finishes its task
// waits for the next one instead of exiting, so a fork costs a wake-up
// (a few microseconds) instead of a thread's creation and exit (80-100 us
// per create and join on the development VM). Semantics stay those of
// std::thread: every task runs at once, on its own thread (a new one when
// none is parked), so tasks may fork and wait on each other without a
// deadlock.
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <mutex>
#include <utility>

namespace accelviz {

/// One task on a pooled thread: started by the constructor, waited for by
/// join() (or the destructor). An exception the task throws is rethrown
/// by join(). The callable is referred to, not copied: it must outlive the
/// task (an lvalue; a temporary does not compile). Not copyable or movable:
/// the pooled thread refers to it.
class PooledTask {
 public:
  template <class Fn>
  explicit PooledTask(Fn& fn) : fn_(const_cast<void*>(static_cast<const void*>(&fn))), call_(&call<Fn>) {
    start();
  }
  ~PooledTask() {
    if (!joined_) wait();
  }
  PooledTask(const PooledTask&) = delete;
  PooledTask& operator=(const PooledTask&) = delete;

  /// Waits for the task to end; rethrows what it threw.
  void join() {
    wait();
    joined_ = true;
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  }

  /// Pooled threads now parked (for tests).
  static std::size_t parked_threads();
  /// Threads the pool has started since the process began (for tests).
  static std::size_t started_threads();

 private:
  template <class Fn>
  static void call(void* fn) {
    (*static_cast<Fn*>(fn))();
  }
  void start();
  void wait();
  friend class ThreadPool;
  void execute();  ///< on the pooled thread: the task (its exception kept)
  void finish();   ///< on the pooled thread, after execute(): wakes join()

  void* fn_;
  void (*call_)(void*);
  std::exception_ptr error_;
  std::mutex m_;
  std::condition_variable cv_;
  bool done_ = false, joined_ = false;
};

}  // namespace accelviz
