#pragma once
// Four triangles per SIMD test: the leaves of the 4-wide BVH keep their
// triangles as blocks of four in structure-of-arrays order (Embree's
// "triangle4" idea), and the watertight test (Woop et al. 2013) runs on the
// four lanes at once with SSE2.
//
// Exactness: each lane performs the float operations of
// core/geometry/triangle.cpp's intersect_watertight in the same order (SSE2
// add/sub/mul/div are IEEE like their scalar forms; no FMA), so a lane's
// U, V, W, det, T and t are bit for bit the scalar ones. Lanes that take one
// of the scalar test's special paths (an edge function of zero, overflow,
// tiny values) are answered by the scalar function itself. The tmax-dependent
// acceptance (scaled interval compare, t <= tmax) is then redone per hit lane
// in slot order against the closest hit so far, exactly as the scalar loop
// over the leaf would, so the traversal's answers do not change.
#include <cstdint>
#include <span>
#include <vector>

#include "core/accel/bvh/bvh_triangle.h"

#if defined(__SSE2__) && !defined(ACCELVIZ_NO_SIMD)
#include <emmintrin.h>
#define ACCELVIZ_BVH_TRI4_SSE2 1
#endif

namespace accelviz::bvh_detail {

/// 160 bytes: rows v[3·vertex + axis][lane], and the leaf-order position of
/// each lane's triangle (kTri4Empty: padding lane).
struct alignas(16) TriBlock4 {
  float v[9][4];
  std::uint32_t pos[4];
};
static_assert(sizeof(TriBlock4) == 160);

inline constexpr std::uint32_t kTri4Empty = 0xFFFFFFFFu;

/// Number of blocks that hold `count` triangles.
constexpr std::uint32_t tri4_block_count(std::uint32_t count) {
  return (count + 3) / 4;
}

/// Writes the tri4_block_count(count) blocks for leaf positions
/// [first, first + count) to out[0..]: `tri(k)` is the triangle at leaf
/// position k. Leaves write disjoint block ranges, so class Bvh fills them on
/// all build threads.
template <class TriAt>
void fill_tri4_blocks(const TriAt& tri, std::uint32_t first, std::uint32_t count, TriBlock4* out) {
  for (std::uint32_t b = 0; b < count; b += 4) {
    TriBlock4 blk{};
    for (std::uint32_t l = 0; l < 4; ++l) {
      const bool used = b + l < count;
      // Padding lanes repeat the block's first triangle (finite values) and are masked out.
      const Triangle& t = tri(first + b + (used ? l : 0));
      const glm::vec3* vs[3] = {&t.v0, &t.v1, &t.v2};
      for (int k = 0; k < 3; ++k)
        for (int a = 0; a < 3; ++a) blk.v[3 * k + a][l] = (&vs[k]->x)[a];
      blk.pos[l] = used ? first + b + l : kTri4Empty;
    }
    out[b / 4] = blk;
  }
}

/// fill_tri4_blocks appended to `out` (a vector of TriBlock4); returns the
/// index of the first block.
template <class TriAt, class Blocks>
std::uint32_t append_tri4_blocks(const TriAt& tri, std::uint32_t first, std::uint32_t count, Blocks& out) {
  const auto start = static_cast<std::uint32_t>(out.size());
  out.resize(start + tri4_block_count(count));
  fill_tri4_blocks(tri, first, count, out.data() + start);
  return start;
}

/// The triangle in lane `l` of a block (the floats it was built from).
[[gnu::always_inline]] inline Triangle tri4_triangle(const TriBlock4& b, std::uint32_t l) {
  return Triangle{
      {b.v[0][l], b.v[1][l], b.v[2][l]}, {b.v[3][l], b.v[4][l], b.v[5][l]}, {b.v[6][l], b.v[7][l], b.v[8][l]}};
}

/// Bit l set: lane l holds a triangle (not padding).
[[gnu::always_inline]] inline int tri4_used_lanes(const TriBlock4& b) {
#ifdef ACCELVIZ_BVH_TRI4_SSE2
  const __m128i pos = _mm_load_si128(reinterpret_cast<const __m128i*>(b.pos));
  return 0xF & ~_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(pos, _mm_set1_epi32(-1))));
#else
  int used = 0;
  for (int l = 0; l < 4; ++l) used |= (b.pos[l] != kTri4Empty ? 1 : 0) << l;
  return used;
#endif
}

