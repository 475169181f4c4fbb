#include "core/analysis/epo.h"

#include <algorithm>
#include <atomic>
#include <glm/glm.hpp>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "core/util/parallel.h"

namespace accelviz {

double clipped_triangle_area(const Triangle& tri, const Aabb& box) {
  if (box.is_empty()) return 0.0;
  const Aabb tb = tri.bounds();
  // A convex polygon clipped by six half-spaces has at most 3 + 6 vertices.
  glm::dvec3 poly[9], next[9];
  int count = 3;
  poly[0] = tri.v0;
  poly[1] = tri.v1;
  poly[2] = tri.v2;
  for (int plane = 0; plane < 6 && count > 0; ++plane) {
    const int axis = plane % 3;
    const bool upper = plane >= 3;
    const double bound = upper ? box.hi[axis] : box.lo[axis];
    // The clipped polygon stays inside the triangle's box: a plane that box
    // does not cross cuts nothing (the common case for nodes near the triangle).
    if (upper ? tb.hi[axis] <= box.hi[axis] : tb.lo[axis] >= box.lo[axis]) continue;
    if (upper ? tb.lo[axis] > box.hi[axis] : tb.hi[axis] < box.lo[axis]) return 0.0;
    // Signed distance inside (>= 0 keeps the vertex).
    const auto inside = [&](const glm::dvec3& p) { return upper ? bound - p[axis] : p[axis] - bound; };
    int m = 0;
    for (int i = 0; i < count; ++i) {
      const glm::dvec3& a = poly[i];
      const glm::dvec3& b = poly[(i + 1) % count];
      const double da = inside(a), db = inside(b);
      if (da >= 0.0) next[m++] = a;
      if ((da >= 0.0) != (db >= 0.0)) {
        const double s = da / (da - db);
        glm::dvec3 p = a + s * (b - a);
        p[axis] = bound;  // exactly on the plane, so later planes see no rounding drift
        next[m++] = p;
      }
    }
    count = m;
    for (int i = 0; i < count; ++i) poly[i] = next[i];
  }
  if (count < 3) return 0.0;
  glm::dvec3 sum(0.0);
  for (int i = 1; i + 1 < count; ++i) sum += glm::cross(poly[i] - poly[0], poly[i + 1] - poly[0]);
  return 0.5 * glm::length(sum);
}

double bvh_epo_leaf_order(std::span<const BvhNode> nodes, std::span<const Triangle> tris, double cost_traversal,
                          double cost_intersect, unsigned threads, const ProgressCallback& progress) {
  if (nodes.empty() || tris.empty()) return 0.0;
  // 1. Leaf-position range [first, end) of every subtree, bottom-up
  //    (children are stored after their parents).
  std::vector<std::uint32_t> first(nodes.size()), end(nodes.size());
  std::vector<std::uint64_t> count(nodes.size());
  for (std::size_t i = nodes.size(); i-- > 0;) {
    const BvhNode& n = nodes[i];
    if (n.count > 0) {
      if (std::uint64_t{n.index} + n.count > tris.size()) throw std::invalid_argument("bvh_epo: leaf range out of bounds");
      first[i] = n.index;
      end[i] = n.index + n.count;
      count[i] = n.count;
    } else {
      if (n.index <= i || n.index + 1 >= nodes.size()) throw std::invalid_argument("bvh_epo: malformed node array");
      first[i] = std::min(first[n.index], first[n.index + 1]);
      end[i] = std::max(end[n.index], end[n.index + 1]);
      count[i] = count[n.index] + count[n.index + 1];
    }
    if (end[i] - first[i] != count[i])
      throw std::invalid_argument("bvh_epo: a subtree's primitives are not contiguous in leaf order");
  }

  // 2. Per triangle: walk the nodes whose boxes its box overlaps (children
  //    lie inside their parent, so a disjoint box prunes the subtree) and
  //    sum C(n)·A(t ∩ n) over those that do not contain it in their subtree.
  //    Per-triangle results are summed in order afterwards, so the total
  //    does not depend on the thread count.
  std::vector<double> per_tri(tris.size(), 0.0), tri_area(tris.size(), 0.0);
  // Progress and cancellation: each chunk of triangles reports, one thread
  // at a time (try_lock: a busy callback is skipped, not waited for); a
  // false answer makes every thread skip the rest.
  std::atomic<bool> cancelled{false};
  std::atomic<std::size_t> done{0};
  std::mutex progress_mutex;
  parallel_for(tris.size(), threads, 256, [&](std::size_t b, std::size_t e, unsigned) {
    std::vector<std::uint32_t> stack;
    stack.reserve(2 * kBvhMaxDepth);
    for (std::size_t k = b; k < e; ++k) {
      if (progress && (k - b) % 256 == 0) {  // (one thread runs the whole range in one call)
        if (cancelled.load(std::memory_order_relaxed)) return;
        const std::size_t before = done.fetch_add(std::min<std::size_t>(256, e - k), std::memory_order_relaxed);
        std::unique_lock lock(progress_mutex, std::try_to_lock);
        if (lock.owns_lock() && !progress(static_cast<double>(before) / static_cast<double>(tris.size()))) {
          cancelled.store(true);
          return;
        }
      }
      const Triangle& t = tris[k];
      tri_area[k] = 0.5 * glm::length(glm::cross(glm::dvec3(t.v1) - glm::dvec3(t.v0), glm::dvec3(t.v2) - glm::dvec3(t.v0)));
      if (!(tri_area[k] > 0.0)) continue;
      const Aabb tb = t.bounds();
      double sum = 0.0;
      stack.clear();
      stack.push_back(0);
      while (!stack.empty()) {
        const std::uint32_t i = stack.back();
        stack.pop_back();
        const BvhNode& n = nodes[i];
        if (Aabb::intersection(n.bounds, tb).is_empty()) continue;
        const bool own = k >= first[i] && k < end[i];
        if (!own) {
          const double a = n.bounds.contains(tb) ? tri_area[k] : clipped_triangle_area(t, n.bounds);
          if (!(a > 0.0)) continue;  // the triangle misses this box, hence all boxes below it
          sum += (n.count == 0 ? cost_traversal : cost_intersect * static_cast<double>(n.count)) * a;
        }
        if (n.count == 0) {
          stack.push_back(n.index + 1);
          stack.push_back(n.index);
        }
      }
      per_tri[k] = sum;
    }
  });
  if (cancelled.load()) throw BuildCancelled();
  double total = 0.0, area = 0.0;
  for (std::size_t k = 0; k < tris.size(); ++k) {
    total += per_tri[k];
    area += tri_area[k];
  }
  return area > 0.0 ? total / area : 0.0;
}

double bvh_epo(std::span<const BvhNode> nodes, std::span<const std::uint32_t> prim_indices,
               std::span<const Triangle> triangles, double cost_traversal, double cost_intersect, unsigned threads,
               const ProgressCallback& progress) {
  if (prim_indices.size() != triangles.size())
    throw std::invalid_argument("bvh_epo: prim_indices and triangles differ in size");
  std::vector<Triangle> leaf_order(triangles.size());
  for (std::size_t k = 0; k < prim_indices.size(); ++k) {
    if (prim_indices[k] >= triangles.size()) throw std::invalid_argument("bvh_epo: primitive index out of range");
    leaf_order[k] = triangles[prim_indices[k]];
  }
  return bvh_epo_leaf_order(nodes, leaf_order, cost_traversal, cost_intersect, threads, progress);
}

}  // namespace accelviz
