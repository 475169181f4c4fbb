#pragma once
// Predicted vs measured cost of a BVH for one view. The SAH predicts the
// expected cost of a ray that hits the root box, taking the probability of
// entering node n as A(n)/A(root) (surface area ratio, for uniformly
// distributed long rays); EPO adds what the overlap of boxes with other
// subtrees' geometry costs. The measured side uses the very same terms on
// the view's actual rays: C_trav per inner node entered + C_isect per
// primitive test, averaged over the rays that entered the root, and per
// node the fraction of those rays that entered it.
#include <cstdint>
#include <span>
#include <vector>

#include "core/accel/bvh/bvh.h"
#include "core/analysis/insight/visit_attribution.h"

namespace accelviz {

/// A(n)/A(root) for every node (surface areas of the boxes); all 1 when the
/// root box has no area (as bvh_sah_cost takes them). Empty for an empty tree.
std::vector<double> bvh_hit_probabilities(std::span<const BvhNode> nodes);

/// Fraction of the rays that entered the root which also entered each node
/// (node ids are BVH node indices; 0 everywhere when no ray entered the root).
std::vector<double> measured_entry_fractions(const VisitRecord& rec, std::size_t node_count);

struct CostComparison {
  double sah = 0.0;             ///< predicted: SAH expected cost per ray that hits the root
  double epo = 0.0;             ///< EPO of the tree (NaN when the tree was built without it)
  std::uint64_t rays = 0;       ///< rays of the view
  std::uint64_t root_rays = 0;  ///< rays that entered the root box (the SAH's condition)
  double nodes_per_ray = 0.0;   ///< measured: mean nodes entered (inner + leaves), over root_rays
  double inner_per_ray = 0.0;   ///< measured: mean inner nodes entered, over root_rays
  double prims_per_ray = 0.0;   ///< measured: mean primitive tests, over root_rays
  double cost_per_ray = 0.0;    ///< measured: C_trav·inner_per_ray + C_isect·prims_per_ray
  double ratio = 0.0;           ///< cost_per_ray / sah (0 when sah is 0)
};

/// The comparison for `bvh` over a record of its own traversals (record_visits
/// on the same tree). C_trav and C_isect are the tree's build options.
CostComparison compare_predicted_measured(const Bvh& bvh, const VisitRecord& rec);

}  // namespace accelviz
