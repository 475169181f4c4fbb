#include "core/analysis/insight/sah_explainer.h"

#include <algorithm>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "core/accel/bvh/bvh_build.h"

namespace accelviz {

const char* to_string(SplitDecision d) {
  switch (d) {
    case SplitDecision::split:
      return "split";
    case SplitDecision::leaf:
      return "leaf";
    case SplitDecision::always_leaf:
      return "always leaf";
    case SplitDecision::unsplittable:
      return "unsplittable";
  }
  return "?";
}

SplitExplanation explain_binned_split(std::span<const Aabb> bounds, std::span<const glm::vec3> centroids,
                                      const BvhOptions& opts) {
  using namespace bvh_detail;
  validate(opts);
  if (bounds.size() != centroids.size())
    throw std::invalid_argument("explain_binned_split: " + std::to_string(bounds.size()) + " bounds but " +
                                std::to_string(centroids.size()) + " centroids");
  std::vector<BuildPrim> prims(bounds.size());
  for (std::size_t i = 0; i < prims.size(); ++i) prims[i] = {centroids[i], static_cast<std::uint32_t>(i), bounds[i]};

  SplitExplanation e;
  const std::size_t n = prims.size();
  e.prims = n;
  e.buckets = binned_bucket_count(opts.buckets, opts.small_node_buckets, n);
  range_bounds(prims, e.bounds, e.centroid_bounds);
  const SplitParams params{opts.buckets, opts.max_leaf_size, opts.leaf_size_cap, opts.cost_traversal,
                           opts.cost_intersect};
  e.leaf_cost = static_cast<double>(opts.cost_intersect) * static_cast<double>(n);
  e.leaf_allowed = n <= static_cast<std::size_t>(opts.leaf_size_cap);
  e.split_cost = std::numeric_limits<double>::quiet_NaN();
  if (n == 0) {
    e.decision = SplitDecision::always_leaf;
    return e;
  }

  const auto bins = std::make_unique<Bins>();
  struct CostTable {
    CandidateCosts c;
  };
  const auto table = std::make_unique<CostTable>();
  CandidateCosts* costs = &table->c;
  BinnedSahSearch s;
  const bool binned = binned_sah_search(e.buckets, prims, e.centroid_bounds, *bins, s, costs);
  const double node_area = e.bounds.half_area();
  // Normalised by the node's area; a node without area gives every child ratio 1.
  const auto full_cost = [&](double area_count, std::size_t nl, std::size_t nr) {
    const double weighted = node_area > 0.0 ? area_count / node_area : static_cast<double>(nl + nr);
    return static_cast<double>(opts.cost_traversal) + static_cast<double>(opts.cost_intersect) * weighted;
  };
  const int nb = e.buckets;
  if (binned) {
    for (int a = 0; a < 3; ++a) {
      AxisExplanation& ax = e.axes[a];
      ax.usable = s.usable[a];
      if (!ax.usable) continue;
      const float lo = e.centroid_bounds.lo[a];
      const float width = 1.0f / s.k[a];
      std::uint32_t left = 0;
      for (int b = 0; b < nb; ++b) {
        BucketInfo bi;
        bi.count = bins->count[a][b];
        bi.lo = lo + static_cast<float>(b) * width;
        bi.hi = b == nb - 1 ? e.centroid_bounds.hi[a] : lo + static_cast<float>(b + 1) * width;
        if (bi.count > 0) bi.box = bucket_box(*bins, a, b);
        ax.buckets.push_back(bi);
      }
      for (int b = 0; b < nb - 1; ++b) {
        left += bins->count[a][b];
        ax.plane.push_back(ax.buckets[static_cast<std::size_t>(b)].hi);
        ax.left.push_back(left);
        const float c = (*costs)[a][b];
        ax.cost.push_back(c == c ? full_cost(c, left, n - left) : std::numeric_limits<double>::quiet_NaN());
      }
    }
  }
  if (binned && s.best_axis >= 0) {
    e.chosen_axis = s.best_axis;
    e.chosen_plane = s.best_bucket;
    e.chosen_left = s.best_left;
    e.split_cost = full_cost(s.best_cost, s.best_left, n - s.best_left);
  }
  if (n <= static_cast<std::size_t>(opts.max_leaf_size))
    e.decision = SplitDecision::always_leaf;
  else if (e.chosen_axis < 0)
    e.decision = SplitDecision::unsplittable;
  else if (sah_prefers_leaf(params, n, e.bounds.half_area(), s.best_cost))
    e.decision = SplitDecision::leaf;
  else
    e.decision = SplitDecision::split;
  return e;
}

SplitExplanation explain_bvh_node(const Bvh& bvh, std::uint32_t node, const BvhOptions& opts) {
  const auto nodes = bvh.nodes();
  if (node >= nodes.size())
    throw std::out_of_range("explain_bvh_node: node " + std::to_string(node) + " of " + std::to_string(nodes.size()));
  // A subtree's primitives are contiguous in leaf order: find its range.
  std::uint32_t first = std::numeric_limits<std::uint32_t>::max(), last = 0;
  std::vector<std::uint32_t> stack{node};
  while (!stack.empty()) {
    const BvhNode& n = nodes[stack.back()];
    stack.pop_back();
    if (n.is_leaf()) {
      first = std::min(first, n.index);
      last = std::max(last, n.index + n.count);
    } else {
      stack.push_back(n.index);
      stack.push_back(n.index + 1);
    }
  }
  const std::vector<Triangle> leaf_tris = bvh.copy_leaf_triangles(first, last);
  const std::span<const Triangle> tris(leaf_tris);
  std::vector<Aabb> bounds(tris.size());
  std::vector<glm::vec3> centroids(tris.size());
  for (std::size_t i = 0; i < tris.size(); ++i) {
    bounds[i] = tris[i].bounds();
    centroids[i] = bounds[i].center();  // what class Bvh bins on
  }
  return explain_binned_split(bounds, centroids, opts);
}

}  // namespace accelviz
