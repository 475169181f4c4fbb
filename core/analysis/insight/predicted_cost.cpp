#include "core/analysis/insight/predicted_cost.h"

#include <limits>

#include "core/analysis/sah.h"

namespace accelviz {

std::vector<double> bvh_hit_probabilities(std::span<const BvhNode> nodes) {
  std::vector<double> p(nodes.size(), 1.0);
  if (nodes.empty()) return p;
  const double root = nodes[0].bounds.half_area();
  if (!(root > 0.0)) return p;
  for (std::size_t i = 0; i < nodes.size(); ++i) p[i] = static_cast<double>(nodes[i].bounds.half_area()) / root;
  return p;
}

std::vector<double> measured_entry_fractions(const VisitRecord& rec, std::size_t node_count) {
  std::vector<double> f(node_count, 0.0);
  std::uint64_t root_rays = 0;
  for (std::size_t p = 0; p < rec.pixel_count(); ++p) {
    const auto ns = rec.nodes_of(p);
    if (ns.empty() || ns.front() != 0) continue;
    ++root_rays;
    for (const std::uint32_t id : ns)
      if (id < node_count) f[id] += 1.0;
  }
  if (root_rays > 0)
    for (double& v : f) v /= static_cast<double>(root_rays);
  return f;
}

CostComparison compare_predicted_measured(const Bvh& bvh, const VisitRecord& rec) {
  const auto nodes = bvh.nodes();
  const BvhOptions& o = bvh.options();
  CostComparison c;
  c.sah = bvh_sah_cost(nodes, o.cost_traversal, o.cost_intersect);
  const auto it = bvh.build_stats().extra.find("epo");
  c.epo = it != bvh.build_stats().extra.end() ? it->second : std::numeric_limits<double>::quiet_NaN();
  c.rays = rec.pixel_count();
  double node_sum = 0.0, inner_sum = 0.0, prim_sum = 0.0;
  for (std::size_t p = 0; p < rec.pixel_count(); ++p) {
    const auto ns = rec.nodes_of(p);
    if (ns.empty() || ns.front() != 0) continue;
    ++c.root_rays;
    node_sum += static_cast<double>(ns.size());
    for (const std::uint32_t id : ns)
      if (id < nodes.size() && !nodes[id].is_leaf()) inner_sum += 1.0;
    prim_sum += static_cast<double>(rec.stats[p].prim_tests);
  }
  if (c.root_rays > 0) {
    const double r = static_cast<double>(c.root_rays);
    c.nodes_per_ray = node_sum / r;
    c.inner_per_ray = inner_sum / r;
    c.prims_per_ray = prim_sum / r;
  }
  c.cost_per_ray = o.cost_traversal * c.inner_per_ray + o.cost_intersect * c.prims_per_ray;
  c.ratio = c.sah > 0.0 ? c.cost_per_ray / c.sah : 0.0;
  return c;
}

}  // namespace accelviz