/// Copies the triangles at the blocks' positions again (after a refit):
/// `tri(k)` is the triangle now at leaf position k.
template <class TriAt, class Blocks>
void refit_tri4_blocks(const TriAt& tri, Blocks& blocks) {
  for (TriBlock4& blk : blocks)
    for (std::uint32_t l = 0; l < 4; ++l) {
      const std::uint32_t p = blk.pos[l] != kTri4Empty ? blk.pos[l] : blk.pos[0];
      const Triangle& t = tri(p);
      const glm::vec3* vs[3] = {&t.v0, &t.v1, &t.v2};
      for (int k = 0; k < 3; ++k)
        for (int a = 0; a < 3; ++a) blk.v[3 * k + a][l] = (&vs[k]->x)[a];
    }
}

/// The watertight test's tmax-dependent acceptance of a candidate from its
/// figures (det, T, t = T/det), as the scalar test applies it last: the
/// four-lane test's lanes (tri4_accept) and the packet walk's lanes
/// (bvh_packet_traverse.inl) replay it per candidate in leaf order.
[[gnu::always_inline]] inline bool watertight_accept_tmax(float det, float T, float t, float tmax) {
  if (det > 0.0f ? T > tmax * det : T < tmax * det) return false;
  return t <= tmax;
}

#ifdef ACCELVIZ_BVH_TRI4_SSE2

/// Per-ray constants of the four-lane test.
struct Tri4Ray {
  __m128 ox, oy, oz, sx, sy, sz;
  int kx = 0, ky = 1, kz = 2;
  Tri4Ray() = default;  ///< unset; assign before use
  explicit Tri4Ray(const InlineWatertightRay& r)
      : ox(_mm_set1_ps(r.ox)),
        oy(_mm_set1_ps(r.oy)),
        oz(_mm_set1_ps(r.oz)),
        sx(_mm_set1_ps(r.wr.sx)),
        sy(_mm_set1_ps(r.wr.sy)),
        sz(_mm_set1_ps(r.wr.sz)),
        kx(r.wr.kx),
        ky(r.wr.ky),
        kz(r.wr.kz) {}
};

/// The tmax-independent part of the watertight test on four lanes.
struct Tri4Result {
  alignas(16) float T[4], det[4], t[4], u[4], v[4];
  int candidate = 0;  ///< lanes inside, det != 0, and t >= tmin with t finite (tmax not yet applied)
  int special = 0;    ///< lanes the scalar function must answer
};

[[gnu::always_inline]] inline __m128 finite_mask(__m128 x) {
  // x - x is 0 for finite x, NaN for inf/NaN; (0 == 0) true, NaN compares false.
  return _mm_cmpeq_ps(_mm_sub_ps(x, x), _mm_setzero_ps());
}

