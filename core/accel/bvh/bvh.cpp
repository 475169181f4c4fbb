// BVH over triangles: construction wrapper, traversals and refit.
//
// Two traversals, each a function template instantiated per closest vs any
// hit, ordered vs fixed child order and triangle test, so that every choice
// is made once per ray:
//  - traverse: the binary node array, also instantiated with Collect = true
//    for statistics and traces (Collect = false carries no counters at all);
//  - traverse_wide (bvh_wide_traverse.inl): the 8-wide (AVX2, where the CPU
//    has it) or 4-wide (SSE) copy (bvh_wide.h), the default fast path.
#include "core/accel/bvh/bvh.h"

#include <bit>
#include <chrono>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "core/accel/bvh/bvh_build.h"
#include "core/accel/bvh/bvh_slab.h"
#include "core/accel/bvh/bvh_tri8.h"
#include "core/accel/bvh/bvh_triangle.h"
#include "core/accel/bvh/bvh_wide.h"
#include "core/analysis/epo.h"
#include "core/analysis/sah.h"
#include "core/util/parallel.h"
#include "core/util/prefetch.h"
#include "core/util/timing.h"

namespace accelviz {
namespace {

/// BvhOptions::wide_merge_blocks = -1: the fast path's leaf slots take binary
/// subtrees whose leaves fill at most kWideMergeBlocks triangle blocks when
/// the blocks take kWideMergeMinBytes or more. Fewer wide nodes to fetch per
/// ray pays where the walk waits on memory (dragon: 46 MB of blocks); on a
/// mesh whose tree stays in cache (bunny: 3.7 MB) the extra triangle tests
/// made shadow rays slower (docs/performance.md, 2026-12-02).
constexpr int kWideMergeBlocks = 2;
constexpr std::size_t kWideMergeMinBytes = std::size_t{16} << 20;

/// The triangle-block fill prefetches the triangles of the leaf this many
/// leaves ahead of the one it copies.
constexpr std::size_t kGatherAhead = 4;

/// Collapses `nodes` into `wide`, leaf slots pointing at the triangle blocks; returns its bytes.
template <int W>
std::size_t make_wide(std::span<const BvhNode> nodes, HugePageVector<std::uint32_t>& leaf_order,
                      std::span<std::uint32_t> leaf_block, int merge_blocks, bvh_detail::WideBvhT<W>& wide,
                      BuildStats& stats, unsigned threads) {
  bvh_detail::collapse_to_wide(nodes, wide, merge_blocks, threads);
  stats.extra["wide_merge_blocks"] = merge_blocks;
  // The triangle blocks in the order the fast path's leaf slots are laid out
  // (a slot's binary leaves one after the other).
  bvh_detail::lay_out_leaf_blocks(wide, nodes, leaf_order, leaf_block, threads);
  const std::size_t node_bytes = wide.nodes.size() * sizeof(bvh_detail::WideNodeT<W>);
  const std::size_t source_bytes = wide.source.size() * sizeof(std::uint32_t);
  stats.extra["wide_nodes"] = static_cast<double>(wide.nodes.size());
  stats.extra["memory_wide_nodes"] = static_cast<double>(node_bytes);
  stats.extra["memory_wide_source"] = static_cast<double>(source_bytes);
  return node_bytes + source_bytes;
}

}  // namespace

Bvh::Bvh(std::span<const Triangle> triangles, const BvhOptions& opts, const ProgressCallback& progress) : opts_(opts) {
  const auto t0 = std::chrono::steady_clock::now();
  validate(opts_);
  // The builder's records straight from the triangles (no bounds/centroid
  // arrays to fill and copy).
  BvhTopology topo = bvh_detail::build_bvh_from_boxes(
      triangles.size(), [&](std::size_t i) { return triangles[i].bounds(); }, opts_, progress);
  nodes_ = std::move(topo.nodes);
  prim_indices_ = std::move(topo.prim_indices);
  stats_ = std::move(topo.stats);
  // Where the build's time goes (the binary tree, the wide tree collapsed
  // from it, the triangle blocks), for the build's thread scaling.
  const double topology_ms = ms_since(t0);
  // The triangles as blocks of four, each leaf from a new block (its
  // triangles contiguous, in leaf order), the blocks in the order the wide
  // tree's leaf slots are laid out (else in node order): first the leaves in
  // that order and their first blocks, then the blocks filled on all build
  // threads (each leaf its own range; the pages are first touched there).
  std::size_t block_count = 0;
  for (const BvhNode& n : nodes_) block_count += bvh_detail::tri4_block_count(n.count);
  leaf_block_.assign(nodes_.size(), 0);
  HugePageVector<std::uint32_t> leaf_order;
  std::size_t wide_bytes = 0;
  if (opts_.wide_traversal && !nodes_.empty()) {
    const int merge = opts_.wide_merge_blocks >= 0                                        ? opts_.wide_merge_blocks
                      : block_count * sizeof(bvh_detail::TriBlock4) >= kWideMergeMinBytes ? kWideMergeBlocks
                                                                                          : 0;
    const int width = opts_.wide_width == 0                                   ? (bvh_detail::cpu_has_wide8() ? 8 : 4)
                      : opts_.wide_width == 8 && !bvh_detail::cpu_has_wide8() ? 4
                                                                              : opts_.wide_width;
    if (width == 8) {
      wide8_ = std::make_unique<bvh_detail::WideBvh8>();
      wide_bytes = make_wide(nodes_, leaf_order, leaf_block_, merge, *wide8_, stats_, opts_.threads);
    } else {
      wide_ = std::make_unique<bvh_detail::WideBvh>();
      wide_bytes = make_wide(nodes_, leaf_order, leaf_block_, merge, *wide_, stats_, opts_.threads);
    }
    stats_.extra["wide_width"] = width;
  } else {
    // A binary tree of n nodes has (n + 1) / 2 leaves: every entry is written.
    leaf_order.resize((nodes_.size() + 1) / 2);
    std::uint32_t next_block = 0;
    std::size_t at = 0;
    for (std::uint32_t i = 0; i < nodes_.size(); ++i)
      if (nodes_[i].count > 0)
        next_block = bvh_detail::place_leaf_blocks(nodes_, i, next_block, leaf_order[at++], leaf_block_);
  }
  const double wide_ms = ms_since(t0) - topology_ms;
  blocks_.resize(block_count);  // default-initialised: not written here (HugePageAllocator)
  parallel_for(leaf_order.size(), opts_.threads, 4096, [&](std::size_t begin, std::size_t end, unsigned) {
    const auto tri_at = [&](std::uint32_t k) -> const Triangle& { return triangles[prim_indices_[k]]; };
    for (std::size_t j = begin; j < end; ++j) {
      // The triangles are read in leaf order, i.e. at random in the scene's
      // array: their fetches are started a few leaves ahead.
      if (j + kGatherAhead < end) {
        const BvhNode& ahead = nodes_[leaf_order[j + kGatherAhead]];
        for (std::uint32_t k = ahead.index; k < ahead.index + ahead.count; ++k)
          prefetch_object(&triangles[prim_indices_[k]]);
      }
      const BvhNode& leaf = nodes_[leaf_order[j]];
      bvh_detail::fill_tri4_blocks(tri_at, leaf.index, leaf.count, blocks_.data() + leaf_block_[leaf_order[j]]);
    }
  });
  const std::size_t node_bytes = nodes_.size() * sizeof(BvhNode);
  const std::size_t index_bytes = prim_indices_.size() * sizeof(std::uint32_t);
  const std::size_t block_bytes = blocks_.size() * sizeof(bvh_detail::TriBlock4);
  const std::size_t leaf_block_bytes = leaf_block_.size() * sizeof(std::uint32_t);
  stats_.extra["memory_binary_nodes"] = static_cast<double>(node_bytes);
  stats_.extra["memory_prim_indices"] = static_cast<double>(index_bytes);
  stats_.extra["memory_tri_blocks"] = static_cast<double>(block_bytes);
  stats_.extra["memory_leaf_block_index"] = static_cast<double>(leaf_block_bytes);
  stats_.memory_bytes = node_bytes + index_bytes + block_bytes + leaf_block_bytes + wide_bytes;
  stats_.build_ms = ms_since(t0);
  stats_.extra["build_topology_ms"] = topology_ms;
  stats_.extra["build_wide_ms"] = wide_ms;
  stats_.extra["build_blocks_ms"] = stats_.build_ms - topology_ms - wide_ms;
  update_epo(triangles, progress);  // sah_cost: the builder's, over these nodes
}

Bvh::~Bvh() = default;
Bvh::Bvh(const Bvh& o)
    : Accelerator(o),
      nodes_(o.nodes_),
      prim_indices_(o.prim_indices_),
      blocks_(o.blocks_),
      leaf_block_(o.leaf_block_),
      wide_(o.wide_ ? std::make_unique<bvh_detail::WideBvh>(*o.wide_) : nullptr),
      wide8_(o.wide8_ ? std::make_unique<bvh_detail::WideBvh8>(*o.wide8_) : nullptr),
      opts_(o.opts_),
      stats_(o.stats_) {}
Bvh::Bvh(Bvh&&) noexcept = default;
Bvh& Bvh::operator=(Bvh&&) noexcept = default;

void Bvh::update_epo(std::span<const Triangle> triangles, const ProgressCallback& progress) {
  if (opts_.compute_epo) {
    // Not part of build_ms: it is a measurement of the tree, not a step of
    // making it; its own time is reported beside it. The build's progress
    // stays at 1 meanwhile; the callback is asked only whether to go on.
    const auto t0 = std::chrono::steady_clock::now();
    const ProgressCallback go_on = progress ? ProgressCallback([&](double) { return progress(1.0); }) : nullptr;
    stats_.extra["epo"] =
        bvh_epo(nodes_, prim_indices_, triangles, opts_.cost_traversal, opts_.cost_intersect, opts_.threads, go_on);
    stats_.extra["epo_ms"] = ms_since(t0);
  }
}

void Bvh::refit(std::span<const Triangle> moved) {
  if (moved.size() != prim_indices_.size())
    throw std::invalid_argument("Bvh::refit: expected " + std::to_string(prim_indices_.size()) + " triangles, got " +
                                std::to_string(moved.size()));
  const auto t0 = std::chrono::steady_clock::now();
  // Children are stored after their parents: one reverse sweep is bottom-up.
  for (std::size_t i = nodes_.size(); i-- > 0;) {
    BvhNode& n = nodes_[i];
    Aabb b;
    if (n.count > 0) {
      for (std::uint32_t k = n.index; k < n.index + n.count; ++k) b.extend(moved[prim_indices_[k]].bounds());
    } else {
      b = Aabb::merge(nodes_[n.index].bounds, nodes_[n.index + 1].bounds);
    }
    n.bounds = b;
  }
  bvh_detail::refit_tri4_blocks([&](std::uint32_t k) -> const Triangle& { return moved[prim_indices_[k]]; }, blocks_);
  if (wide_) bvh_detail::refit_wide(*wide_, nodes_);
  if (wide8_) bvh_detail::refit_wide(*wide8_, nodes_);
  stats_.extra["refit_ms"] = ms_since(t0);
  stats_.sah_cost = bvh_sah_cost(nodes_, opts_.cost_traversal, opts_.cost_intersect);  // the boxes moved
  update_epo(moved);
}

std::vector<Triangle> Bvh::copy_leaf_triangles() const {
  return copy_leaf_triangles(0, static_cast<std::uint32_t>(prim_indices_.size()));
}

std::vector<Triangle> Bvh::copy_leaf_triangles(std::uint32_t first, std::uint32_t last) const {
  last = std::min(last, static_cast<std::uint32_t>(prim_indices_.size()));
  if (first >= last) return {};
  std::vector<Triangle> out(last - first);
  for (const bvh_detail::TriBlock4& b : blocks_)
    for (std::uint32_t l = 0; l < 4; ++l)
      if (b.pos[l] != bvh_detail::kTri4Empty && b.pos[l] >= first && b.pos[l] < last)
        out[b.pos[l] - first] = bvh_detail::tri4_triangle(b, l);
  return out;
}

namespace {

using bvh_detail::slab_test;
using bvh_detail::slab_test_pair;
using bvh_detail::SlabRay;

struct BvhView {
  const BvhNode* nodes;
  const bvh_detail::TriBlock4* blocks;  ///< the triangle blocks (bvh_tri4.h)
  const std::uint32_t* leaf_block;      ///< per binary node: a leaf's first block
  const std::uint32_t* prim_ids;
  std::size_t node_count;
};

/// Statistics and trace sink of the Collect path; the fast path never touches it.
struct Collector {
  RayStats* stats;
  VisitTrace* trace;
  bool back_to_front = false;  ///< QueryOptions::back_to_front (Collect path only)
  bool xray = false;           ///< QueryOptions::xray (Collect path only)

