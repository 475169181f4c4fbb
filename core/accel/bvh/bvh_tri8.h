#pragma once
// Two triangle blocks per test: the 8-wide walk (AVX2) runs the watertight
// and Moller-Trumbore tests of bvh_tri4.h on two consecutive blocks of a
// leaf slot at once, lanes 0-3 from the first block and 4-7 from the second
// (the leaf's triangles in order). Leaf slots of two or more blocks are
// common where the collapse merges binary leaves (BvhOptions::
// wide_merge_blocks) and in leaves of more than four triangles.
//
// Exactness: the tests are bvh_tri4.h's, written once for four and eight
// lanes (tri_lanes_edges, tri_lanes_distance, tri_lanes_mt): each lane
// performs the scalar test's float operations in its order (AVX add/sub/
// mul/div are IEEE like their SSE forms; core builds with -ffp-contract=off,
// so nothing becomes an FMA), so a lane's figures are bit for bit the
// four-lane ones and hence the scalar ones; the callers replay the same
// acceptance per lane.
#include "core/accel/bvh/bvh_slab.h"  // ACCELVIZ_BVH_WIDE8_AVX2
#include "core/accel/bvh/bvh_tri4.h"
#include "core/accel/bvh/bvh_triangle.h"

#ifdef ACCELVIZ_BVH_WIDE8_AVX2
#include <immintrin.h>

namespace accelviz::bvh_detail {

/// Bit l set: lane l of the pair holds a triangle.
[[gnu::always_inline]] inline int tri8_used_lanes(const TriBlock4* b) {
  return tri4_used_lanes(b[0]) | (tri4_used_lanes(b[1]) << 4);
}

using Tri8Result = TriLanesResult<8>;
using Tri8MtResult = TriLanesMtResult<8>;

[[gnu::target("avx2"), gnu::always_inline]] inline int lanes_mask(Lanes<8>::I m) {
  return _mm256_movemask_ps(reinterpret_cast<__m256>(m));
}

/// intersect_tri4 on the two blocks b[0], b[1] for the ray whose watertight
/// constants are `r` (broadcast here: no per-ray 256-bit state).
[[gnu::target("avx2"), gnu::always_inline]] inline void intersect_tri8(const TriBlock4* b, const InlineWatertightRay& r,
                                                                       float tmin, Tri8Result& out) {
  const TriLanesRay<8> r8(r);
  WatertightLanes<Lanes<8>::F> w;
  tri_lanes_edges<8>(b, r8, w);
  if (lanes_mask(w.ok | w.special) == 0) return set_lanes(out, 0, 0, 0);  // as intersect_tri4
  tri_lanes_distance<8>(r8, tmin, w, out);
  set_lanes(out, lanes_mask(w.special), lanes_mask(w.late), lanes_mask(w.ok));
}

/// intersect_tri4_mt on the two blocks b[0], b[1] for ray `ray`.
[[gnu::target("avx2"), gnu::always_inline]] inline void intersect_tri8_mt(const TriBlock4* b, const Ray& ray,
                                                                          float tmin, Tri8MtResult& out) {
  Lanes<8>::I ok;
  tri_lanes_mt<8>(b, TriLanesMtRay<8>(ray), tmin, out, ok);
  out.candidate = lanes_mask(ok);
}

}  // namespace accelviz::bvh_detail

#endif  // ACCELVIZ_BVH_WIDE8_AVX2
