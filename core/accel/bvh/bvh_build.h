#pragma once
// Internals shared by the top-down BVH build driver (bvh_build.cpp) and the
// splitters (one per file: bvh_build_binned.cpp, bvh_build_exact.cpp,
// bvh_build_median.cpp). Not part of the public API: include bvh.h instead.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <span>
#include <vector>

#include "core/accel/bvh/bvh.h"
#include "core/math/aabb.h"
#include "core/util/parallel.h"

namespace accelviz::bvh_detail {

/// A primitive as the builder sees it. The builder partitions an array of
/// these in place, so each node's primitives are contiguous in memory and
/// binning streams through them instead of gathering through an index array
/// (the PrimRef layout of Embree's builders; Wald 2007, section 3).
struct BuildPrim {
  glm::vec3 centroid;
  std::uint32_t id;
  Aabb bounds;
};
static_assert(sizeof(BuildPrim) == 40);

/// The quantisation grid of the LBVH's Morton codes: 1024 cells per axis over
/// the root's centroid bounds (lbvh_builder.cpp).
struct MortonFrame {
  glm::vec3 origin{0.0f};
  float scale[3] = {0.0f, 0.0f, 0.0f};  ///< cells per unit; 0 on a flat axis
};

/// The options a splitter needs, already validated.
struct SplitParams {
  int buckets = 32;
  int max_leaf_size = 4;
  int leaf_size_cap = 16;
  float cost_traversal = 1.0f;
  float cost_intersect = 1.0f;
  MortonFrame morton;  ///< lbvh only
  /// lbvh only, optional: lbvh_sort's sorted codes, morton_codes[i] being
  /// the code of morton_base[i] (the build's whole record array), so that a
  /// split reads codes instead of recomputing them from centroids (a random
  /// record fetch per probe of its binary search). They stay in step with
  /// the records: the driver reorders a range only for an object median,
  /// on a range of equal codes (unsplittable) or under the depth budget,
  /// below which the LBVH cuts nothing (a debug build asserts it).
  std::span<const std::uint32_t> morton_codes;
  const BuildPrim* morton_base = nullptr;
  bool small_node_buckets = true;  ///< binned only: binned_bucket_count's rule
};

enum class SplitOutcome {
  split,         ///< prims partitioned: [0, mid) left, [mid, n) right
  leaf,          ///< the SAH says a leaf is cheaper (only offered when n <= leaf_size_cap)
  unsplittable,  ///< the splitter cannot separate these primitives (e.g. all centroids equal)
};

struct SplitResult {
  std::size_t mid = 0;      ///< primitives in the left child
  Aabb bounds[2];           ///< children's geometric bounds
  Aabb centroid_bounds[2];  ///< children's centroid bounds
  /// The records went to SplitScratch::move_to (left ones first, each side
  /// in its old order); the node's own range is left as it was.
  bool moved = false;
};

/// Nodes of at least this many primitives may be split on several threads:
/// the builder lends its idle threads to them (SplitScratch::helpers), one per
/// kParallelSplitGrain primitives at most. Only the binned SAH uses them, to
/// bin (bin_primitives_parallel) and to partition (partition_to).
inline constexpr std::size_t kParallelSplitMinPrims = 32768;
inline constexpr std::size_t kParallelSplitGrain = 16384;
/// The binned SAH's builder partitions every node of at least this many
/// primitives out of place (SplitScratch::move_to: partition_to, which can
/// run on lent threads), whatever the thread count, so that the tree does
/// not depend on how many threads a split had; and the children of such a
/// node out of place again, back into the build's records. Measured on the
/// 2-vCPU VM (docs/performance.md, "The partition out of place"): builds on
/// one and two threads took 1-12 % less time than with every partition in
/// place, and 0.9-3.5 % less at 256 than at 32768 in ten of twelve cells.
inline constexpr std::size_t kOutOfPlaceMinPrims = 256;

/// Per-thread buffers reused from node to node, so that the recursion does not allocate.
struct SplitScratch {
  std::vector<float> suffix_area;  ///< exact sweep: half area of prims [i, n)
  /// Threads this split may use besides the calling one (set by the builder
  /// for the duration of one split; 0: split on the calling thread alone).
  unsigned helpers = 0;
  /// Set (as long as the node's range) for a binned split that is to write
  /// its records here, partitioned and stable (partition_to), instead of
  /// partitioning them in place; empty: in place. Set by the builder for one
  /// split; splitters other than the binned SAH ignore it.
  std::span<BuildPrim> move_to;
  /// The binning's bucket counts per thread's slice (bin_primitives_parallel),
  /// and each slice's count left of the chosen plane, for partition_to.
  std::vector<std::uint32_t> slice_counts;
  std::vector<std::size_t> slice_left;
};

/// Signature shared by the splitters. `prims` is the node's range,
/// `bounds`/`centroid_bounds` its geometric and centroid bounds, n > max_leaf_size.
using SplitFn = SplitOutcome (*)(const SplitParams& params, std::span<BuildPrim> prims, const Aabb& bounds,
                                 const Aabb& centroid_bounds, SplitScratch& scratch, SplitResult& out);

/// A splitter as the builder drives it: the function, and whether it puts
/// threads lent for one split (SplitScratch::helpers) to use; the builder
/// lends none to one that does not.
struct Splitter {
  SplitFn split;
  bool uses_helpers = false;
  /// The split leaves SplitResult's bounds unset: the driver boxes the tree
  /// bottom up as its recursion returns (a leaf from its primitives, an
  /// inner node from its two children, on the thread that built them), O(n)
  /// in all instead of a pass over every node's primitives at every level.
  /// For splitters that need no bounds to choose their cut (the LBVH).
  bool bounds_after = false;
};

SplitOutcome split_binned_sah(const SplitParams& params, std::span<BuildPrim> prims, const Aabb& bounds,
                              const Aabb& centroid_bounds, SplitScratch& scratch, SplitResult& out);
SplitOutcome split_exact_sah(const SplitParams& params, std::span<BuildPrim> prims, const Aabb& bounds,
                             const Aabb& centroid_bounds, SplitScratch& scratch, SplitResult& out);
SplitOutcome split_median(const SplitParams& params, std::span<BuildPrim> prims, const Aabb& bounds,
                          const Aabb& centroid_bounds, SplitScratch& scratch, SplitResult& out);
/// LBVH (lbvh_builder.cpp): cuts a Morton-sorted range at its highest
/// differing code bit. The range must have been sorted by lbvh_sort. Sets
/// only out.mid (a bounds_after splitter: it ignores its bounds arguments).
SplitOutcome split_lbvh(const SplitParams& params, std::span<BuildPrim> prims, const Aabb& bounds,
                        const Aabb& centroid_bounds, SplitScratch& scratch, SplitResult& out);
MortonFrame morton_frame(const Aabb& centroid_bounds);
/// 30-bit Morton code of a centroid (10 bits per axis, x highest).
std::uint32_t morton_code(const glm::vec3& centroid, const MortonFrame& frame);
/// Sorts primitives (given in id order) by (Morton code, id): stable LSD
/// radix sort on `threads` threads. Returns the sorted codes (code i is
/// prims[i]'s after the sort).
HugePageVector<std::uint32_t> lbvh_sort(std::span<BuildPrim> prims, const MortonFrame& frame, unsigned threads);

/// Bucket contents of one binned SAH pass: bounds (lanes 0..2 used, lane 3 unspecified; 16-byte
/// rows so that the SIMD pass can load and store them whole) and counts, per
/// axis and bucket.
inline constexpr int kMaxBuckets = 256;
struct Bins {
  alignas(16) float lo[3][kMaxBuckets][4];
  alignas(16) float hi[3][kMaxBuckets][4];
  std::uint32_t count[3][kMaxBuckets];
};

/// Bucket of a centroid coordinate: floor((c - lo)·k), clamped to [0, B-1];
/// a NaN lands in bucket 0. The binning passes and the partition use it (or
/// its SIMD equivalent), so they agree exactly.
inline int bucket_of(float c, float lo, float k, int buckets) {
  const float x = (c - lo) * k;
  if (!(x >= 0.0f)) return 0;
  const float top = static_cast<float>(buckets - 1);
  return x < top ? static_cast<int>(x) : buckets - 1;
}

/// bucket_of(c, lo, k, buckets) <= plane for a plane 0 <= plane <= buckets - 2
/// (the partition's test), in one compare: truncation and the clamp to
/// [0, B-1] never move (c - lo)·k across the integer plane + 1, and NaN or
/// negative values fail the compare and go left, as bucket 0 does.
inline bool left_of_plane(float c, float lo, float k, int plane) {
  return !((c - lo) * k >= static_cast<float>(plane + 1));
}

/// The binned SAH's partition in place (split_binned_sah's last step when
/// SplitScratch::move_to is empty): moves the
/// records left of the plane (left_of_plane(centroid[axis], lo, k, plane))
/// before the others and returns their count; each side's centroid bounds
/// come back in left_centroids and right_centroids (the same values as
/// Aabb::extend over the side; a zero's sign may differ). With SSE2 every
/// record is classified without a branch: blocks of 64 at both ends, their
/// misplaced records swapped in pairs (Edelkamp and Weiss's block
/// partition), and the last 127 or fewer through two buffers; builds
/// without SIMD take the two-ended (Hoare) loop.
std::size_t partition_at_plane(std::span<BuildPrim> prims, int axis, float lo, float k, int plane, Aabb& left_centroids,
                               Aabb& right_centroids);

/// Buckets the binned SAH uses on a node of n primitives: with
/// `small_node_buckets` (BvhOptions, default), B on large nodes and
/// min(B, 4 + n/20) on smaller ones (Embree's rule in its binned builders): a
/// small node's split is found among fewer planes, which saves most of the
/// per-node cost of clearing and sweeping B buckets at a small SAH price;
/// without, B everywhere. split_binned_sah and the explainer both use it.
inline int binned_bucket_count(int buckets, bool small_node_buckets, std::size_t n) {
  const std::size_t small = 4 + n / 20;
  return small_node_buckets && small < static_cast<std::size_t>(buckets) ? static_cast<int>(small) : buckets;
}

/// Resets the first `buckets` buckets of every axis to empty.
void clear_bins(Bins& bins, int buckets);
/// Adds every primitive to its bucket on all three axes (Wald 2007):
/// bucket = bucket_of(centroid[a], origin[a], k[a], buckets).
/// bin_primitives uses SSE2 where available (three axes per instruction),
/// and on CPUs with AVX2 an AVX2 pass for ranges of 64 primitives or more
/// (one 32-byte update per bucket); both give the same bits.
/// bin_primitives_scalar is their twin, and the tests check they agree.
void bin_primitives(std::span<const BuildPrim> prims, const glm::vec3& origin, const float k[3], int buckets,
                    Bins& bins);
void bin_primitives_scalar(std::span<const BuildPrim> prims, const glm::vec3& origin, const float k[3], int buckets,
                           Bins& bins);
/// bin_primitives on `threads` threads: each bins a contiguous slice into its
/// own Bins, and the slices merge in order with bin_primitives' min/max
/// operand order, so `bins` comes out bit for bit as bin_primitives leaves it
/// (for bounds without NaN). `bins` must be cleared for `buckets`.
/// With `slice_counts`, also writes each slice's bucket counts there:
/// threads·3·kMaxBuckets values, slice t's count of bucket b on axis a at
/// (t·3 + a)·kMaxBuckets + b (slice t is prims[n·t/threads, n·(t+1)/threads)).
void bin_primitives_parallel(std::span<const BuildPrim> prims, const glm::vec3& origin, const float k[3], int buckets,
                             Bins& bins, unsigned threads, std::uint32_t* slice_counts = nullptr);

/// Box of bucket b on `axis` (empty when the bucket is).
Aabb bucket_box(const Bins& bins, int axis, int b);

/// Outcome of the binned SAH search over one node (split_binned_sah's steps
/// 1-3; the explainer in core/analysis/insight runs the same code).
struct BinnedSahSearch {
  float k[3] = {0.0f, 0.0f, 0.0f};         ///< buckets per unit of centroid extent, per axis (0: axis unusable)
  bool usable[3] = {false, false, false};  ///< the axis's centroids spread (non-zero, finite extent)
  float best_cost = kInfinity;             ///< A_L·N_L + A_R·N_R (half areas) of the best candidate
  std::size_t best_left = 0;               ///< primitives left of the best plane
  int best_axis = -1;                      ///< -1: no plane separates anything
  int best_bucket = -1;                    ///< the best plane lies between buckets best_bucket and best_bucket + 1
};
/// Cost A_L·N_L + A_R·N_R of every candidate plane b (between buckets b and
/// b+1) per axis; NaN where one side is empty or the axis is unusable.
using CandidateCosts = float[3][kMaxBuckets];

/// Bins `prims` into `buckets` buckets over `centroid_bounds` on every
/// usable axis and evaluates the SAH at the B-1 bucket boundaries. Returns
/// false (bins untouched) when no axis is usable (all centroids on one
/// point). With `costs`, also records every candidate's cost. With
/// threads > 1 the binning runs on that many threads (the same bins).
/// With `slice_counts`, the binning's counts per slice go there (resized;
/// see bin_primitives_parallel).
bool binned_sah_search(int buckets, std::span<const BuildPrim> prims, const Aabb& centroid_bounds, Bins& bins,
                       BinnedSahSearch& out, CandidateCosts* costs = nullptr, unsigned threads = 1,
                       std::vector<std::uint32_t>* slice_counts = nullptr);

/// partition_at_plane out of place and stable: writes the records of `src`
/// left of the plane to dst[0, mid) and the others to dst[mid, n), each side
/// in its order in `src`, and returns mid. `slice_left` holds, for each of
/// its S slices of `src` (slice t is src[n·t/S, n·(t+1)/S)), how many of the
/// slice's records are left of the plane, as the binning counted them; the
/// slices are written on S threads (parallel_for). The result, and each
/// side's centroid bounds (merged slice by slice in order, so the bits of one
/// pass), do not depend on S. Throws std::logic_error when a slice's count
/// is not its own (no write leaves `dst` then, but its contents are undefined).
std::size_t partition_to(std::span<const BuildPrim> src, std::span<BuildPrim> dst, int axis, float lo, float k,
                         int plane, std::span<const std::size_t> slice_left, Aabb& left_centroids,
                         Aabb& right_centroids);

/// Object median split: orders the range by centroid on the axis of largest
/// centroid extent (ties by primitive id, so the result is unique) and cuts
/// it in two halves (left gets n/2). Always separates n >= 2 primitives, which
/// is why it is the fallback when a splitter cannot separate them and when the
/// depth budget runs short. Fills the children's bounds.
void split_object_median(std::span<BuildPrim> prims, const Aabb& centroid_bounds, SplitResult& out);

/// build_bvh's steps 2-4 on records the caller has filled: prims[i].id == i
/// (id order, as lbvh_sort requires), `root_bounds`/`root_centroids` their
/// Aabb::extend unions in id order. Reorders `prims`. class Bvh calls this
/// with records made straight from its triangles (no bounds/centroid arrays).
BvhTopology build_bvh_records(std::span<BuildPrim> prims, const Aabb& root_bounds, const Aabb& root_centroids,
                              const BvhOptions& opts, const ProgressCallback& progress = {});
/// Throws std::invalid_argument when n primitives do not fit 32-bit indices.
void check_prim_count(std::size_t n);

/// Records per chunk of build_bvh_from's parallel fill.
inline constexpr std::size_t kRecordChunk = 16384;

/// build_bvh_records over n primitives whose records (in id order) and root
/// bounds come from `bounds_at(i)` and `centroid_at(i, box)` (box =
/// bounds_at(i)): what build_bvh does from its arrays and class Bvh straight
/// from its triangles (build_bvh_from_boxes). bounds_at and centroid_at are
/// called from all build threads.

template <class BoundsAt, class CentroidAt>
BvhTopology build_bvh_from(std::size_t n, const BoundsAt& bounds_at, const CentroidAt& centroid_at,
                           const BvhOptions& opts, const ProgressCallback& progress) {
  check_prim_count(n);
  // The records on all build threads, in fixed chunks whose bounds merge in
  // chunk order: the root boxes do not depend on the thread count.
  HugePageVector<BuildPrim> prims(n);
  const std::size_t chunks = (n + kRecordChunk - 1) / kRecordChunk;
  std::vector<Aabb> chunk_bounds(chunks), chunk_centroids(chunks);
  parallel_for(n, opts.threads, kRecordChunk, [&](std::size_t begin, std::size_t end, unsigned) {
    Aabb rb, rc;
    for (std::size_t i = begin; i < end; ++i) {
      const Aabb b = bounds_at(i);
      const glm::vec3 c = centroid_at(i, b);
      prims[i] = BuildPrim{c, static_cast<std::uint32_t>(i), b};
      rb.extend(b);
      rc.extend(c);
    }
    chunk_bounds[begin / kRecordChunk] = rb;
    chunk_centroids[begin / kRecordChunk] = rc;
  });
  Aabb root_bounds, root_centroids;
  for (std::size_t k = 0; k < chunks; ++k) {
    root_bounds.extend(chunk_bounds[k]);
    root_centroids.extend(chunk_centroids[k]);
  }
  return build_bvh_records(prims, root_bounds, root_centroids, opts, progress);
}

/// build_bvh_from with each primitive's centroid taken as the centre of its
/// box (what Embree's builders bin on): class Bvh builds from these. For a
/// triangle the box centre bins better than the vertex average: dragon SAH
/// 50.11 against 51.70 at the default buckets (docs/bvh.md).
template <class BoundsAt>
BvhTopology build_bvh_from_boxes(std::size_t n, const BoundsAt& bounds_at, const BvhOptions& opts,
                                 const ProgressCallback& progress) {
  return build_bvh_from(
      n, bounds_at, [](std::size_t, const Aabb& box) { return box.center(); }, opts, progress);
}

/// Geometric and centroid bounds of a range.
void range_bounds(std::span<const BuildPrim> prims, Aabb& bounds, Aabb& centroid_bounds);

/// Sort key of a centroid coordinate: NaN maps to +inf so that comparisons stay
/// a strict weak order even on garbage input (std::sort requires one).
inline float sort_key(float c) {
  return c == c ? c : std::numeric_limits<float>::infinity();
}

/// Strict "a before b" on `axis`, ties broken by id: every primitive has a unique position.
inline bool centroid_less(const BuildPrim& a, const BuildPrim& b, int axis) {
  const float ka = sort_key(a.centroid[axis]), kb = sort_key(b.centroid[axis]);
  return ka < kb || (ka == kb && a.id < b.id);
}

/// The SAH termination rule: a leaf when it is no more expensive than the
/// best split and the node is small enough to be allowed as a leaf.
/// `split_area_count` = A_L·N_L + A_R·N_R (half areas). Compared with both
/// sides multiplied by A_N so that a zero-area node needs no division.
inline bool sah_prefers_leaf(const SplitParams& p, std::size_t n, float node_half_area, float split_area_count) {
  if (n > static_cast<std::size_t>(p.leaf_size_cap)) return false;
  const float leaf = p.cost_intersect * static_cast<float>(n) * node_half_area;
  const float split = p.cost_traversal * node_half_area + p.cost_intersect * split_area_count;
  return leaf <= split;
}

/// Better candidate: cheaper, or equally cheap and more balanced (keeps
/// zero-area and all-equal-cost cases from degenerating into chains).
/// Start a search with best_cost = +inf and best_left = 0 so that the first
/// candidate wins even when its cost overflowed to +inf.
inline bool better_split(float cost, std::size_t n_left, std::size_t n, float best_cost, std::size_t best_left) {
  if (!(cost <= best_cost)) return false;  // worse, or NaN
  if (cost < best_cost) return true;
  const auto imbalance = [n](std::size_t l) { return l * 2 > n ? l * 2 - n : n - l * 2; };
  return imbalance(n_left) < imbalance(best_left);
}

}  // namespace accelviz::bvh_detail
