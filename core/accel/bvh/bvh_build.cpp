// Top-down BVH construction driver, shared by all splitters.
//
// Steps:
//  1. Validate the options and copy bounds/centroids into BuildPrim records
//     (build_bvh; class Bvh fills the records straight from its triangles
//     and calls build_bvh_records).
//  2. Recurse from the root: a node becomes a leaf when it is small enough
//     (max_leaf_size) or when the splitter's SAH says so; otherwise the
//     splitter partitions its range and both children recurse. The binned
//     SAH partitions its nodes of kOutOfPlaceMinPrims records or more into a
//     second array of records, stable, on the threads lent to the split, and
//     their children from there back into the first; the others, and the
//     other splitters, partition in place.
//     Splitters that cannot separate the primitives (all centroids equal) and
//     nodes about to exceed the depth budget fall back to an object median
//     split, so every build terminates with bounded leaves and depth.
//  3. Large subtrees are built on other threads. Each thread writes its subtree
//     into its own node vector, which the parent splices in after joining; the
//     layout (children adjacent, left subtree before right subtree, depth
//     first) is the same whether or not a subtree was built on another thread,
//     so the node array does not depend on the thread count.
//  4. Statistics: counts and depths tallied as the leaves are made (per
//     thread, merged at each join), the SAH cost over the finished array.
#include "core/accel/bvh/bvh_build.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstring>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>

#include "core/analysis/sah.h"
#include "core/util/parallel.h"
#include "core/util/timing.h"

namespace accelviz {

const char* to_string(BvhSplitter s) {
  switch (s) {
    case BvhSplitter::binned_sah:
      return "binned";
    case BvhSplitter::exact_sah:
      return "exact";
    case BvhSplitter::median:
      return "median";
    case BvhSplitter::lbvh:
      return "lbvh";
  }
  return "?";
}

void validate(const BvhOptions& o) {
  const auto fail = [](const std::string& msg) { throw std::invalid_argument("BvhOptions: " + msg); };
  if (o.splitter != BvhSplitter::binned_sah && o.splitter != BvhSplitter::exact_sah &&
      o.splitter != BvhSplitter::median && o.splitter != BvhSplitter::lbvh)
    fail("unknown splitter");
  if (o.buckets < 2 || o.buckets > 256) fail("buckets must be in 2..256, got " + std::to_string(o.buckets));
  if (o.max_leaf_size < 1 || o.max_leaf_size > 255)
    fail("max_leaf_size must be in 1..255, got " + std::to_string(o.max_leaf_size));
  if (o.leaf_size_cap < o.max_leaf_size || o.leaf_size_cap > 255)
    fail("leaf_size_cap must be in max_leaf_size..255 (" + std::to_string(o.max_leaf_size) + "..255), got " +
         std::to_string(o.leaf_size_cap));
  if (!(o.cost_traversal > 0.0f) || !std::isfinite(o.cost_traversal))
    fail("cost_traversal must be finite and > 0, got " + std::to_string(o.cost_traversal));
  if (!(o.cost_intersect > 0.0f) || !std::isfinite(o.cost_intersect))
    fail("cost_intersect must be finite and > 0, got " + std::to_string(o.cost_intersect));
  if (o.wide_width != 0 && o.wide_width != 4 && o.wide_width != 8)
    fail("wide_width must be 0 (auto), 4 or 8, got " + std::to_string(o.wide_width));
  if (o.wide_merge_blocks < -1 || o.wide_merge_blocks > 63)
    fail("wide_merge_blocks must be in -1..63 (-1: auto), got " + std::to_string(o.wide_merge_blocks));
}

namespace bvh_detail {

void range_bounds(std::span<const BuildPrim> prims, Aabb& bounds, Aabb& centroid_bounds) {
  Aabb b, c;
  for (const BuildPrim& p : prims) {
    b.extend(p.bounds);
    c.extend(p.centroid);
  }
  bounds = b;
  centroid_bounds = c;
}

void split_object_median(std::span<BuildPrim> prims, const Aabb& centroid_bounds, SplitResult& out) {
  const int axis = centroid_bounds.largest_axis();
  const std::size_t mid = prims.size() / 2;
  std::nth_element(prims.begin(), prims.begin() + static_cast<std::ptrdiff_t>(mid), prims.end(),
                   [axis](const BuildPrim& a, const BuildPrim& b) { return centroid_less(a, b, axis); });
  out.mid = mid;
  range_bounds(prims.first(mid), out.bounds[0], out.centroid_bounds[0]);
  range_bounds(prims.subspan(mid), out.bounds[1], out.centroid_bounds[1]);
}

namespace {

/// Subtrees at least this large may go to another thread; below it a fork
/// costs more than it saves. 1024 since the forks use pooled threads: two-
/// thread builds of the bunny took 0.81-0.98 of the time they took with
/// 4096 (eight alternated rounds; docs/performance.md, "Pooled threads"),
/// whose tails had subtrees left that no idle thread could take.
constexpr std::size_t kParallelMinPrims = 1024;

struct NodeWork {
  std::uint32_t begin, end;
  Aabb bounds, centroid_bounds;
  std::uint32_t depth;
  bool moved = false;  ///< the records are in the builder's second array (its split moved them)
};

/// The tree's shape, counted as its leaves are made (integers: the same sums
/// in any order, so on any number of threads): what bvh_tree_shape computes
/// from the finished array in a serial pass (4 ms on the dragon).
struct LeafTally {
  std::uint64_t leaves = 0, depth_sum = 0;
  std::uint32_t max_depth = 0;
  void add(std::uint32_t depth) {
    ++leaves;
    depth_sum += depth;
    max_depth = std::max(max_depth, depth);
  }
  void merge(const LeafTally& o) {
    leaves += o.leaves;
    depth_sum += o.depth_sum;
    max_depth = std::max(max_depth, o.max_depth);
  }
};

inline std::uint32_t ceil_log2(std::size_t n) {
  return n <= 1 ? 0u : static_cast<std::uint32_t>(std::bit_width(n - 1));
}

/// Storage for n build records, left unwritten (a vector would initialise
/// each): BuildPrim is an aggregate of trivially copyable members, so a
/// record copied in with memcpy is a record.
class RawRecords {
 public:
  explicit RawRecords(std::size_t n) : n_(n), p_(n > 0 ? HugePageAllocator<BuildPrim>().allocate(n) : nullptr) {}
  ~RawRecords() {
    if (p_) HugePageAllocator<BuildPrim>().deallocate(p_, n_);
  }
  RawRecords(const RawRecords&) = delete;
  RawRecords& operator=(const RawRecords&) = delete;
  std::span<BuildPrim> span() const { return {p_, n_}; }

