#pragma once
// Book-keeping shared by the top-down builders of the space-partitioning
// trees (K-D tree, octree): the SAH sum, the leaves and their depths, and the
// build's progress as a share of the whole, gathered while the nodes are made.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

#include "core/accel/accel.h"
#include "core/util/parallel.h"

namespace accelviz::spatial {

/// The K-D tree and the octree build scenes of fewer triangles on one thread
/// (more: the top of the tree on one, its subtrees as jobs on all).
inline constexpr std::size_t kParallelBuildMin = 16384;

/// Runs build(job) for every job (each with its triangles in `prims`) on
/// `threads` threads, the jobs with the most triangles first, so that the
/// long ones do not start last.
template <class Job, class Build>
void build_jobs(std::vector<Job>& jobs, unsigned threads, const Build& build) {
  std::vector<std::size_t> order(jobs.size());
  for (std::size_t j = 0; j < order.size(); ++j) order[j] = j;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t x, std::size_t y) { return jobs[x].prims.size() > jobs[y].prims.size(); });
  parallel_for(order.size(), threads, 1, [&](std::size_t b, std::size_t e, unsigned) {
    for (std::size_t k = b; k < e; ++k) build(jobs[order[k]]);
  });
}

/// What a top-down build counts as it makes nodes.
struct TreeTally {
  double sah_sum = 0.0;  ///< inner nodes' C_trav·A plus leaves' C_isect·n·A (half areas A)
  std::uint64_t leaves = 0, empty_leaves = 0;
  std::uint32_t deepest = 0;
  double depth_sum = 0.0;

  /// An inner node whose SAH term is `sah_term`.
  void inner(double sah_term) { sah_sum += sah_term; }

  /// A leaf of `prims` references at `depth` whose SAH term is `sah_term`.
  void leaf(std::size_t prims, int depth, double sah_term) {
    sah_sum += sah_term;
    ++leaves;
    if (prims == 0) ++empty_leaves;
    deepest = std::max(deepest, static_cast<std::uint32_t>(depth));
    depth_sum += depth;
  }

  /// The tree's share of `stats`: nodes, leaves, depths, the SAH cost (the sum
  /// over the root's half area; `flat_root_cost` when the root has none), and
  /// the references against the `prims` primitives (extras "references",
  /// "duplication", "empty_leaves").
  void fill(BuildStats& stats, std::size_t nodes, std::size_t refs, std::size_t prims, double root_half_area,
            double flat_root_cost) const {
    stats.node_count = nodes;
    stats.leaf_count = leaves;
    stats.max_depth = deepest;
    stats.avg_leaf_depth = leaves ? depth_sum / static_cast<double>(leaves) : 0.0;
    stats.sah_cost = root_half_area > 0.0 ? sah_sum / root_half_area : flat_root_cost;
    stats.extra["references"] = static_cast<double>(refs);
    stats.extra["duplication"] = prims ? static_cast<double>(refs) / static_cast<double>(prims) : 0.0;
    stats.extra["empty_leaves"] = static_cast<double>(empty_leaves);
  }
};

/// Progress of a top-down build: each finished leaf adds its share of the
/// whole (its weight); the callback hears of every further 1 % and may
/// cancel the build (BuildCancelled). Builders of subtrees on several
/// threads may share one: one thread at a time calls the callback (a thread
/// that finds it busy leaves the report to a later leaf), and once it has
/// cancelled, every thread's next leaf throws too.
class BuildProgress {
 public:
  explicit BuildProgress(const ProgressCallback& callback) : callback_(callback) {}

  void add(double weight) {
    if (!callback_) return;
    if (cancelled_.load(std::memory_order_relaxed)) throw BuildCancelled();
    const double done = done_.fetch_add(weight, std::memory_order_relaxed) + weight;
    if (done - reported_.load(std::memory_order_relaxed) < 0.01) return;
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || done - reported_.load(std::memory_order_relaxed) < 0.01) return;
    if (cancelled_.load()) throw BuildCancelled();  // another thread's report cancelled while this one waited
    reported_.store(done, std::memory_order_relaxed);
    if (!callback_(std::min(done, 1.0))) {
      cancelled_.store(true);
      throw BuildCancelled();
    }
  }

 private:
  const ProgressCallback& callback_;
  std::atomic<double> done_{0.0}, reported_{0.0};
  std::atomic<bool> cancelled_{false};
  std::mutex mutex_;
};

}  // namespace accelviz::spatial
