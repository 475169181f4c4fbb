// Octree construction: top-down, each cell's triangles filtered into the
// eight octants by the exact triangle-box overlap test. On several threads
// the top of the tree is built here and its cells as jobs on all threads,
// then laid out as one thread writes them (docs/structures.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/accel/kdtree/spatial_build.h"
#include "core/accel/kdtree/spatial_traversal.h"
#include "core/accel/octree/octree.h"
#include "core/geometry/tri_box_overlap.h"
#include "core/util/parallel.h"
#include "core/util/timing.h"

namespace accelviz {

void validate(const OctreeOptions& o) {
  if (o.max_depth < 0 || o.max_depth > kOctreeMaxDepth)
    throw std::invalid_argument("octree: max_depth must lie in 0.." + std::to_string(kOctreeMaxDepth) + ", got " +
                                std::to_string(o.max_depth));
  if (o.max_leaf_size < 1)
    throw std::invalid_argument("octree: max_leaf_size must be >= 1, got " + std::to_string(o.max_leaf_size));
}

namespace {

bool boxes_overlap(const Aabb& a, const Aabb& b) {
  return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y && a.lo.z <= b.hi.z &&
         b.lo.z <= a.hi.z;
}

/// A cell the top of a parallel build leaves to a thread of its own: its
/// triangles, box, depth and share of the progress; where the one-thread
/// build would have written its subtree (its node in the top array, and the
/// sizes of the top's node and reference arrays when it was left); and,
/// once built, its nodes (its own cell at 0) and references, numbered from 0.
struct OctJob {
  std::vector<std::uint32_t> prims;
  Aabb box;
  int depth = 0;
  double weight = 0.0;
  std::uint32_t top_node = 0;
  std::size_t top_nodes_at = 0, top_refs_at = 0;
  std::vector<OctreeNode> nodes;
  std::vector<std::uint32_t> refs;
};

class OctreeBuilder {
 public:
  OctreeBuilder(std::span<const Triangle> tris, const OctreeOptions& opts, float pad, spatial::BuildProgress& progress,
                std::vector<OctreeNode>& nodes, std::vector<std::uint32_t>& refs)
      : tris_(tris), opts_(opts), pad_(pad), progress_(progress), nodes_(nodes), refs_(refs) {}

  /// The top of a parallel build: a cell below the root with at most
  /// `job_max` triangles is left as a job in `jobs`; the top's cells sort
  /// their triangles into octants on up to `threads`.
  void defer_subtrees(std::size_t job_max, unsigned threads, std::vector<OctJob>& jobs) {
    job_max_ = job_max;
    threads_ = threads;
    jobs_ = &jobs;
  }

