#pragma once
// A tiny parallel-for over an index range: dynamic chunks handed out through
// an atomic counter, so uneven work (rays that hit dense regions) balances.
// The extra threads are pooled ones (thread_pool.h), parked between calls.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <memory>
#include <optional>
#include <thread>
#include <type_traits>
#include <vector>

#include "core/util/thread_pool.h"

namespace accelviz {

/// Number of worker threads to use for `requested` (0 = all hardware threads).
inline unsigned resolve_threads(unsigned requested) {
  if (requested > 0) return requested;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw > 0 ? hw : 1;
}

/// Runs fn(0) here and fn(1) .. fn(threads - 1) on pooled threads
/// (thread_pool.h), and returns when all have ended; rethrows the first
/// exception (in thread order) after all have ended. (fn, a temporary
/// included, lives until then: the pooled parts refer to it.)
template <typename Fn>
void fork_join(unsigned threads, Fn&& fn) {
  if (threads <= 1) {
    fn(0u);
    return;
  }
  using F = std::remove_reference_t<Fn>;
  // Part t's call and its task side by side, in one allocation per fork
  // (the task refers to the call, so the call must not move).
  struct Part {
    F* fn;
    unsigned index;
    std::optional<PooledTask> task;
    void operator()() const { (*fn)(index); }
  };
  const std::unique_ptr<Part[]> parts(new Part[threads - 1]);
  for (unsigned t = 1; t < threads; ++t) {
    Part& part = parts[t - 1];
    part.fn = &fn;
    part.index = t;
    part.task.emplace(part);
  }
  std::exception_ptr error;
  try {
    fn(0u);
  } catch (...) {
    error = std::current_exception();
  }
  for (unsigned t = 1; t < threads; ++t) try {
      parts[t - 1].task->join();
    } catch (...) {
      if (!error) error = std::current_exception();
    }
  if (error) std::rethrow_exception(error);
}

/// Calls fn(begin, end, thread_index) over [0, n) in chunks of `chunk`.
/// With threads == 1 everything runs on the calling thread.
template <typename Fn>
void parallel_for(std::size_t n, unsigned threads, std::size_t chunk, Fn&& fn) {
  threads = resolve_threads(threads);
  if (n == 0) return;
  chunk = std::max<std::size_t>(chunk, 1);
  if (threads == 1 || n <= chunk) {
    fn(std::size_t{0}, n, 0u);
    return;
  }
  std::atomic<std::size_t> next{0};
  auto worker = [&](unsigned ti) {
    for (;;) {
      const std::size_t b = next.fetch_add(chunk, std::memory_order_relaxed);
      if (b >= n) break;
      fn(b, std::min(n, b + chunk), ti);
    }
  };
  fork_join(threads, worker);
}

}  // namespace accelviz
