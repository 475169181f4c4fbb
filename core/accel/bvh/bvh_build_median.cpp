// Median splitter: equal primitive counts on the axis of largest centroid
// extent, no cost model. Cheap and balanced (depth ⌈log2(n/leaf)⌉), but blind
// to empty space and overlap: the baseline that shows what the SAH buys.
#include "core/accel/bvh/bvh_build.h"

namespace accelviz::bvh_detail {

SplitOutcome split_median(const SplitParams& /*params*/, std::span<BuildPrim> prims, const Aabb& /*bounds*/,
                          const Aabb& centroid_bounds, SplitScratch& /*scratch*/, SplitResult& out) {
  split_object_median(prims, centroid_bounds, out);
  return SplitOutcome::split;
}

}  // namespace accelviz::bvh_detail