 private:
  std::size_t n_;
  BuildPrim* p_;
};

class Builder {
 public:
  /// `moved`: empty, or an array as long as `prims` into which the binned
  /// SAH partitions nodes of kOutOfPlaceMinPrims records or more
  /// (SplitScratch::move_to), and out of which it partitions their children
  /// back.
  Builder(const SplitParams& params, Splitter split, std::span<BuildPrim> prims, std::span<BuildPrim> moved,
          unsigned threads, const ProgressCallback& progress)
      : params_(params), split_(split), prims_(prims), moved_(moved), max_threads_(threads), progress_(progress) {
    report_step_ = std::max<std::uint64_t>(1, prims.size() / 128);
  }

  /// Builds the subtree of `w` into `out`, whose element `slot` is the
  /// subtree root, counting its leaves into `tally`.
  void build(const NodeWork& w, HugePageVector<BvhNode>& out, std::uint32_t slot, SplitScratch& scratch,
             LeafTally& tally) {
    if (cancelled_.load(std::memory_order_relaxed)) return;
    const std::size_t n = w.end - w.begin;
    // The records are in prims_, or in moved_ when the parent's split moved
    // them there: a leaf takes them back first; a split of such a node
    // partitions them back (a median split, where they are).
    bool moved = w.moved;
    std::span<BuildPrim> range = (moved ? moved_ : prims_).subspan(w.begin, n);
    const auto in_place = [&] {
      if (!moved) return;
      std::memcpy(prims_.data() + w.begin, range.data(), n * sizeof(BuildPrim));
      range = prims_.subspan(w.begin, n);
      moved = false;
    };
    if (n <= static_cast<std::size_t>(params_.max_leaf_size)) {
      in_place();
      make_leaf(w, out, slot, tally);
      return;
    }
    SplitResult s;
    // The object median needs the node's centroid bounds, which a
    // bounds_after splitter's children do not carry: computed here, for the
    // (rare) nodes that fall back to it.
    const auto median_split = [&] {
      Aabb centroids = w.centroid_bounds;
      if (split_.bounds_after) {
        Aabb unused;
        range_bounds(range, unused, centroids);
      }
      split_object_median(range, centroids, s);
    };
    // Depth budget: a node at depth d with n primitives can always finish
    // within kBvhMaxDepth when d + ceil(log2 n) <= kBvhMaxDepth and every
    // split from here on halves n; so once that sum reaches the budget, only
    // median splits are allowed. Traversal stacks rely on this bound.
    if (w.depth + ceil_log2(n) >= kBvhMaxDepth) {
      median_split();
    } else {
      const ThreadLoan loan(*this, scratch, n);
      // Out of place: every node this large (on any number of threads, so
      // the tree is the same on all; partition_to on the lent threads), and
      // every node whose records are in moved_ (back to prims_).
      const bool move_out = moved || (!moved_.empty() && n >= kOutOfPlaceMinPrims);
      scratch.move_to = move_out ? (moved ? prims_ : moved_).subspan(w.begin, n) : std::span<BuildPrim>{};
      const SplitOutcome r = split_.split(params_, range, w.bounds, w.centroid_bounds, scratch, s);
      scratch.move_to = {};
      if (r == SplitOutcome::split && s.moved) {
        moved = !moved;
        range = (moved ? moved_ : prims_).subspan(w.begin, n);
      }
      if (r == SplitOutcome::leaf) {
        in_place();
        make_leaf(w, out, slot, tally);
        return;
      }
      if (r == SplitOutcome::unsplittable) {
        if (n <= static_cast<std::size_t>(params_.leaf_size_cap)) {
          in_place();
          make_leaf(w, out, slot, tally);
          return;
        }
        median_split();
      }
    }
    // Every split must separate; a splitter bug must not recurse forever.
    if (s.mid == 0 || s.mid >= n) median_split();

    const std::uint32_t mid = w.begin + static_cast<std::uint32_t>(s.mid);
    const NodeWork left{w.begin, mid, s.bounds[0], s.centroid_bounds[0], w.depth + 1, moved};
    const NodeWork right{mid, w.end, s.bounds[1], s.centroid_bounds[1], w.depth + 1, moved};
    const auto first_child = static_cast<std::uint32_t>(out.size());
    out.resize(out.size() + 2);
    out[slot] = BvhNode{w.bounds, first_child, 0};

    if (right.end - right.begin >= kParallelMinPrims && try_acquire_thread()) {
      // The right subtree goes into its own vector (its root at 0) on another
      // thread; the left one is built here, straight into `out`.
      HugePageVector<BvhNode> right_nodes;
      LeafTally right_tally;
      std::exception_ptr right_error;
      const auto build_right = [&] {
        try {
          SplitScratch own_scratch;
          right_nodes.reserve(2 * (right.end - right.begin));
          right_nodes.resize(1);
          build(right, right_nodes, 0, own_scratch, right_tally);
        } catch (...) {
          right_error = std::current_exception();
          cancelled_.store(true);
        }
        release_thread();
      };
      PooledTask worker(build_right);  // a parked thread (core/util/thread_pool.h)
      try {
        build(left, out, first_child, scratch, tally);
      } catch (...) {
        cancelled_.store(true);
        worker.join();
        throw;
      }
      // While it waits for the right subtree this thread is idle: its count
      // goes back, so that a split elsewhere can take another thread meanwhile
      // (else the count stays full while threads wait, and the builds of
      // uneven SAH subtrees run on fewer threads than asked for). Counted
      // again after; the count may pass max_threads_ by one until a worker
      // ends, when no split can take a thread.
      release_thread();
      worker.join();
      active_threads_.fetch_add(1);
      if (right_error) std::rethrow_exception(right_error);
      if (cancelled_.load(std::memory_order_relaxed)) return;
      tally.merge(right_tally);
      // Splice: right_nodes[0] is the right child; its descendants follow the
      // left subtree, so local index i (>= 1) becomes base + i - 1.
      const auto base = static_cast<std::uint32_t>(out.size());
      const auto rebase = [base](BvhNode nd) {
        if (nd.count == 0) nd.index = base + nd.index - 1;
        return nd;
      };
      out[first_child + 1] = rebase(right_nodes[0]);
      out.reserve(out.size() + right_nodes.size() - 1);
      for (std::size_t i = 1; i < right_nodes.size(); ++i) out.push_back(rebase(right_nodes[i]));
    } else {
      build(left, out, first_child, scratch, tally);
      build(right, out, first_child + 1, scratch, tally);
    }
    // Boxed on the way back up (children done, on whichever thread built them).
    if (split_.bounds_after) out[slot].bounds = Aabb::merge(out[first_child].bounds, out[first_child + 1].bounds);
  }

