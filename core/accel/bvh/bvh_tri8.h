#pragma once
// Two triangle blocks per test: the 8-wide walk (AVX2) runs the watertight
// and Moller-Trumbore tests of bvh_tri4.h on two consecutive blocks of a
// leaf slot at once, lanes 0-3 from the first block and 4-7 from the second
// (the leaf's triangles in order). Leaf slots of two or more blocks are
// common where the collapse merges binary leaves (BvhOptions::
// wide_merge_blocks) and in leaves of more than four triangles.
//
// Exactness: each lane performs the same float operations in the same order
// as the four-lane tests (AVX add/sub/mul/div are IEEE like their SSE forms;
// no FMA: the operations are written as separate intrinsics and core builds
// with -ffp-contract=off), so a lane's figures are bit for bit the
// four-lane ones and hence the scalar ones. The results keep the four-lane
// layout per half, so the callers replay the same acceptance per lane.
#include "core/accel/bvh/bvh_slab.h"  // ACCELVIZ_BVH_WIDE8_AVX2
#include "core/accel/bvh/bvh_tri4.h"
#include "core/accel/bvh/bvh_triangle.h"

#ifdef ACCELVIZ_BVH_WIDE8_AVX2
#include <immintrin.h>

namespace accelviz::bvh_detail {

/// Row `row` of blocks b[0] (lanes 0-3) and b[1] (lanes 4-7).
[[gnu::target("avx2"), gnu::always_inline]] inline __m256 tri8_row(const TriBlock4* b, int row) {
  return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(b[0].v[row])), _mm_load_ps(b[1].v[row]), 1);
}

/// Bit l set: lane l of the pair holds a triangle.
[[gnu::always_inline]] inline int tri8_used_lanes(const TriBlock4* b) {
  return tri4_used_lanes(b[0]) | (tri4_used_lanes(b[1]) << 4);
}

/// intersect_tri4's figures for lanes 0-7 (T, det, t, u, v) and masks.
struct Tri8Result {
  alignas(32) float T[8], det[8], t[8], u[8], v[8];
  int candidate = 0;  ///< as Tri4Result::candidate, eight lanes
  int special = 0;    ///< as Tri4Result::special, eight lanes
};

[[gnu::target("avx2"), gnu::always_inline]] inline __m256 finite_mask8(__m256 x) {
  return _mm256_cmp_ps(_mm256_sub_ps(x, x), _mm256_setzero_ps(), _CMP_EQ_OQ);
}