  void entered(std::uint32_t node, float t0, float t1) const {
    ++stats->nodes_visited;
    if (trace) trace->steps.push_back({VisitStep::Kind::node_entered, node, t0, t1});
  }
  void missed(std::uint32_t node, float t0, float t1) const {
    ++stats->nodes_missed;
    if (trace) trace->steps.push_back({VisitStep::Kind::node_missed, node, t0, t1});
  }
  void culled(std::uint32_t node, float t0, float t1) const {
    ++stats->nodes_culled;
    if (trace) trace->steps.push_back({VisitStep::Kind::node_culled, node, t0, t1});
  }
  void prim(std::uint32_t id, bool hit, float t) const {
    if (trace)
      trace->steps.push_back(
          {hit ? VisitStep::Kind::prim_hit : VisitStep::Kind::prim_miss, id, hit ? t : kInfinity, kInfinity});
  }
};

using bvh_detail::InlineWatertightRay;
using bvh_detail::test_triangle;

/// A hit at (t, u, v) on lane l of triangle block `blk`, found in leaf order,
/// into `best` (best.prim: the lane's leaf position). Any hit records it and
/// returns true (the walk is over); closest hit records it with the
/// triangle's normal when it is nearer than best (first found wins ties, as
/// in BruteForce) and lowers `closest`, and returns false. Every walk's leaf
/// test ends here: the binary walk (traverse), the heatmap's counted walk and
/// the wide walk (LeafRay). The fields go to best one by one: a Hit assembled
/// and copied stalled, the copy's 16-byte loads waiting for the narrower
/// stores that had just filled it (6 % of the kitchen's single-ray any-hit
/// walk); and the lane's Triangle is gathered only for the normal.
template <bool AnyHit>
[[gnu::always_inline]] inline bool take_hit(const bvh_detail::TriBlock4& blk, int l, float t, float u, float v,
                                            float& closest, Hit& best) {
  if constexpr (!AnyHit) {
    if (!(t < best.t)) return false;
    best.ng = triangle_normal(bvh_detail::tri4_triangle(blk, static_cast<std::uint32_t>(l)));
    closest = t;
  }
  best.t = t;
  best.u = u;
  best.v = v;
  best.prim = blk.pos[l];
  return AnyHit;
}

/// Leaves of the subtree at `node` whose boxes (and their ancestors' boxes
/// below `node`) the ray crosses in [tmin, tmax]: what a full traversal of
/// that subtree would enter. `node` itself was already tested when pushed.
std::uint32_t leaves_crossed(const BvhView& bvh, const SlabRay& sr, float tmin, float tmax, std::uint32_t node) {
  std::uint32_t stack[kBvhMaxDepth + 1];
  unsigned sp = 0;
  std::uint32_t leaves = 0;
  stack[sp++] = node;
  while (sp > 0) {
    const BvhNode& n = bvh.nodes[stack[--sp]];
    if (n.count > 0) {
      ++leaves;
      continue;
    }
    float t0, t1;
    for (std::uint32_t ch = n.index; ch < n.index + 2; ++ch)
      if (slab_test(bvh.nodes[ch], sr, tmin, tmax, t0, t1)) stack[sp++] = ch;
  }
  return leaves;
}

/// Stack-based traversal (children tested at the parent; the far child is
/// pushed with its entry distance and skipped on pop when a closer hit has
/// been found since).
///  - AnyHit: returns at the first hit in [tmin, tmax]; no culling.
///  - Ordered: the child with the smaller entry distance first; otherwise
///    left then right.
///  - Collect: count into *c.stats and record into c.trace. Boxes are then
///    tested against [tmin, ray.tmax] so that a box beyond the closest hit is
///    told apart ("culled") from a box the ray misses; the fast path tests
///    against [tmin, closest] directly. Both take the same decisions.
/// Returns the hit with `prim` = leaf-order position (the caller maps it).
template <bool AnyHit, bool Ordered, bool Collect, TriangleTest Test>
Hit traverse(const BvhView& bvh, const Ray& ray, const Collector& c) {
  Hit best;
  if (bvh.node_count == 0) return best;
  const SlabRay sr(ray);
  const float tmin = ray.tmin;
  float closest = ray.tmax;

  struct Entry {
    std::uint32_t node;
    float t_entry;
  };
  Entry stack[kBvhMaxDepth];
  float stack_exit[Collect ? kBvhMaxDepth : 1];  // only the trace needs exit distances of pushed nodes
  unsigned sp = 0;

  float r0, r1;
  if constexpr (Collect) ++c.stats->box_tests;
  if (!slab_test(bvh.nodes[0], sr, tmin, closest, r0, r1)) {
    if constexpr (Collect) c.missed(0, r0, r1);
    return best;
  }
  if constexpr (Collect) c.entered(0, r0, r1);
  // Set up after the root test: most rays of a typical view miss the scene box.
  const InlineWatertightRay wr = Test == TriangleTest::watertight ? InlineWatertightRay(ray) : InlineWatertightRay();

  std::uint32_t node = 0;
  for (;;) {
    const BvhNode& n = bvh.nodes[node];
    if (n.count == 0) {
      const std::uint32_t i0 = n.index, i1 = n.index + 1;
      // Collect tests against the segment's end and classifies culling itself.
      const float box_tmax = Collect && !AnyHit ? ray.tmax : closest;
      float te[2], tx[2];
      const int mask = slab_test_pair(bvh.nodes + i0, sr, tmin, box_tmax, te, tx);
      bool h0 = (mask & 1) != 0, h1 = (mask & 2) != 0;
      const float a0 = te[0], a1 = tx[0], b0 = te[1], b1 = tx[1];
      if constexpr (Collect) {
        c.stats->box_tests += 2;
        const float cull_t = c.xray ? ray.tmax : closest;
        if (!h0)
          c.missed(i0, a0, a1);
        else if (a0 > cull_t) {
          c.culled(i0, a0, a1);
          h0 = false;
        }
        if (!h1)
          c.missed(i1, b0, b1);
        else if (b0 > cull_t) {
          c.culled(i1, b0, b1);
          h1 = false;
        }
      }
      if constexpr (!Collect) {
        // Fast path with one data-dependent branch (any child hit?) instead
        // of two: the far child is written to the stack unconditionally and
        // kept only when both were hit; which child comes first is a select.
        // Those outcomes are coin flips per node, and mispredicted branches
        // were a quarter of the traversal time.
        if (mask != 0) {
          const bool both = mask == 3;
          const bool second_first = Ordered && b0 < a0;
          stack[sp] = {i1 - (second_first ? 1u : 0u), second_first ? a0 : b0};
          sp += both ? 1u : 0u;
          node = both ? i0 + (second_first ? 1u : 0u) : i0 + static_cast<std::uint32_t>(mask >> 1);
          continue;
        }
      } else if (h0 && h1) {
        // Which child is nearer is a coin flip per node: selects, not a swap.
        const bool second_first = Ordered && (c.back_to_front ? a0 < b0 : b0 < a0);
        const std::uint32_t near = i0 + (second_first ? 1u : 0u);
        const std::uint32_t far = i1 - (second_first ? 1u : 0u);
        stack[sp] = {far, second_first ? a0 : b0};
        if constexpr (Collect) stack_exit[sp] = second_first ? a1 : b1;
        ++sp;
        node = near;
        if constexpr (Collect) {
          if (second_first)
            c.entered(near, b0, b1);
          else
            c.entered(near, a0, a1);
        }
        continue;
      } else if (h0 || h1) {
        node = i0 + (h1 ? 1u : 0u);
        if (h0)
          c.entered(i0, a0, a1);
        else
          c.entered(i1, b0, b1);
        continue;
      }
    } else {
      const bvh_detail::TriBlock4* blk = bvh.blocks + bvh.leaf_block[node];
      for (std::uint32_t j = 0; j < n.count; ++j) {
        const std::uint32_t k = n.index + j;
        const Triangle tri = bvh_detail::tri4_triangle(blk[j >> 2], j & 3);
        Hit h;
        // X-ray: every primitive is tested over the whole segment.
        const float prim_tmax = Collect && !AnyHit && c.xray ? ray.tmax : closest;
        const bool hit = test_triangle<Test>(ray, wr, tri, tmin, prim_tmax, h);
        if constexpr (Collect) {
          ++c.stats->prim_tests;
          c.prim(bvh.prim_ids[k], hit, h.t);
        }
        if constexpr (AnyHit) {
          if (hit) {
            take_hit<true>(blk[j >> 2], static_cast<int>(j & 3), h.t, h.u, h.v, closest, best);
            if constexpr (Collect) {
              // Leaves the early exit never reached: those below the pending stack entries that the ray crosses.
              for (unsigned i = 0; i < sp; ++i)
                c.stats->leaves_skipped += leaves_crossed(bvh, sr, tmin, ray.tmax, stack[i].node);
            }
            return best;
          }
        } else if (hit) {
          take_hit<false>(blk[j >> 2], static_cast<int>(j & 3), h.t, h.u, h.v, closest, best);
        }
      }
    }
    // Pop the next node whose entry still lies before the closest hit.
    for (;;) {
      if (sp == 0) return best;
      --sp;
      const Entry e = stack[sp];
      if (!AnyHit && e.t_entry > closest && !(Collect && c.xray)) {
        if constexpr (Collect) c.culled(e.node, e.t_entry, stack_exit[sp]);
        continue;
      }
      node = e.node;
      if constexpr (Collect) c.entered(e.node, e.t_entry, stack_exit[sp]);
      break;
    }
  }
}

/// The heatmap's walk: closest hit with statistics and no trace over the
/// binary tree (QueryOptions without back_to_front and xray). It takes the
/// decisions of traverse<false, Ordered, true, Test> and gives the same hit
/// and the same RayStats (tests/core/test_bvh_query.cpp compares the two per
/// ray); it only does less to get them:
///  - counters are locals, added once at the end, and two of them are
///    derived: every inner node entered tests both children (box_tests =
///    1 + 2 * inner nodes entered), and every box tested is entered, missed
///    or culled, since a closest-hit walk pops every pending entry;
///  - each child pair is tested once against [tmin, ray.tmax] (missed =
///    not crossed) with the culling (entry beyond the closest hit) a second
///    compare on the same lanes, then the fast path's branch-free push;
///  - watertight leaves test four triangles at a time (bvh_tri4.h: lanes in
///    the leaf's order, accepted against the closest hit in that order, as
///    the scalar loop would), each triangle still counting as one test;
///  - it is a state advanced one node per step(), so that several rays can
///    be walked in turns (walk_counted_batch): deep in a dense mesh
///    neighbouring rays share few nodes and a lone walk mostly waits on
///    memory; each step asks for what the next steps will read (a kept
///    child's child pair, a leaf's first block) before it is needed.
/// Interleaved: a leaf takes two steps, the first only looks its blocks up.
template <bool Ordered, TriangleTest Test, bool Interleaved>
class CountedWalk {
 public:
  /// Starts the walk of `ray` (kept by reference). False: there is nothing
  /// to walk (empty tree, or the ray misses the root box); finish() then
  /// already gives the final result.
  bool start(const BvhView& bvh, const Ray& ray) {
    ray_ = &ray;
    best_ = Hit{};
    closest_ = ray.tmax;
    sp_ = 0;
    visited_ = inner_ = missed_ = prims_ = 0;
    leaf_ready_ = false;
    empty_ = bvh.node_count == 0;
    if (empty_) return false;
    sr_ = SlabRay(ray);
    float r0, r1;
    if (!slab_test(bvh.nodes[0], sr_, ray.tmin, closest_, r0, r1)) {
      missed_ = 1;
      return false;
    }
    visited_ = 1;
    if constexpr (Test == TriangleTest::watertight) {
      wr_ = InlineWatertightRay(ray);
#ifdef ACCELVIZ_BVH_TRI4_SSE2
      tr4_ = bvh_detail::Tri4Ray(wr_);
#endif
    }
    node_ = 0;
    return true;
  }

