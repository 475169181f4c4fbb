#pragma once
// A tiny parallel-for over an index range: dynamic chunks handed out through
// an atomic counter, so uneven work (rays that hit dense regions) balances.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace accelviz {

/// Number of worker threads to use for `requested` (0 = all hardware threads).
inline unsigned resolve_threads(unsigned requested) {
  if (requested > 0) return requested;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw > 0 ? hw : 1;
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
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(worker, t);
  worker(0);
  for (auto& th : pool) th.join();
}

}  // namespace accelviz
