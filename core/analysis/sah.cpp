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
  // Children always follow their parent in the array, so one forward sweep
  // propagates depths.
  HugePageVector<std::uint32_t> depth(nodes.size(), 0);  // fresh pages: cheaper as huge ones (huge_page_allocator.h)
  double depth_sum = 0.0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const BvhNode& n = nodes[i];
    if (n.count == 0) {
      if (n.index <= i || n.index + 1 >= nodes.size()) continue;  // malformed: not a tree this builder makes
      depth[n.index] = depth[i] + 1;
      depth[n.index + 1] = depth[i] + 1;
    } else {
      ++s.leaf_count;
      depth_sum += depth[i];
      if (depth[i] > s.max_depth) s.max_depth = depth[i];
    }
  }
  s.avg_leaf_depth = s.leaf_count > 0 ? depth_sum / static_cast<double>(s.leaf_count) : 0.0;
  return s;
}

}  // namespace accelviz
