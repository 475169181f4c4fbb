#pragma once
// The binned-SAH explainer: for one node, what the binned SAH builder sees
// and decides. Per axis, the primitives' centroids are dropped into B equal
// buckets over the centroid bounds (counts, the centroid interval each bucket
// covers, the union box of its primitives), the SAH cost is evaluated at the
// B-1 bucket boundaries, the cheapest plane is chosen, and it is compared
// with making the node a leaf. Runs the builder's own code
// (bvh_detail::binned_sah_search), so what it shows is what the build does.
#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "core/accel/bvh/bvh.h"
#include "core/math/aabb.h"

namespace accelviz {

struct BucketInfo {
  std::uint32_t count = 0;  ///< primitives whose centroid falls in the bucket
  float lo = 0.0f;          ///< centroid interval covered on the axis: [lo, hi)
  float hi = 0.0f;
  Aabb box;  ///< union of the bounds of its primitives (empty when count is 0)
};

struct AxisExplanation {
  bool usable = false;              ///< false: the centroids do not spread on this axis (no candidates)
  std::vector<BucketInfo> buckets;  ///< B entries (empty when not usable)
  std::vector<float> plane;         ///< B-1 candidate plane positions (between bucket b and b+1)
  std::vector<std::uint32_t> left;  ///< primitives left of each candidate plane
  /// Full SAH cost of splitting at each candidate, per ray that hits the node:
  /// C_trav + C_isect·(A_L·N_L + A_R·N_R)/A_N; NaN where one side is empty.
  std::vector<double> cost;
};

enum class SplitDecision {
  split,         ///< the cheapest plane beats a leaf (or a leaf is not allowed)
  leaf,          ///< a leaf costs no more than the best split and the node is within leaf_size_cap
  always_leaf,   ///< at most max_leaf_size primitives: a leaf without asking the SAH
  unsplittable,  ///< all centroids in one bucket on every axis: the SAH cannot separate them (the builder falls back to
                 ///< an object median split)
};
const char* to_string(SplitDecision d);

struct SplitExplanation {
  std::size_t prims = 0;
  int buckets = 0;       ///< buckets used, as the build does (binned_bucket_count)
  Aabb bounds;           ///< node box
  Aabb centroid_bounds;  ///< box of the centroids (what is binned)
  AxisExplanation axes[3];
  int chosen_axis = -1;   ///< -1 when unsplittable
  int chosen_plane = -1;  ///< index into axes[chosen_axis].plane
  std::size_t chosen_left = 0;
  double leaf_cost = 0.0;     ///< C_isect·N
  double split_cost = 0.0;    ///< cost of the chosen plane (NaN when unsplittable)
  bool leaf_allowed = false;  ///< N <= leaf_size_cap
  SplitDecision decision = SplitDecision::unsplittable;
};

/// Explains the split of primitives given by their bounds and centroids
/// under `opts` (buckets, max_leaf_size, leaf_size_cap, C_trav, C_isect).
/// Throws std::invalid_argument on bad options or mismatched spans.
SplitExplanation explain_binned_split(std::span<const Aabb> bounds, std::span<const glm::vec3> centroids,
                                      const BvhOptions& opts);

/// Explains the split of the primitives below `node` of a built tree (their
/// centroids taken as their boxes' centres, as class Bvh builds), with
/// `opts` (e.g. another bucket count than the tree was built with).
/// Throws std::out_of_range for a bad node.
SplitExplanation explain_bvh_node(const Bvh& bvh, std::uint32_t node, const BvhOptions& opts);

}  // namespace accelviz