  /// After the build: throws what a callback threw, or BuildCancelled.
  void finish() {
    if (callback_error_) std::rethrow_exception(callback_error_);
    if (cancelled_.load()) throw BuildCancelled();
    if (progress_) {
      bool go_on = true;
      go_on = progress_(1.0);
      if (!go_on) throw BuildCancelled();
    }
  }

 private:
  void make_leaf(const NodeWork& w, HugePageVector<BvhNode>& out, std::uint32_t slot, LeafTally& tally) {
    tally.add(w.depth);
    Aabb bounds = w.bounds;
    if (split_.bounds_after) {  // the geometric half of range_bounds (centroids are not needed here)
      bounds = Aabb{};
      for (std::uint32_t k = w.begin; k < w.end; ++k) bounds.extend(prims_[k].bounds);
    }
    out[slot] = BvhNode{bounds, w.begin, w.end - w.begin};
    if (!progress_) return;
    const std::uint64_t n = w.end - w.begin;
    const std::uint64_t before = placed_.fetch_add(n, std::memory_order_relaxed);
    if (before / report_step_ == (before + n) / report_step_) return;
    // The callback is user code: one thread at a time calls it; a thread that
    // finds it busy skips this report rather than wait.
    std::unique_lock lock(progress_mutex_, std::try_to_lock);
    if (!lock.owns_lock() || cancelled_.load()) return;
    try {
      if (!progress_(static_cast<double>(before + n) / static_cast<double>(prims_.size()))) cancelled_.store(true);
    } catch (...) {
      callback_error_ = std::current_exception();
      cancelled_.store(true);
    }
  }