  /// Walks one node; false when the walk is over.
  [[gnu::always_inline]] bool step(const BvhView& bvh) {
    const Ray& ray = *ray_;
    const float tmin = ray.tmin;
    const BvhNode& n = bvh.nodes[node_];
    if (n.count == 0) {
      const std::uint32_t i0 = n.index;
      float te[2];
      const int bits = slab_test_pair_cull(bvh.nodes + i0, sr_, tmin, ray.tmax, closest_, te);
      const int mask = bits >> 2;
      ++inner_;
      missed_ += 2u - static_cast<std::uint32_t>((bits & 1) + ((bits >> 1) & 1));  // (no popcnt in x86-64 v1)
      // What each kept child leads to: its child pair, or a leaf's entry of
      // leaf_block (a missed or culled child asks for itself, in cache).
      for (std::uint32_t c = 0; c < 2; ++c) {
        const BvhNode& ch = bvh.nodes[i0 + c];
        const void* next = ch.count == 0 ? static_cast<const void*>(bvh.nodes + ch.index)
                                         : static_cast<const void*>(bvh.leaf_block + i0 + c);
        __builtin_prefetch((mask >> c) & 1 ? next : &ch);
      }
      if (mask != 0) {
        const bool both = mask == 3;
        const bool second_first = Ordered && te[1] < te[0];
        stack_[sp_] = {i0 + 1u - (second_first ? 1u : 0u), second_first ? te[0] : te[1]};
        sp_ += both ? 1u : 0u;
        node_ = both ? i0 + (second_first ? 1u : 0u) : i0 + static_cast<std::uint32_t>(mask >> 1);
        ++visited_;
        return true;
      }
    } else {
      if constexpr (Interleaved) {
        if (!leaf_ready_) {
          block_ = bvh.leaf_block[node_];
          const char* b = reinterpret_cast<const char*>(bvh.blocks + block_);
          __builtin_prefetch(b);
          __builtin_prefetch(b + 64);
          __builtin_prefetch(b + sizeof(bvh_detail::TriBlock4) - 1);
          leaf_ready_ = true;
          return true;
        }
        leaf_ready_ = false;
      } else {
        block_ = bvh.leaf_block[node_];
      }
      leaf(bvh, n);
    }
    // Pop the next node whose entry still lies before the closest hit.
    while (sp_ > 0) {
      const Entry e = stack_[--sp_];
      if (e.t_entry > closest_) continue;
      node_ = e.node;
      ++visited_;
      return true;
    }
    return false;
  }

