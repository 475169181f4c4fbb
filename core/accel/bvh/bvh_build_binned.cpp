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
#include <limits>
#include <utility>

#if defined(__SSE2__) && !defined(ACCELVIZ_NO_SIMD)
#include <emmintrin.h>
#endif

namespace accelviz::bvh_detail {

void clear_bins(Bins& bins, int buckets) {
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < buckets; ++b) {
      for (int l = 0; l < 4; ++l) {
        bins.lo[a][b][l] = kInfinity;
        bins.hi[a][b][l] = -kInfinity;
      }
      bins.count[a][b] = 0;
    }
}

void bin_primitives_scalar(std::span<const BuildPrim> prims, const glm::vec3& origin, const float k[3], int buckets,
                           Bins& bins) {
  for (const BuildPrim& p : prims) {
    for (int a = 0; a < 3; ++a) {
      const int b = bucket_of(p.centroid[a], origin[a], k[a], buckets);
      float* lo = bins.lo[a][b];
      float* hi = bins.hi[a][b];
      for (int l = 0; l < 3; ++l) {
        lo[l] = lo[l] < p.bounds.lo[l] ? lo[l] : p.bounds.lo[l];  // minps semantics
        hi[l] = hi[l] > p.bounds.hi[l] ? hi[l] : p.bounds.hi[l];  // maxps semantics
      }
      ++bins.count[a][b];
    }
  }
}

#if defined(__SSE2__) && !defined(ACCELVIZ_NO_SIMD)
void bin_primitives(std::span<const BuildPrim> prims, const glm::vec3& origin, const float k[3], int buckets,
                    Bins& bins) {
  // The three bucket indices in one go: (c - origin)·k, clamped to
  // [0, B-1] by max/min (a NaN or negative lane gives 0, as bucket_of), then
  // truncated. Lane 3 reads the id and is ignored.
  const __m128 o = _mm_setr_ps(origin.x, origin.y, origin.z, 0.0f);
  const __m128 kv = _mm_setr_ps(k[0], k[1], k[2], 0.0f);
  const __m128 top = _mm_set1_ps(static_cast<float>(buckets - 1));
  alignas(16) int idx[4];
  for (const BuildPrim& p : prims) {
    const __m128 x = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(&p.centroid.x), o), kv);
    _mm_store_si128(reinterpret_cast<__m128i*>(idx), _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(x, _mm_setzero_ps()), top)));
    // lo.xyz (+ hi.x), and hi.xyz rotated out of (lo.z, hi.x, hi.y, hi.z):
    // both loads stay inside the 40-byte record.
    const __m128 lo = _mm_loadu_ps(&p.bounds.lo.x);
    const __m128 hz = _mm_loadu_ps(&p.bounds.lo.z);
    const __m128 hi = _mm_shuffle_ps(hz, hz, _MM_SHUFFLE(0, 3, 2, 1));
    for (int a = 0; a < 3; ++a) {
      float* bl = bins.lo[a][idx[a]];
      float* bh = bins.hi[a][idx[a]];
      _mm_store_ps(bl, _mm_min_ps(_mm_load_ps(bl), lo));
      _mm_store_ps(bh, _mm_max_ps(_mm_load_ps(bh), hi));
      ++bins.count[a][idx[a]];
    }
  }
}
#else
void bin_primitives(std::span<const BuildPrim> prims, const glm::vec3& origin, const float k[3], int buckets,
                    Bins& bins) {
  bin_primitives_scalar(prims, origin, k, buckets, bins);
}
#endif

Aabb bucket_box(const Bins& bins, int axis, int b) {
  const float* lo = bins.lo[axis][b];
  const float* hi = bins.hi[axis][b];
  return Aabb{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}};
}