  // Fills nodes_[node] (already allocated) for the cell `box` holding `prims`.
  void build(std::uint32_t node, std::vector<std::uint32_t>& prims, const Aabb& box, int depth, double weight) {
    const std::size_t n = prims.size();
    if (jobs_ && depth > 0 && n <= job_max_) {
      jobs_->push_back({std::move(prims), box, depth, weight, node, nodes_.size(), refs_.size(), {}, {}});
      return;
    }
    if (static_cast<int>(n) <= opts_.max_leaf_size || depth >= opts_.max_depth) {
      make_leaf(node, prims, weight);
      return;
    }
    // 1. Distribute the triangles over the octants they overlap (padded
    //    boxes, see spatial::kCellPaddingRel).
    //    (On the top of a parallel build, the octants on all threads.)
    std::array<std::vector<std::uint32_t>, 8> child;
    const auto fill = [&](int o) {
      const Aabb cb = padded_box(Octree::child_box(box, o), pad_);
      for (std::uint32_t id : prims)
        if (boxes_overlap(bounds_of(id), cb) && triangle_box_overlap(tris_[id], cb)) child[o].push_back(id);
    };
    if (threads_ > 1 && n >= kParallelOctantsMin) {
      parallel_for(8, threads_, 1, [&](std::size_t b, std::size_t e, unsigned) {
        for (std::size_t o = b; o < e; ++o) fill(static_cast<int>(o));
      });
    } else {
      for (int o = 0; o < 8; ++o) fill(o);
    }
    // 2. Stop when splitting separates nothing: every non-empty octant would
    //    hold all the triangles again (duplicates, triangles crossing at one
    //    place), and more than one octant does. (A single non-empty octant
    //    still shrinks the cell around a cluster, so that case goes on, up to
    //    max_depth.) Without this rule coincident triangles would subdivide
    //    along their whole surface down to max_depth.
    //    And, with cost_termination, stop where the surface area heuristic
    //    (MacDonald & Booth 1990) with C_trav = C_isect = 1 finds the split
    //    no cheaper than the leaf: each octant has a quarter of the cell's
    //    area, so splitting costs 1 + Σ n_child / 4 against n. Triangles that
    //    cross each other (all sharing a point, say) put two or more
    //    triangles in every cell along their intersections at every depth;
    //    without a cost rule such cells split down to max_depth.
    int nonempty = 0;
    bool progress_made = false;
    std::size_t refs = 0;
    for (const auto& c : child) {
      refs += c.size();
      if (c.empty()) continue;
      ++nonempty;
      if (c.size() < n) progress_made = true;
    }
    const bool too_costly = opts_.cost_termination && 1.0 + 0.25 * static_cast<double>(refs) >= static_cast<double>(n);
    if (nonempty == 0 || (!progress_made && nonempty > 1) || too_costly) {
      make_leaf(node, prims, weight);
      return;
    }
    std::vector<std::uint32_t>().swap(prims);

    // 3. Eight children together at the end of the array.
    if (nodes_.size() + 8 >= OctreeNode::kInner) throw std::length_error("octree: more than 2^32-1 nodes");
    const std::uint32_t base = static_cast<std::uint32_t>(nodes_.size());
    nodes_.resize(nodes_.size() + 8);
    nodes_[node] = {base, OctreeNode::kInner};
    std::size_t total = 0;
    for (const auto& c : child) total += c.size();
    for (int o = 0; o < 8; ++o) {
      const double w = total ? weight * static_cast<double>(child[o].size()) / static_cast<double>(total) : 0.0;
      build(base + o, child[o], Octree::child_box(box, o), depth + 1, w);
    }
  }

 private:
  Aabb bounds_of(std::uint32_t id) const { return tris_[id].bounds(); }

  /// Cells with fewer triangles sort them into octants on one thread.
  static constexpr std::size_t kParallelOctantsMin = 4096;

  void make_leaf(std::uint32_t node, const std::vector<std::uint32_t>& prims, double weight) {
    if (refs_.size() + prims.size() >= 0xFFFFFFFFull) throw std::length_error("octree: more than 2^32-1 references");
    nodes_[node] = {static_cast<std::uint32_t>(refs_.size()), static_cast<std::uint32_t>(prims.size())};
    refs_.insert(refs_.end(), prims.begin(), prims.end());
    progress_.add(weight);
  }