  /// Adds the walk's counters to `stats`; returns the hit (prim = leaf-order position).
  const Hit& finish(RayStats& stats) const {
    if (!empty_) {
      const std::uint32_t boxes = 1 + 2 * inner_;
      stats.nodes_visited += visited_;
      stats.box_tests += boxes;
      stats.nodes_missed += missed_;
      stats.nodes_culled += boxes - visited_ - missed_;
      stats.prim_tests += prims_;
    }
    return best_;
  }

 private:
  struct Entry {
    std::uint32_t node;
    float t_entry;
  };

  [[gnu::always_inline]] void leaf(const BvhView& bvh, const BvhNode& n) {
    const Ray& ray = *ray_;
    const float tmin = ray.tmin;
    prims_ += n.count;
    const bvh_detail::TriBlock4* blk = bvh.blocks + block_;
#ifdef ACCELVIZ_BVH_TRI4_SSE2
    if constexpr (Test == TriangleTest::watertight) {
      for (std::uint32_t left = n.count; left > 0; ++blk) {
        const int valid = left >= 4 ? 0xF : (1 << left) - 1;
        left = left >= 4 ? left - 4 : 0;
        bvh_detail::Tri4Result r;
        bvh_detail::intersect_tri4(*blk, tr4_, tmin, r);
        int lanes = (r.candidate | r.special) & valid;
        while (lanes != 0) {
          const int l = std::countr_zero(static_cast<unsigned>(lanes));
          lanes &= lanes - 1;
          if ((r.special >> l) & 1) {
            Hit h;
            if (intersect_watertight(ray, wr_.wr, bvh_detail::tri4_triangle(*blk, static_cast<std::uint32_t>(l)), tmin,
                                     closest_, h))
              take_hit<false>(*blk, l, h.t, h.u, h.v, closest_, best_);
          } else if (bvh_detail::tri4_accept(r, l, closest_)) {
            take_hit<false>(*blk, l, r.t[l], r.u[l], r.v[l], closest_, best_);
          }
        }
      }
      return;
    }
#endif
    for (std::uint32_t j = 0; j < n.count; ++j) {
      Hit h;
      if (test_triangle<Test>(ray, wr_, bvh_detail::tri4_triangle(blk[j >> 2], j & 3), tmin, closest_, h))
        take_hit<false>(blk[j >> 2], static_cast<int>(j & 3), h.t, h.u, h.v, closest_, best_);
    }
  }