namespace {

template <bool Record>
bool search_impl(int nb, std::span<const BuildPrim> prims, const Aabb& centroid_bounds, Bins& bins,
                 BinnedSahSearch& s, CandidateCosts* costs) {
  const std::size_t n = prims.size();
  s = BinnedSahSearch{};

  // 1. Per-axis scale k = B / extent of the centroid bounds. An axis whose
  //    centroids do not spread (zero or denormal extent) cannot be binned.
  bool any_usable = false;
  for (int a = 0; a < 3; ++a) {
    const float extent = centroid_bounds.hi[a] - centroid_bounds.lo[a];
    s.k[a] = extent > 0.0f ? static_cast<float>(nb) / extent : 0.0f;
    s.usable[a] = extent > 0.0f && std::isfinite(s.k[a]) && std::isfinite(extent);
    any_usable = any_usable || s.usable[a];
    if constexpr (Record)
      for (int b = 0; b < nb - 1; ++b) (*costs)[a][b] = std::numeric_limits<float>::quiet_NaN();
  }
  if (!any_usable) return false;

  // 2. Binning: one pass, all three axes. (Only the B buckets in use are cleared.)
  clear_bins(bins, nb);
  bin_primitives(prims, centroid_bounds.lo, s.k, nb, bins);

  // 3. SAH at every bucket boundary: a right-to-left sweep stores the right
  //    side's area and count, a left-to-right sweep completes the cost
  //    A_L·N_L + A_R·N_R (half areas; C_trav and 1/A_N are common to all
  //    candidates and enter only the leaf test).
  for (int a = 0; a < 3; ++a) {
    if (!s.usable[a]) continue;
    std::array<float, kMaxBuckets> right_area;
    std::array<std::uint32_t, kMaxBuckets> right_count;
    Aabb acc;
    std::uint32_t cnt = 0;
    for (int b = nb - 1; b > 0; --b) {
      acc.extend(bucket_box(bins, a, b));
      cnt += bins.count[a][b];
      right_area[b - 1] = acc.half_area();
      right_count[b - 1] = cnt;
    }
    acc = Aabb{};
    cnt = 0;
    for (int b = 0; b < nb - 1; ++b) {
      acc.extend(bucket_box(bins, a, b));
      cnt += bins.count[a][b];
      if (cnt == 0 || right_count[b] == 0) continue;
      const float cost =
          acc.half_area() * static_cast<float>(cnt) + right_area[b] * static_cast<float>(right_count[b]);
      if constexpr (Record) (*costs)[a][b] = cost;
      if (better_split(cost, cnt, n, s.best_cost, s.best_left)) {
        s.best_cost = cost;
        s.best_left = cnt;
        s.best_axis = a;
        s.best_bucket = b;
      }
    }
  }
  return true;
}

}  // namespace

bool binned_sah_search(int buckets, std::span<const BuildPrim> prims, const Aabb& centroid_bounds, Bins& bins,
                       BinnedSahSearch& out, CandidateCosts* costs) {
  return costs ? search_impl<true>(buckets, prims, centroid_bounds, bins, out, costs)
               : search_impl<false>(buckets, prims, centroid_bounds, bins, out, nullptr);
}

SplitOutcome split_binned_sah(const SplitParams& params, std::span<BuildPrim> prims, const Aabb& bounds,
                              const Aabb& centroid_bounds, SplitScratch& /*scratch*/, SplitResult& out) {
  const int nb = params.buckets;
  const std::size_t n = prims.size();

  // 1-3. Scale, binning and the SAH at every bucket boundary (shared with the
  //      explainer in core/analysis/insight). Bins is left uninitialised.
  Bins bins;
  BinnedSahSearch search;
  if (!binned_sah_search(nb, prims, centroid_bounds, bins, search)) return SplitOutcome::unsplittable;
  const float best_cost = search.best_cost;
  const int best_axis = search.best_axis, best_bucket = search.best_bucket;
  const glm::vec3 lo = centroid_bounds.lo;
  const float* k = search.k;
  if (best_axis < 0) return SplitOutcome::unsplittable;
  if (sah_prefers_leaf(params, n, bounds.half_area(), best_cost)) return SplitOutcome::leaf;

  // 4. Children's bounds are the unions of their buckets' bounds.
  Aabb child_bounds[2];
  for (int b = 0; b < nb; ++b) child_bounds[b <= best_bucket ? 0 : 1].extend(bucket_box(bins, best_axis, b));

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