/// intersect_tri4 on the two blocks b[0], b[1] for the ray whose watertight
/// constants are `r` (broadcast here from memory: no per-ray 256-bit state).
[[gnu::target("avx2"), gnu::always_inline]] inline void intersect_tri8(const TriBlock4* b, const InlineWatertightRay& r,
                                                                       float tmin, Tri8Result& out) {
  const int kx = r.wr.kx, ky = r.wr.ky, kz = r.wr.kz;
  const __m256 zero = _mm256_setzero_ps();
  const __m256 ox = _mm256_broadcast_ss(&r.ox), oy = _mm256_broadcast_ss(&r.oy), oz = _mm256_broadcast_ss(&r.oz);
  const __m256 sx = _mm256_broadcast_ss(&r.wr.sx), sy = _mm256_broadcast_ss(&r.wr.sy);
  const __m256 Ax = _mm256_sub_ps(tri8_row(b, 0 + kx), ox), Ay = _mm256_sub_ps(tri8_row(b, 0 + ky), oy),
               Az = _mm256_sub_ps(tri8_row(b, 0 + kz), oz);
  const __m256 Bx = _mm256_sub_ps(tri8_row(b, 3 + kx), ox), By = _mm256_sub_ps(tri8_row(b, 3 + ky), oy),
               Bz = _mm256_sub_ps(tri8_row(b, 3 + kz), oz);
  const __m256 Cx = _mm256_sub_ps(tri8_row(b, 6 + kx), ox), Cy = _mm256_sub_ps(tri8_row(b, 6 + ky), oy),
               Cz = _mm256_sub_ps(tri8_row(b, 6 + kz), oz);
  const __m256 ax = _mm256_sub_ps(Ax, _mm256_mul_ps(sx, Az)), ay = _mm256_sub_ps(Ay, _mm256_mul_ps(sy, Az));
  const __m256 bx = _mm256_sub_ps(Bx, _mm256_mul_ps(sx, Bz)), by = _mm256_sub_ps(By, _mm256_mul_ps(sy, Bz));
  const __m256 cx = _mm256_sub_ps(Cx, _mm256_mul_ps(sx, Cz)), cy = _mm256_sub_ps(Cy, _mm256_mul_ps(sy, Cz));
  const __m256 U = _mm256_sub_ps(_mm256_mul_ps(cx, by), _mm256_mul_ps(cy, bx));
  const __m256 V = _mm256_sub_ps(_mm256_mul_ps(ax, cy), _mm256_mul_ps(ay, cx));
  const __m256 W = _mm256_sub_ps(_mm256_mul_ps(bx, ay), _mm256_mul_ps(by, ax));
  const __m256 det = _mm256_add_ps(_mm256_add_ps(U, V), W);
  const __m256 all = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
  __m256 special = _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(U, zero, _CMP_EQ_OQ), _mm256_cmp_ps(V, zero, _CMP_EQ_OQ)),
                                _mm256_cmp_ps(W, zero, _CMP_EQ_OQ));
  special = _mm256_or_ps(special, _mm256_andnot_ps(finite_mask8(det), all));
  const __m256 any_neg =
      _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(U, zero, _CMP_LT_OS), _mm256_cmp_ps(V, zero, _CMP_LT_OS)),
                   _mm256_cmp_ps(W, zero, _CMP_LT_OS));
  const __m256 any_pos =
      _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(U, zero, _CMP_GT_OS), _mm256_cmp_ps(V, zero, _CMP_GT_OS)),
                   _mm256_cmp_ps(W, zero, _CMP_GT_OS));
  __m256 ok = _mm256_andnot_ps(_mm256_and_ps(any_neg, any_pos), _mm256_cmp_ps(det, zero, _CMP_NEQ_UQ));
  if (_mm256_movemask_ps(_mm256_or_ps(ok, special)) == 0) {
    out.special = 0;
    out.candidate = 0;
    return;
  }
  const __m256 sz = _mm256_broadcast_ss(&r.wr.sz);
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF));
  const __m256 low = _mm256_set1_ps(1e-30f);
  const __m256 tiny_det = _mm256_and_ps(ok, _mm256_cmp_ps(_mm256_and_ps(det, abs_mask), low, _CMP_LT_OS));
  const __m256 az = _mm256_mul_ps(sz, Az), bz = _mm256_mul_ps(sz, Bz), cz = _mm256_mul_ps(sz, Cz);
  const __m256 T = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(U, az), _mm256_mul_ps(V, bz)), _mm256_mul_ps(W, cz));
  const __m256 absT = _mm256_and_ps(T, abs_mask);
  const __m256 bad_T =
      _mm256_or_ps(_mm256_andnot_ps(finite_mask8(T), all),
                   _mm256_and_ps(_mm256_cmp_ps(absT, low, _CMP_LT_OS), _mm256_cmp_ps(T, zero, _CMP_NEQ_UQ)));
  const __m256 special_late = _mm256_andnot_ps(tiny_det, _mm256_and_ps(ok, bad_T));
  const __m256 late = _mm256_or_ps(tiny_det, special_late);
  ok = _mm256_andnot_ps(late, ok);
  const __m256 vtmin = _mm256_set1_ps(tmin);
  const __m256 tmin_det = _mm256_mul_ps(vtmin, det);
  const __m256 pos = _mm256_cmp_ps(det, zero, _CMP_GT_OS);
  const __m256 tmin_ok = _mm256_or_ps(_mm256_and_ps(pos, _mm256_cmp_ps(T, tmin_det, _CMP_GE_OS)),
                                      _mm256_andnot_ps(pos, _mm256_cmp_ps(T, tmin_det, _CMP_LE_OS)));
  ok = _mm256_and_ps(ok, tmin_ok);
  const __m256 rcp = _mm256_div_ps(_mm256_set1_ps(1.0f), det);
  const __m256 t = _mm256_mul_ps(T, rcp);
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(t, vtmin, _CMP_GE_OS));
  _mm256_store_ps(out.T, T);
  _mm256_store_ps(out.det, det);
  _mm256_store_ps(out.t, t);
  _mm256_store_ps(out.u, _mm256_mul_ps(V, rcp));
  _mm256_store_ps(out.v, _mm256_mul_ps(W, rcp));
  const int sp = _mm256_movemask_ps(special);
  out.special = sp | (_mm256_movemask_ps(late) & ~sp);
  out.candidate = _mm256_movemask_ps(ok) & ~sp;
}