  SlabRay sr_;
  InlineWatertightRay wr_;
#ifdef ACCELVIZ_BVH_TRI4_SSE2
  bvh_detail::Tri4Ray tr4_{InlineWatertightRay()};
#endif
  const Ray* ray_ = nullptr;
  Hit best_;
  float closest_ = 0.0f;
  std::uint32_t node_ = 0, block_ = 0, sp_ = 0;
  std::uint32_t visited_ = 0, inner_ = 0, missed_ = 0, prims_ = 0;
  bool leaf_ready_ = false, empty_ = false;
  Entry stack_[kBvhMaxDepth];
};

template <bool Ordered, TriangleTest Test>
Hit traverse_counted(const BvhView& bvh, const Ray& ray, RayStats& stats) {
  CountedWalk<Ordered, Test, false> w;
  if (w.start(bvh, ray))
    while (w.step(bvh)) {
    }
  return w.finish(stats);
}

/// CountedWalk over `rays`, kWalks of them in turns: each ray's result
/// (prim mapped to scene ids) into hits[i], its counters added to stats[i].
template <bool Ordered, TriangleTest Test>
void walk_counted_batch(const BvhView& bvh, std::span<const Ray> rays, std::span<Hit> hits, std::span<RayStats> stats) {
  constexpr int kWalks = 8;
  CountedWalk<Ordered, Test, true> walk[kWalks];
  std::size_t ray_of[kWalks];
  int active[kWalks];  // the walks in progress: walk[active[0 .. live)]
  std::size_t next = 0;
  const auto finish = [&](int w, std::size_t i) {
    Hit h = walk[w].finish(stats[i]);
    if (h.valid()) h.prim = bvh.prim_ids[h.prim];
    hits[i] = h;
  };
  // Starts rays on walk w until one needs walking; false when none are left.
  const auto refill = [&](int w) {
    while (next < rays.size()) {
      const std::size_t i = next++;
      if (walk[w].start(bvh, rays[i])) {
        ray_of[w] = i;
        return true;
      }
      finish(w, i);
    }
    return false;
  };
  int live = 0;
  for (int w = 0; w < kWalks; ++w)
    if (refill(w)) active[live++] = w;
  while (live > 0) {
    for (int a = 0; a < live;) {
      const int w = active[a];
      if (walk[w].step(bvh)) {
        ++a;
        continue;
      }
      finish(w, ray_of[w]);
      if (refill(w)) {
        ++a;
      } else {
        active[a] = active[--live];
      }
    }
  }
}

#if defined(ACCELVIZ_BVH_WIDE8_AVX2)
#define ACCELVIZ_BVH_WIDE8 1
#endif

/// Eight lanes of the packet walk (bvh_packet_traverse.inl): GCC vectors,
/// two SSE registers each in the 4-wide code, one AVX register in the 8-wide.
static_assert(Accelerator::kPacketWidth == 8);
using PacketF = float __attribute__((vector_size(32)));
using PacketI = std::int32_t __attribute__((vector_size(32)));

/// The 4-wide SSE traversal (bvh_wide_traverse.inl with W = 4) and its packet walk.
namespace wide4 {
constexpr int kWidth = 4;
using WideSlabRayW = bvh_detail::WideSlabRay;
[[gnu::always_inline]] inline int wide_slab_test_w(const bvh_detail::WideNode& n, const WideSlabRayW& r, float tmin,
                                                   float tmax, float* te) {
  return bvh_detail::wide_slab_test(n, r, tmin, tmax, te);
}
/// Bit l: lane l of a comparison result (all ones or zero) is set.
[[gnu::always_inline]] inline int packet_mask(const PacketI& m) {
#ifdef ACCELVIZ_BVH_SLAB_SSE2
  using Half = std::int32_t __attribute__((vector_size(16)));
  const Half lo = __builtin_shufflevector(m, m, 0, 1, 2, 3), hi = __builtin_shufflevector(m, m, 4, 5, 6, 7);
  return _mm_movemask_ps(reinterpret_cast<__m128>(lo)) | (_mm_movemask_ps(reinterpret_cast<__m128>(hi)) << 4);
#else
  int bits = 0;
  for (int l = 0; l < 8; ++l) bits |= (m[l] != 0 ? 1 : 0) << l;
  return bits;
#endif
}
/// A full packet's rays R[0..8) into lanes (the packet walk's set-up).
[[gnu::always_inline]] inline void load_packet(const Ray* R, PacketF org[3], PacketF dir[3], PacketF inv[3],
                                               PacketF& tmin, PacketF& tmax) {
  for (int a = 0; a < 3; ++a) {
    org[a] = PacketF{R[0].origin[a], R[1].origin[a], R[2].origin[a], R[3].origin[a],
                     R[4].origin[a], R[5].origin[a], R[6].origin[a], R[7].origin[a]};
    dir[a] = PacketF{R[0].direction[a], R[1].direction[a], R[2].direction[a], R[3].direction[a],
                     R[4].direction[a], R[5].direction[a], R[6].direction[a], R[7].direction[a]};
    inv[a] = PacketF{R[0].inv_dir[a], R[1].inv_dir[a], R[2].inv_dir[a], R[3].inv_dir[a],
                     R[4].inv_dir[a], R[5].inv_dir[a], R[6].inv_dir[a], R[7].inv_dir[a]};
  }
  tmin = PacketF{R[0].tmin, R[1].tmin, R[2].tmin, R[3].tmin, R[4].tmin, R[5].tmin, R[6].tmin, R[7].tmin};
  tmax = PacketF{R[0].tmax, R[1].tmax, R[2].tmax, R[3].tmax, R[4].tmax, R[5].tmax, R[6].tmax, R[7].tmax};
}
#include "core/accel/bvh/bvh_wide_traverse.inl"
// (after the single-ray walk: the packet walk uses its LeafRay and walk_wide)
#include "core/accel/bvh/bvh_packet_traverse.inl"
}  // namespace wide4

#ifdef ACCELVIZ_BVH_WIDE8
/// The 8-wide traversal: the same source compiled for AVX2 and FMA (every function
/// defined in this region gets the target), called only when the CPU has it.
/// Fused multiply-adds appear only where written as intrinsics (the fast box
/// test): core builds with -ffp-contract=off, so the triangle tests compiled
/// here stay bit for bit the scalar ones.
#pragma GCC push_options
#pragma GCC target("avx2,fma")
namespace wide8 {
constexpr int kWidth = 8;
using WideSlabRayW = bvh_detail::WideSlabRay8;
/// The fast test for the rays it applies to (nearly all), the exact one for
/// the others (WideSlabRay8::fast: a ±0 direction component, a non-finite or
/// huge origin, a negative tmin or tmax). The choice is the same at every
/// node of a ray, so the branch predicts.
[[gnu::always_inline]] inline int wide_slab_test_w(const bvh_detail::WideNode8& n, const WideSlabRayW& r, float tmin,
                                                   float tmax, float* te) {
  if (r.fast) [[likely]]
    return bvh_detail::wide_slab_test8_fast(n, r, tmax, te);  // from the ray's own tmin, as the walk's
  return bvh_detail::wide_slab_test8(n, r, tmin, tmax, te);
}
[[gnu::always_inline]] inline int packet_mask(const PacketI& m) {
  return _mm256_movemask_ps(reinterpret_cast<__m256>(m));
}
/// Four consecutive floats of each ray, starting `at` floats into it, as
/// four vectors (lane l: ray l): one 4x4 transposition per 128-bit half,
/// rays 0-3 in the low half and 4-7 in the high one.
[[gnu::always_inline]] inline void transpose_rays(const Ray* R, int at, __m256 out[4]) {
  __m256 row[4];
  for (int l = 0; l < 4; ++l)
    row[l] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(&R[l].origin.x + at)),
                                  _mm_loadu_ps(&R[l + 4].origin.x + at), 1);
  const __m256 t0 = _mm256_unpacklo_ps(row[0], row[1]), t1 = _mm256_unpacklo_ps(row[2], row[3]);
  const __m256 t2 = _mm256_unpackhi_ps(row[0], row[1]), t3 = _mm256_unpackhi_ps(row[2], row[3]);
  out[0] = _mm256_shuffle_ps(t0, t1, 0x44);
  out[1] = _mm256_shuffle_ps(t0, t1, 0xEE);
  out[2] = _mm256_shuffle_ps(t2, t3, 0x44);
  out[3] = _mm256_shuffle_ps(t2, t3, 0xEE);
}
static_assert(sizeof(Ray) == 44 && offsetof(Ray, tmin) == 12 && offsetof(Ray, direction) == 16 &&
              offsetof(Ray, tmax) == 28 && offsetof(Ray, inv_dir) == 32);
/// A full packet's rays R[0..8) into lanes (the packet walk's set-up): three
/// transpositions of four floats per ray (origin and tmin, direction and
/// tmax, then tmax again and inv_dir: every load stays inside its ray)
/// instead of eleven vectors gathered lane by lane (4 % of the kitchen's
/// primary any-hit packets' instructions).
[[gnu::always_inline]] inline void load_packet(const Ray* R, PacketF org[3], PacketF dir[3], PacketF inv[3],
                                               PacketF& tmin, PacketF& tmax) {
  __m256 v[4];
  transpose_rays(R, 0, v);
  for (int a = 0; a < 3; ++a) org[a] = reinterpret_cast<PacketF>(v[a]);
  tmin = reinterpret_cast<PacketF>(v[3]);
  transpose_rays(R, 4, v);
  for (int a = 0; a < 3; ++a) dir[a] = reinterpret_cast<PacketF>(v[a]);
  tmax = reinterpret_cast<PacketF>(v[3]);
  transpose_rays(R, 7, v);
  for (int a = 0; a < 3; ++a) inv[a] = reinterpret_cast<PacketF>(v[a + 1]);
}
#include "core/accel/bvh/bvh_wide_traverse.inl"
// (after the single-ray walk: the packet walk uses its LeafRay and walk_wide)
#include "core/accel/bvh/bvh_packet_traverse.inl"
}  // namespace wide8
#pragma GCC pop_options
#endif

