// Octree construction: top-down, each cell's triangles filtered into the
// eight octants by the exact triangle-box overlap test.
#include "core/accel/kdtree/spatial_build.h"
#include "core/accel/kdtree/spatial_traversal.h"
#include "core/accel/octree/octree.h"
#include "core/geometry/tri_box_overlap.h"
#include "core/util/timing.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

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

class OctreeBuilder {
 public:
  OctreeBuilder(std::span<const Triangle> tris, const OctreeOptions& opts, float pad, const ProgressCallback& progress,
                std::vector<OctreeNode>& nodes, std::vector<std::uint32_t>& refs)
      : tris_(tris), opts_(opts), pad_(pad), progress_(progress), nodes_(nodes), refs_(refs) {}

  // Fills nodes_[node] (already allocated) for the cell `box` holding `prims`.
  void build(std::uint32_t node, std::vector<std::uint32_t>& prims, const Aabb& box, int depth, double weight) {
    const std::size_t n = prims.size();
    if (static_cast<int>(n) <= opts_.max_leaf_size || depth >= opts_.max_depth) {
      make_leaf(node, prims, box, depth, weight);
      return;
    }
    // 1. Distribute the triangles over the octants they overlap (padded
    //    boxes, see spatial::kCellPaddingRel).
    std::array<std::vector<std::uint32_t>, 8> child;
    for (int o = 0; o < 8; ++o) {
      const Aabb cb = padded_box(Octree::child_box(box, o), pad_);
      for (std::uint32_t id : prims)
        if (boxes_overlap(bounds_of(id), cb) && triangle_box_overlap(tris_[id], cb)) child[o].push_back(id);
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
      make_leaf(node, prims, box, depth, weight);
      return;
    }
    std::vector<std::uint32_t>().swap(prims);

    // 3. Eight children together at the end of the array.
    if (nodes_.size() + 8 >= OctreeNode::kInner) throw std::length_error("octree: more than 2^32-1 nodes");
    const std::uint32_t base = static_cast<std::uint32_t>(nodes_.size());
    nodes_.resize(nodes_.size() + 8);
    nodes_[node] = {base, OctreeNode::kInner};
    tally_.inner(box.half_area());
    std::size_t total = 0;
    for (const auto& c : child) total += c.size();
    for (int o = 0; o < 8; ++o) {
      const double w = total ? weight * static_cast<double>(child[o].size()) / static_cast<double>(total) : 0.0;
      build(base + o, child[o], Octree::child_box(box, o), depth + 1, w);
    }
  }

  spatial::TreeTally tally_;

 private:
  Aabb bounds_of(std::uint32_t id) const { return tris_[id].bounds(); }

  void make_leaf(std::uint32_t node, const std::vector<std::uint32_t>& prims, const Aabb& box, int depth,
                 double weight) {
    if (refs_.size() + prims.size() >= 0xFFFFFFFFull) throw std::length_error("octree: more than 2^32-1 references");
    nodes_[node] = {static_cast<std::uint32_t>(refs_.size()), static_cast<std::uint32_t>(prims.size())};
    refs_.insert(refs_.end(), prims.begin(), prims.end());
    tally_.leaf(prims.size(), depth, static_cast<double>(prims.size()) * box.half_area());
    progress_.add(weight);
  }

  std::span<const Triangle> tris_;
  const OctreeOptions& opts_;
  float pad_;
  spatial::BuildProgress progress_;
  std::vector<OctreeNode>& nodes_;
  std::vector<std::uint32_t>& refs_;
};

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
  OctreeBuilder builder(tris_, opts_, pad, progress, nodes_, prim_refs_);
  if (n > 0) {
    nodes_.emplace_back();
    builder.build(0, prims, root_, 0, 1.0);
  }
  nodes_.shrink_to_fit();
  prim_refs_.shrink_to_fit();

  stats_.build_ms = ms_since(t_start);
  // The triangles it copies count, as the BVH's triangle blocks and Embree's buffers do.
  stats_.memory_bytes =
      nodes_.size() * sizeof(OctreeNode) + prim_refs_.size() * sizeof(std::uint32_t) + tris_.size() * sizeof(Triangle);
  stats_.extra["memory_triangles"] = static_cast<double>(tris_.size() * sizeof(Triangle));
  builder.tally_.fill(stats_, nodes_.size(), prim_refs_.size(), n, root_.half_area(), static_cast<double>(n));
  if (progress && !progress(1.0)) throw BuildCancelled();
}

}  // namespace accelviz