  std::span<const Triangle> tris_;
  const OctreeOptions& opts_;
  float pad_;
  spatial::BuildProgress& progress_;
  std::vector<OctreeNode>& nodes_;
  std::vector<std::uint32_t>& refs_;
  // The top of a parallel build (defer_subtrees); none in a serial build or a job.
  std::size_t job_max_ = 0;
  unsigned threads_ = 1;
  std::vector<OctJob>* jobs_ = nullptr;
};

/// The final node and reference arrays from the top of a parallel build and
/// its jobs (in the order they were left), as the one-thread build writes
/// them: each job's nodes below its own cell where the top's node array
/// stood when it was left, its references likewise, and every child index
/// and leaf offset moved to the new places.
void assemble(const std::vector<OctreeNode>& top, const std::vector<std::uint32_t>& top_refs,
              const std::vector<OctJob>& jobs, std::vector<OctreeNode>& nodes, std::vector<std::uint32_t>& refs) {
  // Nodes and references of the jobs before job j (jobs are left in the
  // order of the walk, so their places in the top's arrays never decrease).
  std::vector<std::uint64_t> nodes_before(jobs.size() + 1, 0), refs_before(jobs.size() + 1, 0);
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    nodes_before[j + 1] = nodes_before[j] + (jobs[j].nodes.size() - 1);  // its own cell is in the top
    refs_before[j + 1] = refs_before[j] + jobs[j].refs.size();
  }
  const std::uint64_t node_count = top.size() + nodes_before.back();
  const std::uint64_t ref_count = top_refs.size() + refs_before.back();
  if (node_count >= OctreeNode::kInner) throw std::length_error("octree: more than 2^32-1 nodes");
  if (ref_count >= 0xFFFFFFFFull) throw std::length_error("octree: more than 2^32-1 references");
  // Each top node's final index: its own plus the job nodes placed before it.
  std::vector<std::uint64_t> at(top.size());
  std::vector<bool> is_job(top.size(), false);
  for (const OctJob& j : jobs) is_job[j.top_node] = true;
  std::size_t k = 0;
  for (std::size_t i = 0; i < top.size(); ++i) {
    while (k < jobs.size() && jobs[k].top_nodes_at <= i) ++k;
    at[i] = i + nodes_before[k];
  }
  nodes.assign(node_count, OctreeNode{});
  for (std::size_t i = 0; i < top.size(); ++i) {
    if (is_job[i]) continue;  // written with its job below
    const OctreeNode& n = top[i];
    if (!n.is_leaf()) {
      nodes[at[i]] = {static_cast<std::uint32_t>(at[n.index]), OctreeNode::kInner};
      continue;
    }
    // A leaf of the top holds more triangles than a job (a smaller cell is
    // a job), so none is empty: the jobs left before it are those whose
    // references start at or before its own.
    const auto before = std::upper_bound(jobs.begin(), jobs.end(), n.index,
                                         [](std::uint32_t r, const OctJob& j) { return r < j.top_refs_at; });
    nodes[at[i]] = {static_cast<std::uint32_t>(n.index + refs_before[static_cast<std::size_t>(before - jobs.begin())]),
                    n.count};
  }
  refs.clear();
  refs.reserve(ref_count);
  std::size_t top_ref = 0;
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    const OctJob& job = jobs[j];
    const std::uint64_t start = job.top_nodes_at + nodes_before[j];  // its node 1
    const std::uint64_t ref_base = job.top_refs_at + refs_before[j];
    const auto place = [&](std::uint32_t local) { return local == 0 ? at[job.top_node] : start + local - 1; };
    for (std::size_t l = 0; l < job.nodes.size(); ++l) {
      const OctreeNode& n = job.nodes[l];
      nodes[place(static_cast<std::uint32_t>(l))] =
          n.is_leaf() ? OctreeNode{static_cast<std::uint32_t>(n.index + ref_base), n.count}
                      : OctreeNode{static_cast<std::uint32_t>(place(n.index)), OctreeNode::kInner};
    }
    refs.insert(refs.end(), top_refs.begin() + static_cast<std::ptrdiff_t>(top_ref),
                top_refs.begin() + static_cast<std::ptrdiff_t>(job.top_refs_at));
    top_ref = job.top_refs_at;
    refs.insert(refs.end(), job.refs.begin(), job.refs.end());
  }
  refs.insert(refs.end(), top_refs.begin() + static_cast<std::ptrdiff_t>(top_ref), top_refs.end());
}

/// The tree's SAH sum, leaves and depths in the order the one-thread build
/// makes its nodes (depth first, octants in order), over the finished array:
/// the same figures whatever the threads that built it.
spatial::TreeTally tally_tree(const std::vector<OctreeNode>& nodes, const Aabb& root) {
  spatial::TreeTally tally;
  struct Cell {
    std::uint32_t node;
    Aabb box;
    int depth;
  };
  std::vector<Cell> stack;
  if (!nodes.empty()) stack.push_back({0, root, 0});
  while (!stack.empty()) {
    const Cell c = stack.back();
    stack.pop_back();
    const OctreeNode& n = nodes[c.node];
    if (n.is_leaf()) {
      tally.leaf(n.count, c.depth, static_cast<double>(n.count) * c.box.half_area());
      continue;
    }
    tally.inner(c.box.half_area());
    for (int o = 7; o >= 0; --o)  // octant 0 on top: visited first
      stack.push_back({n.index + static_cast<std::uint32_t>(o), Octree::child_box(c.box, o), c.depth + 1});
  }
  return tally;
}

}  // namespace

