// The parked threads behind PooledTask (thread_pool.h).
#include "core/util/thread_pool.h"

#include <atomic>
#include <memory>
#include <thread>
#include <vector>

namespace accelviz {

namespace {

/// More parked threads than this exit instead of parking (a run that once
/// asked for many threads does not keep them all).
std::size_t max_parked() {
  const unsigned hw = std::thread::hardware_concurrency();
  return 2 * static_cast<std::size_t>(hw > 0 ? hw : 1) + 2;
}

}  // namespace

/// One pooled thread's mailbox: a task handed over, or none.
struct PoolWorker {
  std::mutex m;
  std::condition_variable cv;
  PooledTask* task = nullptr;
};

class ThreadPool {
 public:
  /// Never destroyed: parked threads wait on it until the process ends.
  static ThreadPool& instance() {
    static ThreadPool* pool = new ThreadPool;
    return *pool;
  }

  void start(PooledTask& t) {
    PoolWorker* w = nullptr;
    {
      const std::lock_guard lock(m_);
      if (!parked_.empty()) {
        w = parked_.back();
        parked_.pop_back();
      }
    }
    if (w == nullptr) {
      auto fresh = std::make_unique<PoolWorker>();  // freed if the thread cannot start
      fresh->task = &t;
      std::thread([this, fw = fresh.get()] { loop(fw); }).detach();
      fresh.release();  // the thread's now
      started_.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    {
      const std::lock_guard lock(w->m);
      w->task = &t;
    }
    w->cv.notify_one();
  }

  std::size_t parked() {
    const std::lock_guard lock(m_);
    return parked_.size();
  }
  std::size_t started() const { return started_.load(std::memory_order_relaxed); }

 private:
  void loop(PoolWorker* w) {
    for (;;) {
      PooledTask* t;
      {
        std::unique_lock lock(w->m);
        w->cv.wait(lock, [w] { return w->task != nullptr; });
        t = std::exchange(w->task, nullptr);
      }
      t->execute();
      // Parked again before the task's waiter wakes, so that its next fork
      // finds this thread (a fork-join loop keeps reusing the same ones). A
      // task handed over meanwhile starts right after the wake-up below.
      bool keep;
      {
        const std::lock_guard lock(m_);
        keep = parked_.size() < max_parked();
        if (keep) parked_.push_back(w);
      }
      t->finish();  // t is not touched after
      if (!keep) {
        delete w;
        return;
      }
    }
  }

  std::mutex m_;
  std::vector<PoolWorker*> parked_;
  std::atomic<std::size_t> started_{0};
};

void PooledTask::start() {
  ThreadPool::instance().start(*this);
}

void PooledTask::execute() {
  try {
    call_(fn_);
  } catch (...) {
    error_ = std::current_exception();
  }
}

void PooledTask::finish() {
  // The waiter may destroy *this as soon as it sees done_: set and notified
  // under the lock, so it cannot return before this thread lets go of it.
  const std::lock_guard lock(m_);
  done_ = true;
  cv_.notify_one();
}

void PooledTask::wait() {
  std::unique_lock lock(m_);
  cv_.wait(lock, [this] { return done_; });
}

std::size_t PooledTask::parked_threads() {
  return ThreadPool::instance().parked();
}
std::size_t PooledTask::started_threads() {
  return ThreadPool::instance().started();
}

}  // namespace accelviz
