// K-D tree construction: SAH over the exact event sweep (Wald & Havran 2006),
// with perfect splits (triangles clipped to the node box, Havran 2000). On
// several threads the top of the tree is built here and its subtrees as jobs
// on all threads, then laid end to end as one thread writes them: the same
// tree and figures on any thread count (docs/structures.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/accel/kdtree/kdtree.h"
#include "core/accel/kdtree/spatial_build.h"
#include "core/geometry/tri_box_overlap.h"
#include "core/util/parallel.h"
#include "core/util/timing.h"

namespace accelviz {

void validate(const KdTreeOptions& o) {
  const auto positive = [](float v) { return std::isfinite(v) && v > 0.0f; };
  if (!positive(o.cost_traversal))
    throw std::invalid_argument("kdtree: cost_traversal must be finite and > 0, got " + std::to_string(o.cost_traversal));
  if (!positive(o.cost_intersect))
    throw std::invalid_argument("kdtree: cost_intersect must be finite and > 0, got " + std::to_string(o.cost_intersect));
  if (o.max_depth < 0 || o.max_depth > kKdMaxDepth)
    throw std::invalid_argument("kdtree: max_depth must be 0 (auto) .. " + std::to_string(kKdMaxDepth) + ", got " +
                                std::to_string(o.max_depth));
  if (o.max_leaf_size < 1)
    throw std::invalid_argument("kdtree: max_leaf_size must be >= 1, got " + std::to_string(o.max_leaf_size));
  if (!(o.empty_bonus >= 0.0f && o.empty_bonus < 1.0f))
    throw std::invalid_argument("kdtree: empty_bonus must lie in [0, 1), got " + std::to_string(o.empty_bonus));
}

namespace {

// Event types in the order Wald & Havran sort them at equal positions: ends
// before planars before starts, so that the sweep sees, at a plane p, the
// primitives ending at p leave the right side before those starting at p
// join the left side.
enum EventType : std::uint32_t { kEnd = 0, kPlanar = 1, kStart = 2 };

// Float to an unsigned key with the same order (positive floats: set the
// sign bit; negative: flip all bits), so events sort as plain integers.
std::uint32_t orderable(float f) {
  const std::uint32_t u = std::bit_cast<std::uint32_t>(f + 0.0f);  // -0 -> +0
  return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}
float from_orderable(std::uint32_t k) {
  return std::bit_cast<float>((k & 0x80000000u) ? (k & 0x7FFFFFFFu) : ~k);
}

struct Split {
  int axis = -1;
  float pos = 0.0f;
  bool planar_left = true;
  double cost = std::numeric_limits<double>::infinity();
};

/// A subtree the top of a parallel build leaves to a thread of its own: its
/// primitives and their clipped bounds, its cell, depth and share of the
/// progress, the node of the top array that stands for it, and (once built)
/// its nodes and references, numbered from 0.
struct KdJob {
  std::vector<std::uint32_t> prims;
  std::vector<Aabb> cb;
  Aabb box;
  int depth = 0;
  double weight = 0.0;
  std::uint32_t top_node = 0;
  std::vector<KdNode> nodes;
  std::vector<std::uint32_t> refs;
};

class KdBuilder {
 public:
  KdBuilder(std::span<const Triangle> tris, const KdTreeOptions& opts, int max_depth, spatial::BuildProgress& progress,
            std::vector<KdNode>& nodes, std::vector<std::uint32_t>& refs)
      : tris_(tris), opts_(opts), max_depth_(max_depth), progress_(progress), nodes_(nodes), refs_(refs) {}

  /// The top of a parallel build: a node of at most `job_max` primitives
  /// (below the root) becomes one node in `nodes` standing for a job, listed
  /// in `jobs`, to be built on its own; the top's split searches run their
  /// three axes on up to `threads` threads.
  void defer_subtrees(std::size_t job_max, unsigned threads, std::vector<KdJob>& jobs) {
    job_max_ = job_max;
    threads_ = threads;
    jobs_ = &jobs;
  }