[[gnu::always_inline]] inline void intersect_tri4(const TriBlock4& b, const Tri4Ray& r, float tmin, Tri4Result& out) {
  const __m128 zero = _mm_setzero_ps();
  const __m128 Ax = _mm_sub_ps(_mm_load_ps(b.v[0 + r.kx]), r.ox), Ay = _mm_sub_ps(_mm_load_ps(b.v[0 + r.ky]), r.oy),
               Az = _mm_sub_ps(_mm_load_ps(b.v[0 + r.kz]), r.oz);
  const __m128 Bx = _mm_sub_ps(_mm_load_ps(b.v[3 + r.kx]), r.ox), By = _mm_sub_ps(_mm_load_ps(b.v[3 + r.ky]), r.oy),
               Bz = _mm_sub_ps(_mm_load_ps(b.v[3 + r.kz]), r.oz);
  const __m128 Cx = _mm_sub_ps(_mm_load_ps(b.v[6 + r.kx]), r.ox), Cy = _mm_sub_ps(_mm_load_ps(b.v[6 + r.ky]), r.oy),
               Cz = _mm_sub_ps(_mm_load_ps(b.v[6 + r.kz]), r.oz);
  const __m128 ax = _mm_sub_ps(Ax, _mm_mul_ps(r.sx, Az)), ay = _mm_sub_ps(Ay, _mm_mul_ps(r.sy, Az));
  const __m128 bx = _mm_sub_ps(Bx, _mm_mul_ps(r.sx, Bz)), by = _mm_sub_ps(By, _mm_mul_ps(r.sy, Bz));
  const __m128 cx = _mm_sub_ps(Cx, _mm_mul_ps(r.sx, Cz)), cy = _mm_sub_ps(Cy, _mm_mul_ps(r.sy, Cz));
  const __m128 U = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
  const __m128 V = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
  const __m128 W = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
  const __m128 det = _mm_add_ps(_mm_add_ps(U, V), W);
  // Special: a zero edge function, or U + V + W not finite (as triangle.cpp's checks, in its order).
  __m128 special = _mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(U, zero), _mm_cmpeq_ps(V, zero)), _mm_cmpeq_ps(W, zero));
  special = _mm_or_ps(special, _mm_andnot_ps(finite_mask(det), _mm_castsi128_ps(_mm_set1_epi32(-1))));
  const __m128 any_neg = _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(U, zero), _mm_cmplt_ps(V, zero)), _mm_cmplt_ps(W, zero));
  const __m128 any_pos = _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(U, zero), _mm_cmpgt_ps(V, zero)), _mm_cmpgt_ps(W, zero));
  __m128 ok = _mm_andnot_ps(_mm_and_ps(any_neg, any_pos), _mm_cmpneq_ps(det, zero));
  // No lane inside and none special: nothing below can make a lane a
  // candidate or special (both need `ok` or `special`), so stop here.
  if (_mm_movemask_ps(_mm_or_ps(ok, special)) == 0) {
    out.special = 0;
    out.candidate = 0;
    return;
  }
  // |det| < 1e-30: special (only for lanes still in the game, as the scalar order has it).
  const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF));
  const __m128 low = _mm_set1_ps(1e-30f);
  const __m128 tiny_det = _mm_and_ps(ok, _mm_cmplt_ps(_mm_and_ps(det, abs_mask), low));
  const __m128 az = _mm_mul_ps(r.sz, Az), bz = _mm_mul_ps(r.sz, Bz), cz = _mm_mul_ps(r.sz, Cz);
  const __m128 T = _mm_add_ps(_mm_add_ps(_mm_mul_ps(U, az), _mm_mul_ps(V, bz)), _mm_mul_ps(W, cz));
  const __m128 absT = _mm_and_ps(T, abs_mask);
  const __m128 bad_T = _mm_or_ps(_mm_andnot_ps(finite_mask(T), _mm_castsi128_ps(_mm_set1_epi32(-1))),
                                 _mm_and_ps(_mm_cmplt_ps(absT, low), _mm_cmpneq_ps(T, zero)));
  const __m128 special_late = _mm_andnot_ps(tiny_det, _mm_and_ps(ok, bad_T));
  const __m128 late = _mm_or_ps(tiny_det, special_late);
  ok = _mm_andnot_ps(late, ok);
  // tmin side of the scaled compare: det > 0: T >= tmin·det; det < 0: T <= tmin·det.
  const __m128 tmin_det = _mm_mul_ps(_mm_set1_ps(tmin), det);
  const __m128 pos = _mm_cmpgt_ps(det, zero);
  const __m128 tmin_ok =
      _mm_or_ps(_mm_and_ps(pos, _mm_cmpge_ps(T, tmin_det)), _mm_andnot_ps(pos, _mm_cmple_ps(T, tmin_det)));
  ok = _mm_and_ps(ok, tmin_ok);
  const __m128 rcp = _mm_div_ps(_mm_set1_ps(1.0f), det);
  const __m128 t = _mm_mul_ps(T, rcp);
  ok = _mm_and_ps(ok, _mm_cmpge_ps(t, _mm_set1_ps(tmin)));
  _mm_store_ps(out.T, T);
  _mm_store_ps(out.det, det);
  _mm_store_ps(out.t, t);
  _mm_store_ps(out.u, _mm_mul_ps(V, rcp));
  _mm_store_ps(out.v, _mm_mul_ps(W, rcp));
  const int sp = _mm_movemask_ps(special);
  out.special = sp | (_mm_movemask_ps(late) & ~sp);
  out.candidate = _mm_movemask_ps(ok) & ~sp;
}

/// Per-ray constants of the four-lane Moller-Trumbore test.
struct Tri4MtRay {
  __m128 ox, oy, oz, dx, dy, dz;
  Tri4MtRay() = default;  ///< unset; assign before use
  explicit Tri4MtRay(const Ray& r)
      : ox(_mm_set1_ps(r.origin.x)),
        oy(_mm_set1_ps(r.origin.y)),
        oz(_mm_set1_ps(r.origin.z)),
        dx(_mm_set1_ps(r.direction.x)),
        dy(_mm_set1_ps(r.direction.y)),
        dz(_mm_set1_ps(r.direction.z)) {}
};