/// Runs walk.template operator()<Ordered, Test>() for the query's ordering
/// and triangle test: each choice is made once per query, not per node.
template <class Walk>
decltype(auto) with_query_choices(const QueryOptions& qo, Walk&& walk) {
  const bool wt = qo.triangle_test == TriangleTest::watertight;
  if (qo.ordered)
    return wt ? walk.template operator()<true, TriangleTest::watertight>()
              : walk.template operator()<true, TriangleTest::moller_trumbore>();
  return wt ? walk.template operator()<false, TriangleTest::watertight>()
            : walk.template operator()<false, TriangleTest::moller_trumbore>();
}

/// The single-ray closest-hit walk of the 4-wide copy for the query options.
Hit dispatch_wide(const bvh_detail::WideBvh& wide, const BvhView& v, const Ray& ray, const QueryOptions& qo) {
  return with_query_choices(
      qo, [&]<bool Ordered, TriangleTest Test>() { return wide4::traverse_wide<Ordered, Test>(wide, v, ray); });
}

/// The single-ray closest-hit walk of the 8-wide copy for the query options.
Hit dispatch_wide8([[maybe_unused]] const bvh_detail::WideBvh8& wide, [[maybe_unused]] const BvhView& v,
                   [[maybe_unused]] const Ray& ray, [[maybe_unused]] const QueryOptions& qo) {
#ifdef ACCELVIZ_BVH_WIDE8
  return with_query_choices(
      qo, [&]<bool Ordered, TriangleTest Test>() { return wide8::traverse_wide<Ordered, Test>(wide, v, ray); });
#else
  return Hit{};    // never built without AVX2 support (Bvh checks cpu_has_wide8)
#endif
}