  /// Idle build threads lent to one large binned split for its duration
  /// (SplitScratch::helpers): the top of the tree, where fewer subtrees than
  /// threads are under way, splits on all of them instead of one.
  struct ThreadLoan {
    Builder& builder;
    SplitScratch& scratch;
    ThreadLoan(Builder& b, SplitScratch& s, std::size_t n) : builder(b), scratch(s) {
      scratch.helpers = 0;
      if (!b.split_.uses_helpers || n < kParallelSplitMinPrims) return;
      while (scratch.helpers + 1 < n / kParallelSplitGrain && b.try_acquire_thread()) ++scratch.helpers;
    }
    ~ThreadLoan() {
      for (; scratch.helpers > 0; --scratch.helpers) builder.release_thread();
    }
    ThreadLoan(const ThreadLoan&) = delete;
    ThreadLoan& operator=(const ThreadLoan&) = delete;
  };

  bool try_acquire_thread() {
    unsigned active = active_threads_.load();
    while (active < max_threads_) {
      if (active_threads_.compare_exchange_weak(active, active + 1)) return true;
    }
    return false;
  }
  void release_thread() { active_threads_.fetch_sub(1); }

  const SplitParams params_;
  const Splitter split_;
  std::span<BuildPrim> prims_;
  std::span<BuildPrim> moved_;
  const unsigned max_threads_;
  const ProgressCallback& progress_;
  std::atomic<unsigned> active_threads_{1};
  std::atomic<bool> cancelled_{false};
  std::atomic<std::uint64_t> placed_{0};
  std::uint64_t report_step_ = 1;
  std::mutex progress_mutex_;
  std::exception_ptr callback_error_;
};

}  // namespace
}  // namespace bvh_detail

BvhTopology build_bvh(std::span<const Aabb> bounds, std::span<const glm::vec3> centroids, const BvhOptions& opts,
                      const ProgressCallback& progress) {
  using namespace bvh_detail;
  const auto t0 = std::chrono::steady_clock::now();
  validate(opts);
  if (bounds.size() != centroids.size())
    throw std::invalid_argument("build_bvh: " + std::to_string(bounds.size()) + " bounds but " +
                                std::to_string(centroids.size()) + " centroids");
  // 1. Build records (in id order) and root bounds, then the tree.
  BvhTopology topo = build_bvh_from(
      bounds.size(), [&](std::size_t i) { return bounds[i]; }, [&](std::size_t i, const Aabb&) { return centroids[i]; },
      opts, progress);
  topo.stats.build_ms = ms_since(t0);
  return topo;
}

namespace bvh_detail {

void check_prim_count(std::size_t n) {
  if (n >= std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("build_bvh: too many primitives for 32-bit indices");
}

BvhTopology build_bvh_records(std::span<BuildPrim> prims, const Aabb& root_bounds, const Aabb& root_centroids,
                              const BvhOptions& opts, const ProgressCallback& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  validate(opts);
  check_prim_count(prims.size());

  BvhTopology topo;
  const std::size_t n = prims.size();
  bvh_detail::LeafTally leaves;
  if (n > 0) {
    // 2.-3. Recursive build.
    SplitParams params{opts.buckets, opts.max_leaf_size, opts.leaf_size_cap, opts.cost_traversal, opts.cost_intersect};
    params.small_node_buckets = opts.small_node_buckets;
    HugePageVector<std::uint32_t> morton_codes;
    if (opts.splitter == BvhSplitter::lbvh) {
      params.morton = morton_frame(root_centroids);
      morton_codes = lbvh_sort(prims, params.morton, resolve_threads(opts.threads));
      params.morton_codes = morton_codes;
      params.morton_base = prims.data();
    }
    // Only the binned SAH bins on lent threads (bin_primitives_parallel).
    const Splitter split = opts.splitter == BvhSplitter::binned_sah  ? Splitter{split_binned_sah, true}
                           : opts.splitter == BvhSplitter::exact_sah ? Splitter{split_exact_sah}
                           : opts.splitter == BvhSplitter::lbvh      ? Splitter{split_lbvh, false, true}
                                                                     : Splitter{split_median};
    // The binned SAH's second array of records (see Builder), unwritten:
    // raw storage (a vector would initialise every record), reused from
    // build to build like the other build arrays (HugePageAllocator).
    const RawRecords moved(opts.splitter == BvhSplitter::binned_sah && n >= kOutOfPlaceMinPrims ? n : 0);
    Builder builder(params, split, prims, moved.span(), resolve_threads(opts.threads), progress);
    // At most 2n - 1 nodes: reserving them all spares the regrowth copies.
    // No shrink_to_fit after: pages never written are never touched (not
    // resident), and trimming would copy the whole array (18.5 MB and 4.5k
    // page faults on the dragon) for address space alone.
    topo.nodes.reserve(2 * n);
    topo.nodes.resize(1);
    SplitScratch scratch;
    builder.build(NodeWork{0, static_cast<std::uint32_t>(n), root_bounds, root_centroids, 0}, topo.nodes, 0, scratch,
                  leaves);
    builder.finish();
    topo.prim_indices.resize(n);
    parallel_for(n, resolve_threads(opts.threads), kRecordChunk, [&](std::size_t begin, std::size_t end, unsigned) {
      for (std::size_t i = begin; i < end; ++i) topo.prim_indices[i] = prims[i].id;
    });
  } else if (progress && !progress(1.0)) {
    throw BuildCancelled();
  }

  // 4. Statistics: the shape as the leaves were made (bvh_tree_shape's
  //    figures), the SAH cost on all build threads.
  BuildStats& st = topo.stats;
  st.node_count = topo.nodes.size();
  st.leaf_count = leaves.leaves;
  st.max_depth = leaves.max_depth;
  st.avg_leaf_depth =
      leaves.leaves > 0 ? static_cast<double>(leaves.depth_sum) / static_cast<double>(leaves.leaves) : 0.0;
  st.memory_bytes = topo.nodes.size() * sizeof(BvhNode) + topo.prim_indices.size() * sizeof(std::uint32_t);
  st.sah_cost = bvh_sah_cost(topo.nodes, opts.cost_traversal, opts.cost_intersect, resolve_threads(opts.threads));
  st.build_ms = ms_since(t0);
  return topo;
}

}  // namespace bvh_detail

}  // namespace accelviz