/// intersect_tri4_mt's figures for lanes 0-7.
struct Tri8MtResult {
  alignas(32) float t[8], u[8], v[8];
  int candidate = 0;  ///< as Tri4MtResult::candidate, eight lanes
};

/// intersect_tri4_mt on the two blocks b[0], b[1] for ray `ray`.
[[gnu::target("avx2"), gnu::always_inline]] inline void intersect_tri8_mt(const TriBlock4* b, const Ray& ray,
                                                                          float tmin, Tri8MtResult& out) {
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
  const __m256 dx = _mm256_broadcast_ss(&ray.direction.x), dy = _mm256_broadcast_ss(&ray.direction.y),
               dz = _mm256_broadcast_ss(&ray.direction.z);
  const __m256 v0x = tri8_row(b, 0), v0y = tri8_row(b, 1), v0z = tri8_row(b, 2);
  const __m256 e1x = _mm256_sub_ps(tri8_row(b, 3), v0x), e1y = _mm256_sub_ps(tri8_row(b, 4), v0y),
               e1z = _mm256_sub_ps(tri8_row(b, 5), v0z);
  const __m256 e2x = _mm256_sub_ps(tri8_row(b, 6), v0x), e2y = _mm256_sub_ps(tri8_row(b, 7), v0y),
               e2z = _mm256_sub_ps(tri8_row(b, 8), v0z);
  const __m256 px = _mm256_sub_ps(_mm256_mul_ps(dy, e2z), _mm256_mul_ps(e2y, dz));
  const __m256 py = _mm256_sub_ps(_mm256_mul_ps(dz, e2x), _mm256_mul_ps(e2z, dx));
  const __m256 pz = _mm256_sub_ps(_mm256_mul_ps(dx, e2y), _mm256_mul_ps(e2x, dy));
  const __m256 det =
      _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(e1x, px), _mm256_mul_ps(e1y, py)), _mm256_mul_ps(e1z, pz));
  const __m256 inv = _mm256_div_ps(one, det);
  const __m256 sx = _mm256_sub_ps(_mm256_broadcast_ss(&ray.origin.x), v0x),
               sy = _mm256_sub_ps(_mm256_broadcast_ss(&ray.origin.y), v0y),
               sz = _mm256_sub_ps(_mm256_broadcast_ss(&ray.origin.z), v0z);
  const __m256 u = _mm256_mul_ps(
      _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(sx, px), _mm256_mul_ps(sy, py)), _mm256_mul_ps(sz, pz)), inv);
  const __m256 qx = _mm256_sub_ps(_mm256_mul_ps(sy, e1z), _mm256_mul_ps(e1y, sz));
  const __m256 qy = _mm256_sub_ps(_mm256_mul_ps(sz, e1x), _mm256_mul_ps(e1z, sx));
  const __m256 qz = _mm256_sub_ps(_mm256_mul_ps(sx, e1y), _mm256_mul_ps(e1x, sy));
  const __m256 v = _mm256_mul_ps(
      _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, qx), _mm256_mul_ps(dy, qy)), _mm256_mul_ps(dz, qz)), inv);
  const __m256 t = _mm256_mul_ps(
      _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(e2x, qx), _mm256_mul_ps(e2y, qy)), _mm256_mul_ps(e2z, qz)), inv);
  const __m256 reject = _mm256_or_ps(
      _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(det, zero, _CMP_EQ_OQ), _mm256_cmp_ps(u, zero, _CMP_LT_OS)),
                   _mm256_cmp_ps(u, one, _CMP_GT_OS)),
      _mm256_or_ps(_mm256_cmp_ps(v, zero, _CMP_LT_OS), _mm256_cmp_ps(_mm256_add_ps(u, v), one, _CMP_GT_OS)));
  const __m256 ok = _mm256_andnot_ps(reject, _mm256_cmp_ps(t, _mm256_set1_ps(tmin), _CMP_GE_OS));
  _mm256_store_ps(out.t, t);
  _mm256_store_ps(out.u, u);
  _mm256_store_ps(out.v, v);
  out.candidate = _mm256_movemask_ps(ok);
}

}  // namespace accelviz::bvh_detail

#endif  // ACCELVIZ_BVH_WIDE8_AVX2