/// The single-ray any-hit walk of the W-wide copy for the query's triangle
/// test (any hit ignores the ordering).
template <class WideBvhW>
bool dispatch_occluded(const WideBvhW& wide, const BvhView& v, const Ray& ray, const QueryOptions& qo) {
  const bool wt = qo.triangle_test == TriangleTest::watertight;
  if constexpr (std::is_same_v<WideBvhW, bvh_detail::WideBvh>) {
    return wt ? wide4::occluded_wide<TriangleTest::watertight>(wide, v, ray)
              : wide4::occluded_wide<TriangleTest::moller_trumbore>(wide, v, ray);
  } else {
#ifdef ACCELVIZ_BVH_WIDE8
    return wt ? wide8::occluded_wide<TriangleTest::watertight>(wide, v, ray)
              : wide8::occluded_wide<TriangleTest::moller_trumbore>(wide, v, ray);
#else
    return false;  // never built without AVX2 support (Bvh checks cpu_has_wide8)
#endif
  }
}

/// The packet walk (4-wide SSE) for the query options.
template <bool AnyHit>
void dispatch_packets(const bvh_detail::WideBvh& wide, const BvhView& v, std::span<const Ray> rays, Hit* out,
                      const QueryOptions& qo) {
  with_query_choices(qo, [&]<bool Ordered, TriangleTest Test>() {
    wide4::traverse_packets<AnyHit, Ordered, Test>(wide, v, rays, out);
  });
}

/// The packet walk (8-wide AVX2) for the query options.
template <bool AnyHit>
void dispatch_packets8([[maybe_unused]] const bvh_detail::WideBvh8& wide, [[maybe_unused]] const BvhView& v,
                       [[maybe_unused]] std::span<const Ray> rays, [[maybe_unused]] Hit* out,
                       [[maybe_unused]] const QueryOptions& qo) {
#ifdef ACCELVIZ_BVH_WIDE8
  with_query_choices(qo, [&]<bool Ordered, TriangleTest Test>() {
    wide8::traverse_packets<AnyHit, Ordered, Test>(wide, v, rays, out);
  });
#endif  // never built without AVX2 support (Bvh checks cpu_has_wide8)
}

