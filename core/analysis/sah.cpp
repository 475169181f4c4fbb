#include "core/analysis/sah.h"

#include <algorithm>
#include <vector>

#include "core/util/huge_page_allocator.h"
#include "core/util/parallel.h"

namespace accelviz {

double bvh_sah_cost(std::span<const BvhNode> nodes, double cost_traversal, double cost_intersect, unsigned threads) {
  if (nodes.empty()) return 0.0;
  // Areas in double: a large tree sums millions of small ratios.
  const auto area = [](const Aabb& b) {
    if (b.is_empty()) return 0.0;
    const glm::dvec3 e = glm::dvec3(b.hi) - glm::dvec3(b.lo);
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
  };
  const double root_area = area(nodes[0].bounds);
  std::vector<double> chunk_sum((nodes.size() + kSahChunk - 1) / kSahChunk, 0.0);
  parallel_for(chunk_sum.size(), threads, 1, [&](std::size_t c0, std::size_t c1, unsigned) {
    for (std::size_t c = c0; c < c1; ++c) {
      double sum = 0.0;
      for (const BvhNode& n : nodes.subspan(c * kSahChunk, std::min(kSahChunk, nodes.size() - c * kSahChunk))) {
        const double p = root_area > 0.0 ? area(n.bounds) / root_area : 1.0;
        sum += n.count == 0 ? cost_traversal * p : cost_intersect * static_cast<double>(n.count) * p;
      }
      chunk_sum[c] = sum;
    }
  });
  double sum = 0.0;
  for (const double s : chunk_sum) sum += s;
  return sum;
}

TreeShape bvh_tree_shape(std::span<const BvhNode> nodes) {
  TreeShape s;
  if (nodes.empty()) return s;
  double depth_sum = 0.0;
  for_each_leaf_depth(nodes, [&](std::size_t, std::uint32_t depth) {
    ++s.leaf_count;
    depth_sum += depth;
    if (depth > s.max_depth) s.max_depth = depth;
  });
  s.avg_leaf_depth = s.leaf_count > 0 ? depth_sum / static_cast<double>(s.leaf_count) : 0.0;
  return s;
}

}  // namespace accelviz
