// Full-sweep SAH splitter: the accuracy reference for binning.
//
// For each axis the node's primitives are sorted by centroid (ties by id) and
// the SAH is evaluated between every pair of neighbours: a right-to-left
// sweep stores the half area of every suffix, a left-to-right sweep grows the
// prefix box and completes A_L·N_L + A_R·N_R. O(n log n) per node,
// O(n log² n) per tree; every object split along the three axes is
// considered, so binning can only match or lose against it on one node
// (MacDonald & Booth 1990; Wald 2007 uses it as the reference too).
#include "core/accel/bvh/bvh_build.h"

#include <algorithm>

namespace accelviz::bvh_detail {

SplitOutcome split_exact_sah(const SplitParams& params, std::span<BuildPrim> prims, const Aabb& bounds,
                             const Aabb& /*centroid_bounds*/, SplitScratch& scratch, SplitResult& out) {
  const std::size_t n = prims.size();
  std::vector<float>& suffix = scratch.suffix_area;
  if (suffix.size() < n) suffix.resize(n);

  float best_cost = kInfinity;
  std::size_t best_left = 0;
  int best_axis = -1;
  for (int a = 0; a < 3; ++a) {
    std::sort(prims.begin(), prims.end(), [a](const BuildPrim& x, const BuildPrim& y) { return centroid_less(x, y, a); });
    // suffix[i] = half area of prims [i, n)
    Aabb acc;
    for (std::size_t i = n; i-- > 1;) {
      acc.extend(prims[i].bounds);
      suffix[i] = acc.half_area();
    }
    acc = Aabb{};
    for (std::size_t i = 1; i < n; ++i) {  // split: [0, i) | [i, n)
      acc.extend(prims[i - 1].bounds);
      const float cost = acc.half_area() * static_cast<float>(i) + suffix[i] * static_cast<float>(n - i);
      if (better_split(cost, i, n, best_cost, best_left)) {
        best_cost = cost;
        best_left = i;
        best_axis = a;
      }
    }
  }
  if (best_axis < 0) return SplitOutcome::unsplittable;  // n < 2; the driver never asks
  if (sah_prefers_leaf(params, n, bounds.half_area(), best_cost)) return SplitOutcome::leaf;

  if (best_axis != 2)
    std::sort(prims.begin(), prims.end(),
              [best_axis](const BuildPrim& x, const BuildPrim& y) { return centroid_less(x, y, best_axis); });
  out.mid = best_left;
  range_bounds(prims.first(best_left), out.bounds[0], out.centroid_bounds[0]);
  range_bounds(prims.subspan(best_left), out.bounds[1], out.centroid_bounds[1]);
  return SplitOutcome::split;
}

}  // namespace accelviz::bvh_detail
