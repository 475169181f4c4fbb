#pragma once
// Surface area heuristic cost of a finished BVH (Goldsmith & Salmon 1987,
// MacDonald & Booth 1990): the expected cost of a long random ray that hits
// the root box, assuming the probability of hitting a node given the root is
// the ratio of their surface areas:
//
//   SAH = Σ_inner C_trav·A(n)/A(root) + Σ_leaf C_isect·N(n)·A(n)/A(root)
//
// Recomputed from the node array alone, independently of what the builder
// estimated while splitting, so it also measures refitted trees.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "core/accel/bvh/bvh.h"

namespace accelviz {

/// The range an SAH cost constant (C_trav, C_isect) is taken in, from the command line, `--compare`,
/// a sweep and the GUI's fields alike: only the ratio of the two matters to a build, 3e38 overflowed
/// the cost metric (a ray's cost read inf) and the tree's float SAH sums, and 1e-300 is 0 in float.
inline constexpr double kMinCostConstant = 1e-6;
inline constexpr double kMaxCostConstant = 1e6;

/// "" when `v` lies in [kMinCostConstant, kMaxCostConstant], else "must be a number from 1e-06 to 1e+06".
inline std::string cost_constant_problem(double v) {
  if (v >= kMinCostConstant && v <= kMaxCostConstant) return {};
  return "must be a number from 1e-06 to 1e+06";
}

/// SAH cost of `nodes` (root at 0). 0 for an empty tree. When the root box
/// has zero area (all primitives on a point or a line) every ratio is taken
/// as 1: every ray that hits the root then hits every node. Summed in fixed
/// chunks of kSahChunk nodes, added in chunk order, on `threads` threads (0:
/// all): the same value, bit for bit, on any number of threads.
double bvh_sah_cost(std::span<const BvhNode> nodes, double cost_traversal, double cost_intersect, unsigned threads = 1);
inline constexpr std::size_t kSahChunk = 16384;

/// Counts and depths of a node array (root depth 0).
struct TreeShape {
  std::uint64_t leaf_count = 0;
  std::uint32_t max_depth = 0;
  double avg_leaf_depth = 0.0;  ///< mean depth over leaves (each leaf counted once)
};
TreeShape bvh_tree_shape(std::span<const BvhNode> nodes);

/// Calls f(i, depth) for every leaf i of `nodes` (root at 0, depth 0), in array order. Children
/// always follow their parent in the array, so one forward sweep propagates depths; an inner node
/// whose children do not (a malformed array, not a tree this builder makes) is skipped.
template <class F>
void for_each_leaf_depth(std::span<const BvhNode> nodes, F&& f) {
  HugePageVector<std::uint32_t> depth(nodes.size(), 0);  // fresh pages: cheaper as huge ones (huge_page_allocator.h)
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const BvhNode& n = nodes[i];
    if (n.count > 0) {
      f(i, depth[i]);
    } else if (n.index > i && n.index + 1 < nodes.size()) {
      depth[n.index] = depth[i] + 1;
      depth[n.index + 1] = depth[i] + 1;
    }
  }
}

}  // namespace accelviz
