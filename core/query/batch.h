#pragma once
// Tracing a span of rays over all threads. One virtual call per ray, none per
// node; with an empty `stats` span the structures run their counter-free fast
// path, so a timed batch measures the product, not the instrumentation.
#include <cstdint>
#include <functional>
#include <span>

#include "core/accel/accel.h"

namespace accelviz {

struct BatchOptions {
  unsigned threads = 0;       ///< worker threads (0: all hardware threads)
  std::size_t chunk = 256;    ///< rays handed to a worker at a time (dynamic balancing)
  ProgressCallback progress;  ///< optional; called from worker threads, one call at a time; false cancels
};

/// Runs per_chunk(begin, end) over [0, n) in chunks of batch.chunk on
/// batch.threads workers (dynamic balancing), what trace_closest and
/// trace_any run on. Progress is reported after each chunk by whichever worker
/// finished it (the calling thread may get no chunk at all when the others
/// are quicker), one call at a time: a worker that finds the callback busy
/// skips its report rather than wait, except the last report (1.0), which
/// waits. A cancel stops every worker at its next chunk; returns false then
/// (a cancel at the last report too).
bool for_each_chunk(std::size_t n, const BatchOptions& batch,
                    const std::function<void(std::size_t begin, std::size_t end)>& per_chunk);

/// Closest hit of every ray into `hits` (same size as `rays`). When `stats` is
/// non-empty it must have the same size and receives each ray's counters
/// (reset first). Returns false when the progress callback cancelled: rays not
/// yet traced are then left untouched. Throws std::invalid_argument on a size mismatch.
bool trace_closest(const Accelerator& accel, std::span<const Ray> rays, std::span<Hit> hits, const QueryOptions& query,
                   const BatchOptions& batch, std::span<RayStats> stats = {});

/// Any hit of every ray: occluded[i] = 1 when something lies in [tmin, tmax].
bool trace_any(const Accelerator& accel, std::span<const Ray> rays, std::span<std::uint8_t> occluded,
               const QueryOptions& query, const BatchOptions& batch, std::span<RayStats> stats = {});

/// The packet queries (Accelerator::closest_hits_packets, any_hits_packets)
/// over all threads: chunks are whole packets of eight consecutive rays, so
/// the packets are the same for every thread count. Counter-free.
bool trace_closest_packets(const Accelerator& accel, std::span<const Ray> rays, std::span<Hit> hits,
                           const QueryOptions& query, const BatchOptions& batch);
bool trace_any_packets(const Accelerator& accel, std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                       const QueryOptions& query, const BatchOptions& batch);

/// Shorthands with only a thread count.
inline bool trace_closest(const Accelerator& accel, std::span<const Ray> rays, std::span<Hit> hits,
                          const QueryOptions& query, unsigned threads, std::span<RayStats> stats = {}) {
  return trace_closest(accel, rays, hits, query, BatchOptions{threads}, stats);
}
inline bool trace_any(const Accelerator& accel, std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                      const QueryOptions& query, unsigned threads, std::span<RayStats> stats = {}) {
  return trace_any(accel, rays, occluded, query, BatchOptions{threads}, stats);
}

}  // namespace accelviz