template <bool AnyHit, bool Collect>
Hit dispatch(const BvhView& v, const Ray& ray, const QueryOptions& qo, const Collector& c) {
  return with_query_choices(
      qo, [&]<bool Ordered, TriangleTest Test>() { return traverse<AnyHit, Ordered, Collect, Test>(v, ray, c); });
}

/// Bvh::closest_hit's walks with statistics or a trace, out of line: inlined,
/// their locals made every query's stack frame about 2 KiB and its prologue
/// save six registers.
[[gnu::noinline]] Hit closest_hit_collected(const BvhView& v, const Ray& ray, const QueryOptions& qo, RayStats* stats,
                                            VisitTrace* trace) {
  Hit h;
  if (stats != nullptr && trace == nullptr && !qo.back_to_front && !qo.xray) {
    const bool wt = qo.triangle_test == TriangleTest::watertight;
    if (qo.ordered)
      h = wt ? traverse_counted<true, TriangleTest::watertight>(v, ray, *stats)
             : traverse_counted<true, TriangleTest::moller_trumbore>(v, ray, *stats);
    else
      h = wt ? traverse_counted<false, TriangleTest::watertight>(v, ray, *stats)
             : traverse_counted<false, TriangleTest::moller_trumbore>(v, ray, *stats);
  } else {
    RayStats local;
    h = dispatch<false, true>(v, ray, qo, Collector{stats ? stats : &local, trace, qo.back_to_front, qo.xray});
  }
  return h;
}

/// Bvh::any_hit's walk with statistics or back-to-front order, out of line
/// (as closest_hit_collected).
[[gnu::noinline]] bool any_hit_collected(const BvhView& v, const Ray& ray, const QueryOptions& qo, RayStats* stats) {
  RayStats local;
  return dispatch<true, true>(v, ray, qo, Collector{stats ? stats : &local, nullptr, qo.back_to_front, false}).valid();
}

/// The binary walk without statistics (no wide copy), out of line likewise.
template <bool AnyHit>
[[gnu::noinline]] Hit binary_fast(const BvhView& v, const Ray& ray, const QueryOptions& qo) {
  return dispatch<AnyHit, false>(v, ray, qo, Collector{nullptr, nullptr});
}

}  // namespace

Hit Bvh::closest_hit(const Ray& ray, const QueryOptions& qo, RayStats* stats, VisitTrace* trace) const {
  const BvhView v{nodes_.data(), blocks_.data(), leaf_block_.data(), prim_indices_.data(), nodes_.size()};
  Hit h;
  if (stats == nullptr && trace == nullptr && !qo.back_to_front && !qo.xray) [[likely]]
    h = wide8_  ? dispatch_wide8(*wide8_, v, ray, qo)
        : wide_ ? dispatch_wide(*wide_, v, ray, qo)
                : binary_fast<false>(v, ray, qo);
  else
    h = closest_hit_collected(v, ray, qo, stats, trace);
  if (h.valid()) h.prim = prim_indices_[h.prim];  // the traversals set ng
  return h;
}

void Bvh::closest_hits_span(std::span<const Ray> rays, std::span<Hit> hits, const QueryOptions& qo,
                            std::span<RayStats> stats) const {
  if (stats.empty() || qo.back_to_front || qo.xray) {
    Accelerator::closest_hits_span(rays, hits, qo, stats);
    return;
  }
  const BvhView v{nodes_.data(), blocks_.data(), leaf_block_.data(), prim_indices_.data(), nodes_.size()};
  const bool wt = qo.triangle_test == TriangleTest::watertight;
  if (qo.ordered)
    wt ? walk_counted_batch<true, TriangleTest::watertight>(v, rays, hits, stats)
       : walk_counted_batch<true, TriangleTest::moller_trumbore>(v, rays, hits, stats);
  else
    wt ? walk_counted_batch<false, TriangleTest::watertight>(v, rays, hits, stats)
       : walk_counted_batch<false, TriangleTest::moller_trumbore>(v, rays, hits, stats);
}

void Bvh::closest_packets_span(std::span<const Ray> rays, std::span<Hit> hits, const QueryOptions& qo) const {
  if (!has_packets()) {
    Accelerator::closest_packets_span(rays, hits, qo);
    return;
  }
  const BvhView v{nodes_.data(), blocks_.data(), leaf_block_.data(), prim_indices_.data(), nodes_.size()};
  if (wide8_)
    dispatch_packets8<false>(*wide8_, v, rays, hits.data(), qo);
  else
    dispatch_packets<false>(*wide_, v, rays, hits.data(), qo);
  for (Hit& h : hits)
    if (h.valid()) h.prim = prim_indices_[h.prim];
}

void Bvh::any_packets_span(std::span<const Ray> rays, std::span<std::uint8_t> occluded, const QueryOptions& qo) const {
  if (!has_packets()) {
    Accelerator::any_packets_span(rays, occluded, qo);
    return;
  }
  const BvhView v{nodes_.data(), blocks_.data(), leaf_block_.data(), prim_indices_.data(), nodes_.size()};
  // In blocks of 64 rays: eight packets' results at a time on the stack.
  Hit h[64];
  for (std::size_t b = 0; b < rays.size(); b += 64) {
    const std::span<const Ray> part = rays.subspan(b, std::min<std::size_t>(64, rays.size() - b));
    if (wide8_)
      dispatch_packets8<true>(*wide8_, v, part, h, qo);
    else
      dispatch_packets<true>(*wide_, v, part, h, qo);
    for (std::size_t i = 0; i < part.size(); ++i) occluded[b + i] = h[i].valid() ? 1 : 0;
  }
}

bool Bvh::any_hit(const Ray& ray, const QueryOptions& qo, RayStats* stats) const {
  const BvhView v{nodes_.data(), blocks_.data(), leaf_block_.data(), prim_indices_.data(), nodes_.size()};
  if (stats == nullptr && !qo.back_to_front) [[likely]]
    return wide8_  ? dispatch_occluded(*wide8_, v, ray, qo)
           : wide_ ? dispatch_occluded(*wide_, v, ray, qo)
                   : binary_fast<true>(v, ray, qo).valid();
  return any_hit_collected(v, ray, qo, stats);
}

}  // namespace accelviz
