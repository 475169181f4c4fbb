#include "core/query/batch.h"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <stdexcept>

#include "core/util/parallel.h"

namespace accelviz {

namespace {

/// Runs per_ray(i, stats_or_null) over all rays on the worker threads
/// (for_each_chunk), each ray's stats reset first when there are any.
template <typename PerRay>
bool run_batch(std::size_t n, std::span<RayStats> stats, const BatchOptions& batch, PerRay&& per_ray) {
  const bool with_stats = !stats.empty();
  return for_each_chunk(n, batch, [&](std::size_t begin, std::size_t end) {
    if (with_stats) {
      for (std::size_t i = begin; i < end; ++i) {
        stats[i] = RayStats{};
        per_ray(i, &stats[i]);
      }
    } else {
      for (std::size_t i = begin; i < end; ++i) per_ray(i, nullptr);
    }
  });
}

void check_sizes(std::size_t rays, std::size_t out, std::size_t stats, const char* fn) {
  if (out != rays) throw std::invalid_argument(std::string(fn) + ": output span size differs from the ray count");
  if (stats != 0 && stats != rays)
    throw std::invalid_argument(std::string(fn) + ": stats span must be empty or match the ray count");
}

}  // namespace

bool for_each_chunk(std::size_t n, const BatchOptions& batch,
                    const std::function<void(std::size_t begin, std::size_t end)>& per_chunk) {
  std::atomic<std::size_t> done{0};
  std::atomic<bool> cancelled{false};
  std::mutex progress_mutex;
  auto range = [&](std::size_t begin, std::size_t end, unsigned /*thread*/) {
    if (cancelled.load(std::memory_order_relaxed)) return;
    per_chunk(begin, end);
    const std::size_t so_far = done.fetch_add(end - begin, std::memory_order_relaxed) + (end - begin);
    if (batch.progress) {
      // A report may be skipped while another is under way, but not the
      // last one (1.0): it waits, so the caller always hears the end and
      // can still cancel there however the workers were scheduled.
      std::unique_lock lock(progress_mutex, std::defer_lock);
      if (so_far == n)
        lock.lock();
      else
        lock.try_lock();
      if (lock.owns_lock() && !batch.progress(static_cast<double>(so_far) / static_cast<double>(n)))
        cancelled.store(true, std::memory_order_relaxed);
    }
  };
  const std::size_t chunk = std::max<std::size_t>(batch.chunk, 1);
  if (resolve_threads(batch.threads) == 1) {
    // parallel_for hands a single thread the whole range at once; walk it in
    // chunks here so that progress and cancellation still work.
    for (std::size_t b = 0; b < n && !cancelled.load(std::memory_order_relaxed); b += chunk)
      range(b, std::min(n, b + chunk), 0u);
  } else {
    parallel_for(n, batch.threads, chunk, range);
  }
  return !cancelled.load();
}

bool trace_closest(const Accelerator& accel, std::span<const Ray> rays, std::span<Hit> hits, const QueryOptions& query,
                   const BatchOptions& batch, std::span<RayStats> stats) {
  check_sizes(rays.size(), hits.size(), stats.size(), "trace_closest");
  // One closest_hits call per chunk: a structure that walks several rays at
  // once (Bvh's counted walk) gets the whole chunk.
  return for_each_chunk(rays.size(), batch, [&](std::size_t begin, std::size_t end) {
    const std::size_t count = end - begin;
    std::span<RayStats> chunk_stats = stats.empty() ? stats : stats.subspan(begin, count);
    for (RayStats& s : chunk_stats) s = RayStats{};
    accel.closest_hits(rays.subspan(begin, count), hits.subspan(begin, count), query, chunk_stats);
  });
}

bool trace_any(const Accelerator& accel, std::span<const Ray> rays, std::span<std::uint8_t> occluded,
               const QueryOptions& query, const BatchOptions& batch, std::span<RayStats> stats) {
  check_sizes(rays.size(), occluded.size(), stats.size(), "trace_any");
  return run_batch(rays.size(), stats, batch,
                   [&](std::size_t i, RayStats* s) { occluded[i] = accel.any_hit(rays[i], query, s) ? 1 : 0; });
}

namespace {

/// batch with its chunk rounded up to whole packets.
BatchOptions packet_chunks(BatchOptions batch) {
  constexpr std::size_t w = Accelerator::kPacketWidth;
  batch.chunk = (std::max<std::size_t>(batch.chunk, 1) + w - 1) / w * w;
  return batch;
}

}  // namespace

bool trace_closest_packets(const Accelerator& accel, std::span<const Ray> rays, std::span<Hit> hits,
                           const QueryOptions& query, const BatchOptions& batch) {
  check_sizes(rays.size(), hits.size(), 0, "trace_closest_packets");
  return for_each_chunk(rays.size(), packet_chunks(batch), [&](std::size_t begin, std::size_t end) {
    accel.closest_hits_packets(rays.subspan(begin, end - begin), hits.subspan(begin, end - begin), query);
  });
}

bool trace_any_packets(const Accelerator& accel, std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                       const QueryOptions& query, const BatchOptions& batch) {
  check_sizes(rays.size(), occluded.size(), 0, "trace_any_packets");
  return for_each_chunk(rays.size(), packet_chunks(batch), [&](std::size_t begin, std::size_t end) {
    accel.any_hits_packets(rays.subspan(begin, end - begin), occluded.subspan(begin, end - begin), query);
  });
}

}  // namespace accelviz