/// The tmax-independent part of the Moller-Trumbore test on four lanes.
struct Tri4MtResult {
  alignas(16) float t[4], u[4], v[4];
  int candidate = 0;  ///< lanes with det != 0, u, v inside and t >= tmin (tmax not yet applied)
};

/// intersect_moller_trumbore_inline (core/geometry/triangle_inline.h) on the
/// four lanes of a block: the same operations in the same order (glm::cross,
/// glm::dot as (x + y) + z, one IEEE division), so each lane's t, u, v and
/// outcome are bit for bit the scalar test's (the core library never
/// contracts to FMA). A lane is a hit when it is a candidate and t <= tmax,
/// the scalar test's last check. NaN compares false in both, so a NaN u or v
/// passes and a NaN t fails in both.
[[gnu::always_inline]] inline void intersect_tri4_mt(const TriBlock4& b, const Tri4MtRay& r, float tmin,
                                                     Tri4MtResult& out) {
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
  const __m128 v0x = _mm_load_ps(b.v[0]), v0y = _mm_load_ps(b.v[1]), v0z = _mm_load_ps(b.v[2]);
  const __m128 e1x = _mm_sub_ps(_mm_load_ps(b.v[3]), v0x), e1y = _mm_sub_ps(_mm_load_ps(b.v[4]), v0y),
               e1z = _mm_sub_ps(_mm_load_ps(b.v[5]), v0z);
  const __m128 e2x = _mm_sub_ps(_mm_load_ps(b.v[6]), v0x), e2y = _mm_sub_ps(_mm_load_ps(b.v[7]), v0y),
               e2z = _mm_sub_ps(_mm_load_ps(b.v[8]), v0z);
  // p = cross(d, e2)
  const __m128 px = _mm_sub_ps(_mm_mul_ps(r.dy, e2z), _mm_mul_ps(e2y, r.dz));
  const __m128 py = _mm_sub_ps(_mm_mul_ps(r.dz, e2x), _mm_mul_ps(e2z, r.dx));
  const __m128 pz = _mm_sub_ps(_mm_mul_ps(r.dx, e2y), _mm_mul_ps(e2x, r.dy));
  const __m128 det = _mm_add_ps(_mm_add_ps(_mm_mul_ps(e1x, px), _mm_mul_ps(e1y, py)), _mm_mul_ps(e1z, pz));
  const __m128 inv = _mm_div_ps(one, det);
  const __m128 sx = _mm_sub_ps(r.ox, v0x), sy = _mm_sub_ps(r.oy, v0y), sz = _mm_sub_ps(r.oz, v0z);
  const __m128 u = _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(sx, px), _mm_mul_ps(sy, py)), _mm_mul_ps(sz, pz)), inv);
  // q = cross(s, e1)
  const __m128 qx = _mm_sub_ps(_mm_mul_ps(sy, e1z), _mm_mul_ps(e1y, sz));
  const __m128 qy = _mm_sub_ps(_mm_mul_ps(sz, e1x), _mm_mul_ps(e1z, sx));
  const __m128 qz = _mm_sub_ps(_mm_mul_ps(sx, e1y), _mm_mul_ps(e1x, sy));
  const __m128 v =
      _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(r.dx, qx), _mm_mul_ps(r.dy, qy)), _mm_mul_ps(r.dz, qz)), inv);
  const __m128 t =
      _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(e2x, qx), _mm_mul_ps(e2y, qy)), _mm_mul_ps(e2z, qz)), inv);
  const __m128 reject =
      _mm_or_ps(_mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(det, zero), _mm_cmplt_ps(u, zero)), _mm_cmpgt_ps(u, one)),
                _mm_or_ps(_mm_cmplt_ps(v, zero), _mm_cmpgt_ps(_mm_add_ps(u, v), one)));
  const __m128 ok = _mm_andnot_ps(reject, _mm_cmpge_ps(t, _mm_set1_ps(tmin)));
  _mm_store_ps(out.t, t);
  _mm_store_ps(out.u, u);
  _mm_store_ps(out.v, v);
  out.candidate = _mm_movemask_ps(ok);
}

/// The scalar test's tmax-dependent acceptance of candidate lane l.
[[gnu::always_inline]] inline bool tri4_accept(const Tri4Result& r, int l, float tmax) {
  return watertight_accept_tmax(r.det[l], r.T[l], r.t[l], tmax);
}

#endif  // ACCELVIZ_BVH_TRI4_SSE2

}  // namespace accelviz::bvh_detail