  // Builds the subtree for `prims` (with their bounds clipped to `box`) at
  // the end of the node array. Consumes `prims` and `cb`.
  void build(std::vector<std::uint32_t>& prims, std::vector<Aabb>& cb, const Aabb& box, int depth, double weight) {
    const std::size_t n = prims.size();
    const std::uint32_t index = static_cast<std::uint32_t>(nodes_.size());
    if (nodes_.size() >= (1u << 30)) throw std::length_error("kdtree: more than 2^30 nodes");
    nodes_.emplace_back();
    if (jobs_ && depth > 0 && n <= job_max_) {
      jobs_->push_back({std::move(prims), std::move(cb), box, depth, weight, index, {}, {}});
      return;
    }
    const double area = box.half_area();

    Split split;
    if (n > static_cast<std::size_t>(opts_.max_leaf_size) && depth < max_depth_ && area > 0.0)
      split = find_split(cb, box, area);
    if (split.axis < 0 || split.cost >= static_cast<double>(opts_.cost_intersect) * static_cast<double>(n)) {
      make_leaf(index, prims, weight);
      return;
    }

    // Classify against the chosen plane (Wald & Havran §4.3): a primitive
    // goes left if its clipped extent reaches below the plane, right if it
    // reaches above, both if it straddles; one lying in the plane goes to
    // the side the SAH chose for planars.
    const int a = split.axis;
    const float p = split.pos;
    Aabb left_box = box, right_box = box;
    left_box.hi[a] = p;
    right_box.lo[a] = p;
    std::vector<std::uint32_t> lp, rp;
    std::vector<Aabb> lcb, rcb;
    for (std::size_t i = 0; i < n; ++i) {
      const float lo = cb[i].lo[a], hi = cb[i].hi[a];
      bool go_left = lo < p, go_right = hi > p;
      if (lo == p && hi == p) (split.planar_left ? go_left : go_right) = true;
      if (go_left) {
        lp.push_back(prims[i]);
        lcb.push_back(child_bounds(prims[i], cb[i], left_box));
      }
      if (go_right) {
        rp.push_back(prims[i]);
        rcb.push_back(child_bounds(prims[i], cb[i], right_box));
      }
    }
    std::vector<std::uint32_t>().swap(prims);
    std::vector<Aabb>().swap(cb);

    const double total = static_cast<double>(lp.size() + rp.size());
    const double wl = total > 0.0 ? weight * static_cast<double>(lp.size()) / total : weight * 0.5;
    build(lp, lcb, left_box, depth + 1, wl);
    const std::uint32_t above = static_cast<std::uint32_t>(nodes_.size());
    nodes_[index] = KdNode::inner(a, p, above);
    build(rp, rcb, right_box, depth + 1, weight - wl);
  }

 private:
  Aabb child_bounds(std::uint32_t prim, const Aabb& parent_cb, const Aabb& child_box) const {
    // The part inside the parent lies wholly on this side of the plane: it
    // is also the part inside the child (most primitives; no clipping).
    if (child_box.contains(parent_cb)) return parent_cb;
    if (opts_.perfect_splits) {
      const Aabb c = clipped_triangle_bounds(tris_[prim], child_box);
      if (!c.is_empty()) return c;
    }
    // Clamped bounds (or clipping that rounded to nothing at a tangency):
    // the parent's clipped bounds cut to the child, never smaller than the
    // truth.
    return Aabb::intersection(parent_cb, child_box);
  }

  void make_leaf(std::uint32_t index, const std::vector<std::uint32_t>& prims, double weight) {
    if (prims.size() >= (1u << 30)) throw std::length_error("kdtree: leaf with more than 2^30 primitives");
    // Leaves address their references with 32 bits; split triangles are referenced on both sides.
    if (refs_.size() + prims.size() > 0xFFFFFFFFull) throw std::length_error("kdtree: more than 2^32-1 references");
    nodes_[index] = KdNode::leaf(static_cast<std::uint32_t>(refs_.size()), static_cast<std::uint32_t>(prims.size()));
    refs_.insert(refs_.end(), prims.begin(), prims.end());
    progress_.add(weight);
  }

