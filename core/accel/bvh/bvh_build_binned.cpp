// Binned SAH splitter (Wald, "On fast Construction of SAH-based Bounding
// Volume Hierarchies", IEEE RT 2007).
//
// Instead of evaluating the SAH between every pair of sorted neighbours, the
// centroid range of the node is cut into B equal buckets on each axis; one
// streaming pass drops every primitive into its bucket on all three axes at
// once (counts and bounds), and the SAH is evaluated only at the B-1 bucket
// boundaries of each axis with two sweeps over the buckets. Cost per node:
// O(n + B), no sorting.
#include "core/accel/bvh/bvh_build.h"

#include <array>
#include <utility>

namespace accelviz::bvh_detail {
namespace {

constexpr int kMaxBuckets = 256;

/// No default member initialisers on purpose: a node initialises only the B
/// buckets it uses, not all 3×256.
struct Bucket {
  glm::vec3 lo, hi;
  std::uint32_t count;

  void reset() {
    lo = glm::vec3(kInfinity);
    hi = glm::vec3(-kInfinity);
    count = 0;
  }
  Aabb box() const { return Aabb{lo, hi}; }
};

/// Bucket of a centroid coordinate: floor((c - lo)·k), clamped to [0, B-1].
/// The same function places a primitive while binning and while
/// partitioning, so both passes agree exactly. A NaN lands in bucket 0.
inline int bucket_of(float c, float lo, float k, int buckets) {
  const float x = (c - lo) * k;
  if (!(x >= 0.0f)) return 0;
  const float top = static_cast<float>(buckets - 1);
  return x < top ? static_cast<int>(x) : buckets - 1;
}

}  // namespace

SplitOutcome split_binned_sah(const SplitParams& params, std::span<BuildPrim> prims, const Aabb& bounds,
                              const Aabb& centroid_bounds, SplitScratch& /*scratch*/, SplitResult& out) {
  const int nb = params.buckets;
  const std::size_t n = prims.size();

  // 1. Per-axis scale k = B / extent of the centroid bounds. An axis whose
  //    centroids do not spread (zero or denormal extent) cannot be binned.
  float k[3];
  bool usable[3];
  bool any_usable = false;
  for (int a = 0; a < 3; ++a) {
    const float extent = centroid_bounds.hi[a] - centroid_bounds.lo[a];
    k[a] = extent > 0.0f ? static_cast<float>(nb) / extent : 0.0f;
    usable[a] = extent > 0.0f && std::isfinite(k[a]) && std::isfinite(extent);
    any_usable = any_usable || usable[a];
  }
  if (!any_usable) return SplitOutcome::unsplittable;

  // 2. Binning: one pass, all three axes.
  std::array<std::array<Bucket, kMaxBuckets>, 3> bins;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < nb; ++b) bins[a][b].reset();
  const glm::vec3 lo = centroid_bounds.lo;
  for (const BuildPrim& p : prims) {
    for (int a = 0; a < 3; ++a) {
      Bucket& bk = bins[a][bucket_of(p.centroid[a], lo[a], k[a], nb)];
      bk.lo = glm::min(bk.lo, p.bounds.lo);
      bk.hi = glm::max(bk.hi, p.bounds.hi);
      ++bk.count;
    }
  }

  // 3. SAH at every bucket boundary: a right-to-left sweep stores the right
  //    side's area and count, a left-to-right sweep completes the cost
  //    A_L·N_L + A_R·N_R (half areas; C_trav and 1/A_N are common to all
  //    candidates and enter only the leaf test).
  float best_cost = kInfinity;
  std::size_t best_left = 0;
  int best_axis = -1, best_bucket = -1;
  for (int a = 0; a < 3; ++a) {
    if (!usable[a]) continue;
    std::array<float, kMaxBuckets> right_area;
    std::array<std::uint32_t, kMaxBuckets> right_count;
    Aabb acc;
    std::uint32_t cnt = 0;
    for (int b = nb - 1; b > 0; --b) {
      acc.extend(bins[a][b].box());
      cnt += bins[a][b].count;
      right_area[b - 1] = acc.half_area();
      right_count[b - 1] = cnt;
    }
    acc = Aabb{};
    cnt = 0;
    for (int b = 0; b < nb - 1; ++b) {
      acc.extend(bins[a][b].box());
      cnt += bins[a][b].count;
      if (cnt == 0 || right_count[b] == 0) continue;
      const float cost =
          acc.half_area() * static_cast<float>(cnt) + right_area[b] * static_cast<float>(right_count[b]);
      if (better_split(cost, cnt, n, best_cost, best_left)) {
        best_cost = cost;
        best_left = cnt;
        best_axis = a;
        best_bucket = b;
      }
    }
  }
  if (best_axis < 0) return SplitOutcome::unsplittable;
  if (sah_prefers_leaf(params, n, bounds.half_area(), best_cost)) return SplitOutcome::leaf;

  // 4. Children's bounds are the unions of their buckets' bounds.
  Aabb child_bounds[2];
  for (int b = 0; b < nb; ++b) child_bounds[b <= best_bucket ? 0 : 1].extend(bins[best_axis][b].box());

  // 5. In-place two-ended partition (Hoare), gathering the children's
  //    centroid bounds on the way; each primitive is classified once.
  const int a = best_axis;
  const float lo_a = lo[a], k_a = k[a];
  const auto goes_left = [&](const BuildPrim& p) { return bucket_of(p.centroid[a], lo_a, k_a, nb) <= best_bucket; };
  Aabb cb_left, cb_right;
  std::size_t i = 0, j = n;
  for (;;) {
    while (i < j && goes_left(prims[i])) cb_left.extend(prims[i++].centroid);
    while (i < j && !goes_left(prims[j - 1])) cb_right.extend(prims[--j].centroid);
    if (i >= j) break;
    std::swap(prims[i], prims[j - 1]);
    cb_left.extend(prims[i++].centroid);
    cb_right.extend(prims[--j].centroid);
  }
  out.mid = i;
  out.bounds[0] = child_bounds[0];
  out.bounds[1] = child_bounds[1];
  out.centroid_bounds[0] = cb_left;
  out.centroid_bounds[1] = cb_right;
  return SplitOutcome::split;
}

}  // namespace accelviz::bvh_detail