Octree::Octree(std::span<const Triangle> triangles, const OctreeOptions& opts, const ProgressCallback& progress)
    : tris_(triangles.begin(), triangles.end()), opts_(opts) {
  validate(opts_);
  const auto t_start = std::chrono::steady_clock::now();
  if (tris_.size() >= 0xFFFFFFFFull) throw std::length_error("octree: more than 2^32-2 triangles");

  std::vector<std::uint32_t> prims;
  prims.reserve(tris_.size());
  Aabb bounds;
  for (std::size_t i = 0; i < tris_.size(); ++i) {
    if (!is_finite_triangle(tris_[i])) continue;
    prims.push_back(static_cast<std::uint32_t>(i));
    bounds.extend(tris_[i].bounds());
  }
  const std::size_t n = prims.size();

  float pad = 0.0f;
  if (n > 0) {
    // The root is a cube anchored at the bounds' lower corner (so a flat
    // scene lies on the cube's faces, not on the first mid-plane where every
    // triangle would be referenced twice), with a side a hair above the
    // largest extent; a scene of zero extent gets a tiny positive cube.
    const glm::vec3 ext = bounds.extent();
    const glm::vec3 mag = glm::max(glm::abs(bounds.lo), glm::abs(bounds.hi));
    float side = std::max({ext.x, ext.y, ext.z}) * (1.0f + 1e-6f);
    side = std::max(side, 1e-6f * std::max({mag.x, mag.y, mag.z, 1e-30f}));
    root_.lo = bounds.lo;
    for (int a = 0; a < 3; ++a) {
      root_.hi[a] = root_.lo[a] + side;
      while (root_.hi[a] < bounds.hi[a]) root_.hi[a] = std::nextafter(root_.hi[a], kInfinity);
    }
    pad = spatial::cell_padding(root_.lo, root_.hi);
  }
  spatial::BuildProgress shared_progress(progress);
  const unsigned threads = resolve_threads(opts_.threads);
  if (threads <= 1 || n < spatial::kParallelBuildMin) {
    OctreeBuilder builder(tris_, opts_, pad, shared_progress, nodes_, prim_refs_);
    if (n > 0) {
      nodes_.emplace_back();
      builder.build(0, prims, root_, 0, 1.0);
    }
  } else {
    // The top of the tree on this thread, its cells of at most
    // n / (4 · threads) triangles as jobs, the largest first, on all threads;
    // then the arrays the one-thread build writes (K-D tree alike).
    std::vector<OctreeNode> top(1);
    std::vector<std::uint32_t> top_refs;
    std::vector<OctJob> jobs;
    OctreeBuilder builder(tris_, opts_, pad, shared_progress, top, top_refs);
    builder.defer_subtrees(std::max<std::size_t>(n / (4 * std::size_t{threads}), 1), threads, jobs);
    builder.build(0, prims, root_, 0, 1.0);
    spatial::build_jobs(jobs, threads, [&](OctJob& j) {
      j.nodes.emplace_back();
      OctreeBuilder sub(tris_, opts_, pad, shared_progress, j.nodes, j.refs);
      sub.build(0, j.prims, j.box, j.depth, j.weight);
    });
    assemble(top, top_refs, jobs, nodes_, prim_refs_);
  }
  nodes_.shrink_to_fit();
  prim_refs_.shrink_to_fit();
  const spatial::TreeTally tally = tally_tree(nodes_, root_);

  stats_.build_ms = ms_since(t_start);
  // The triangles it copies count, as the BVH's triangle blocks and Embree's buffers do.
  stats_.memory_bytes =
      nodes_.size() * sizeof(OctreeNode) + prim_refs_.size() * sizeof(std::uint32_t) + tris_.size() * sizeof(Triangle);
  stats_.extra["memory_triangles"] = static_cast<double>(tris_.size() * sizeof(Triangle));
  tally.fill(stats_, nodes_.size(), prim_refs_.size(), n, root_.half_area(), static_cast<double>(n));
  if (progress && !progress(1.0)) throw BuildCancelled();
}

}  // namespace accelviz