  // The exact SAH sweep over the primitives' clipped-bound events, per axis;
  // the first best plane in axis order, then position order.
  Split find_split(const std::vector<Aabb>& cb, const Aabb& box, double area) {
    Split best[3];
    const auto axis_split = [&](int a, std::vector<std::uint64_t>& events) {
      if (box.hi[a] > box.lo[a]) best[a] = find_split_on(a, cb, box, area, events);  // else flat: no plane inside
    };
    if (threads_ > 1 && cb.size() >= kParallelSplitMin) {
      // The top of a parallel build: one axis per thread, each with its own events.
      std::vector<std::uint64_t> events[3];
      parallel_for(3, std::min(threads_, 3u), 1, [&](std::size_t b, std::size_t e, unsigned) {
        for (std::size_t a = b; a < e; ++a) axis_split(static_cast<int>(a), events[a]);
      });
    } else {
      for (int a = 0; a < 3; ++a) axis_split(a, events_);
    }
    Split out;
    for (const Split& s : best)
      if (s.cost < out.cost) out = s;
    return out;
  }

  Split find_split_on(int a, const std::vector<Aabb>& cb, const Aabb& box, double area,
                      std::vector<std::uint64_t>& events) const {
    Split best;
    const std::size_t n = cb.size();
    const double ct = opts_.cost_traversal, ci = opts_.cost_intersect;
    const double bonus = 1.0 - static_cast<double>(opts_.empty_bonus);
    const double inv_area = 1.0 / area;
    const glm::dvec3 ext = glm::dvec3(box.hi) - glm::dvec3(box.lo);
    events.clear();
    for (const Aabb& b : cb) {
      const float lo = b.lo[a], hi = b.hi[a];
      if (lo == hi) {
        events.push_back((std::uint64_t{orderable(lo)} << 2) | kPlanar);
      } else {
        events.push_back((std::uint64_t{orderable(lo)} << 2) | kStart);
        events.push_back((std::uint64_t{orderable(hi)} << 2) | kEnd);
      }
    }
    std::sort(events.begin(), events.end());

    // Areas of the children as linear functions of the plane position.
    const int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
    const double cross = ext[b1] * ext[b2];  // the face the plane cuts
    const double perim = ext[b1] + ext[b2];
    std::size_t nl = 0, nr = n;
    for (std::size_t i = 0; i < events.size();) {
      const std::uint64_t key = events[i] >> 2;
      std::size_t pe = 0, pp = 0, ps = 0;
      while (i < events.size() && (events[i] >> 2) == key && (events[i] & 3u) == kEnd) ++pe, ++i;
      while (i < events.size() && (events[i] >> 2) == key && (events[i] & 3u) == kPlanar) ++pp, ++i;
      while (i < events.size() && (events[i] >> 2) == key && (events[i] & 3u) == kStart) ++ps, ++i;
      nr -= pe + pp;
      const float p = from_orderable(static_cast<std::uint32_t>(key));
      // Only planes strictly inside the node: a plane on the boundary would
      // make an empty flat child and, with the empty bonus, never stop.
      if (p > box.lo[a] && p < box.hi[a]) {
        const double dl = static_cast<double>(p) - box.lo[a];
        const double dr = static_cast<double>(box.hi[a]) - p;
        const double pl = (cross + dl * perim) * inv_area;  // half-area ratios
        const double pr = (cross + dr * perim) * inv_area;
        const auto sah = [&](std::size_t l, std::size_t r) {
          const double c = ct + ci * (pl * static_cast<double>(l) + pr * static_cast<double>(r));
          return (l == 0 || r == 0) ? c * bonus : c;
        };
        const double cost_l = sah(nl + pp, nr);  // planars to the left
        const double cost_r = sah(nl, nr + pp);  // planars to the right
        const bool left = cost_l <= cost_r;
        const double c = left ? cost_l : cost_r;
        if (c < best.cost) best = {a, p, left, c};
      }
      nl += ps + pp;
    }
    return best;
  }

  /// Nodes with fewer primitives search their three axes on one thread.
  static constexpr std::size_t kParallelSplitMin = 4096;

  std::span<const Triangle> tris_;
  const KdTreeOptions& opts_;
  int max_depth_;
  spatial::BuildProgress& progress_;
  std::vector<KdNode>& nodes_;
  std::vector<std::uint32_t>& refs_;
  std::vector<std::uint64_t> events_;  // scratch, reused by every node (used before recursing)
  // The top of a parallel build (defer_subtrees); none in a serial build or a job.
  std::size_t job_max_ = 0;
  unsigned threads_ = 1;
  std::vector<KdJob>* jobs_ = nullptr;
};

/// The final node and reference arrays from the top of a parallel build
/// and its jobs, in the order a serial build writes them (depth first, the
/// below child next to its parent): each job's nodes where its stand-in
/// was, their child indices and leaf offsets moved to their new places.
void assemble(const std::vector<KdNode>& top, const std::vector<std::uint32_t>& top_refs,
              const std::vector<KdJob>& jobs, std::vector<KdNode>& nodes, std::vector<std::uint32_t>& refs) {
  std::vector<std::int32_t> job_at(top.size(), -1);  // the job a top node stands for
  for (std::size_t j = 0; j < jobs.size(); ++j) job_at[jobs[j].top_node] = static_cast<std::int32_t>(j);
  std::vector<std::uint64_t> at(top.size());  // each top node's final index
  std::uint64_t count = 0, ref_count = top_refs.size();
  for (std::size_t i = 0; i < top.size(); ++i) {
    at[i] = count;
    count += job_at[i] >= 0 ? jobs[static_cast<std::size_t>(job_at[i])].nodes.size() : 1;
  }
  for (const KdJob& j : jobs) ref_count += j.refs.size();
  if (count > (1u << 30)) throw std::length_error("kdtree: more than 2^30 nodes");
  if (ref_count > 0xFFFFFFFFull) throw std::length_error("kdtree: more than 2^32-1 references");
  nodes.clear();
  refs.clear();
  nodes.reserve(count);
  refs.reserve(ref_count);
  for (std::size_t i = 0; i < top.size(); ++i) {
    const KdNode& n = top[i];
    if (job_at[i] >= 0) {
      const KdJob& j = jobs[static_cast<std::size_t>(job_at[i])];
      const auto base = static_cast<std::uint32_t>(at[i]), ref_base = static_cast<std::uint32_t>(refs.size());
      for (const KdNode& k : j.nodes)
        nodes.push_back(k.is_leaf() ? KdNode::leaf(k.prim_offset() + ref_base, k.prim_count())
                                    : KdNode::inner(k.axis(), k.split(), k.above_child() + base));
      refs.insert(refs.end(), j.refs.begin(), j.refs.end());
    } else if (n.is_leaf()) {
      nodes.push_back(KdNode::leaf(static_cast<std::uint32_t>(refs.size()), n.prim_count()));
      refs.insert(refs.end(), top_refs.begin() + n.prim_offset(), top_refs.begin() + n.prim_offset() + n.prim_count());
    } else {
      nodes.push_back(KdNode::inner(n.axis(), n.split(), static_cast<std::uint32_t>(at[n.above_child()])));
    }
  }
}

/// The tree's SAH sum, leaves and depths, over the finished node array in
/// its order (depth first), so the same tree gives the same figures
/// whatever the threads that built it.
spatial::TreeTally tally_tree(const std::vector<KdNode>& nodes, const Aabb& root, const KdTreeOptions& opts) {
  spatial::TreeTally tally;
  struct Cell {
    Aabb box;
    int depth;
  };
  std::vector<Cell> stack;
  if (!nodes.empty()) stack.push_back({root, 0});
  for (const KdNode& n : nodes) {  // in array order, which is the order of the walk
    const Cell c = stack.back();
    stack.pop_back();
    if (n.is_leaf()) {
      tally.leaf(n.prim_count(), c.depth,
                 static_cast<double>(opts.cost_intersect) * static_cast<double>(n.prim_count()) * c.box.half_area());
      continue;
    }
    tally.inner(static_cast<double>(opts.cost_traversal) * c.box.half_area());
    Aabb below = c.box, above = c.box;
    below.hi[n.axis()] = n.split();
    above.lo[n.axis()] = n.split();
    stack.push_back({above, c.depth + 1});
    stack.push_back({below, c.depth + 1});  // the next node
  }
  return tally;
}

}  // namespace

KdTree::KdTree(std::span<const Triangle> triangles, const KdTreeOptions& opts, const ProgressCallback& progress)
    : tris_(triangles.begin(), triangles.end()), opts_(opts) {
  validate(opts_);
  const auto t_start = std::chrono::steady_clock::now();
  if (tris_.size() >= (1ull << 32) - 1) throw std::length_error("kdtree: more than 2^32-2 triangles");

  std::vector<std::uint32_t> prims;
  std::vector<Aabb> cb;
  prims.reserve(tris_.size());
  cb.reserve(tris_.size());
  for (std::size_t i = 0; i < tris_.size(); ++i) {
    if (!is_finite_triangle(tris_[i])) continue;
    prims.push_back(static_cast<std::uint32_t>(i));
    cb.push_back(tris_[i].bounds());
    bounds_.extend(cb.back());
  }
  const std::size_t n = prims.size();
  const int max_depth =
      opts_.max_depth > 0
          ? opts_.max_depth
          : std::min(kKdMaxDepth,
                     static_cast<int>(std::lround(8.0 + 1.3 * std::log2(static_cast<double>(std::max<std::size_t>(n, 1))))));

  spatial::BuildProgress shared_progress(progress);
  const unsigned threads = resolve_threads(opts_.threads);
  if (threads <= 1 || n < spatial::kParallelBuildMin) {
    KdBuilder builder(tris_, opts_, max_depth, shared_progress, nodes_, prim_refs_);
    if (n > 0) builder.build(prims, cb, bounds_, 0, 1.0);
  } else {
    // The top of the tree on this thread (its split searches on up to three),
    // then its subtrees of at most n / (4 · threads) primitives, the largest
    // first, on all threads; the same arrays as the serial build.
    std::vector<KdNode> top;
    std::vector<std::uint32_t> top_refs;
    std::vector<KdJob> jobs;
    KdBuilder builder(tris_, opts_, max_depth, shared_progress, top, top_refs);
    builder.defer_subtrees(std::max<std::size_t>(n / (4 * std::size_t{threads}), 1), threads, jobs);
    builder.build(prims, cb, bounds_, 0, 1.0);
    spatial::build_jobs(jobs, threads, [&](KdJob& j) {
      KdBuilder sub(tris_, opts_, max_depth, shared_progress, j.nodes, j.refs);
      sub.build(j.prims, j.cb, j.box, j.depth, j.weight);
    });
    assemble(top, top_refs, jobs, nodes_, prim_refs_);
  }
  nodes_.shrink_to_fit();
  prim_refs_.shrink_to_fit();
  const spatial::TreeTally tally = tally_tree(nodes_, bounds_, opts_);

  stats_.build_ms = ms_since(t_start);
  // The triangles it copies count, as the BVH's triangle blocks and Embree's buffers do.
  stats_.memory_bytes =
      nodes_.size() * sizeof(KdNode) + prim_refs_.size() * sizeof(std::uint32_t) + tris_.size() * sizeof(Triangle);
  stats_.extra["memory_triangles"] = static_cast<double>(tris_.size() * sizeof(Triangle));
  tally.fill(stats_, nodes_.size(), prim_refs_.size(), n, bounds_.half_area(),
             static_cast<double>(opts_.cost_intersect) * static_cast<double>(n));
  stats_.extra["max_depth_limit"] = max_depth;
  if (progress && !progress(1.0)) throw BuildCancelled();
}

}  // namespace accelviz
