#pragma once
// Four triangles per SIMD test: the leaves of the 4-wide BVH keep their
// triangles as blocks of four in structure-of-arrays order (Embree's
// "triangle4" idea), and the watertight test (Woop et al. 2013) and
// Moller-Trumbore run on the four lanes at once with SSE2. The lane tests
// are written once for any width of GCC vector (watertight_lanes_edges,
// watertight_lanes_distance, mt_lanes): four triangles against one ray here,
// eight (two blocks, AVX2) in bvh_tri8.h, and one triangle against a packet
// of eight rays in bvh_packet_traverse.inl.
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

/// The lane tests' arithmetic, written once for any GCC float vector F: the
/// single-ray tests below (one ray against N triangles, the ray's figures
/// broadcast) and the packet walk's (bvh_packet_traverse.inl: one triangle
/// against eight rays, the triangle's coordinates broadcast) fill the same
/// inputs, so each lane performs the scalar test's operations in its order
/// either way. Inputs and outputs go by reference: a 256-bit vector is not
/// passed by value in code compiled without AVX.
template <class F>
using LaneMask = decltype(F{} < F{});

/// Three vectors: x, y and z of N points (or of one point, broadcast).
template <class F>
struct Vec3Lanes {
  F x, y, z;
};

/// The watertight test's state between its two stages, as lane masks.
template <class F>
struct WatertightLanes {
  F Az, Bz, Cz, U, V, W, det;
  LaneMask<F> special, ok, late;
};

/// Stage one of the watertight test: the edge functions U, V, W, det, the
/// lanes inside (`ok`) and the special ones (a zero edge function, det not
/// finite), as triangle.cpp computes them, in its order. A, B, C are the
/// vertices and o the origin, each in the ray's axis order (kx, ky, kz);
/// sx, sy the shear.
template <class F>
[[gnu::always_inline]] inline void watertight_lanes_edges(const Vec3Lanes<F>& A, const Vec3Lanes<F>& B,
                                                          const Vec3Lanes<F>& C, const Vec3Lanes<F>& o, const F& sx,
                                                          const F& sy, WatertightLanes<F>& w) {
  const F Ax = A.x - o.x, Ay = A.y - o.y;
  const F Bx = B.x - o.x, By = B.y - o.y;
  const F Cx = C.x - o.x, Cy = C.y - o.y;
  w.Az = A.z - o.z, w.Bz = B.z - o.z, w.Cz = C.z - o.z;
  const F ax = Ax - sx * w.Az, ay = Ay - sy * w.Az;
  const F bx = Bx - sx * w.Bz, by = By - sy * w.Bz;
  const F cx = Cx - sx * w.Cz, cy = Cy - sy * w.Cz;
  w.U = cx * by - cy * bx;
  w.V = ax * cy - ay * cx;
  w.W = bx * ay - by * ax;
  w.det = (w.U + w.V) + w.W;
  // det - det is 0 for a finite det, NaN for inf/NaN (which compares false).
  w.special = (w.U == 0.0f) | (w.V == 0.0f) | (w.W == 0.0f) | ~((w.det - w.det) == 0.0f);
  const LaneMask<F> any_neg = (w.U < 0.0f) | (w.V < 0.0f) | (w.W < 0.0f);
  const LaneMask<F> any_pos = (w.U > 0.0f) | (w.V > 0.0f) | (w.W > 0.0f);
  w.ok = ~(any_neg & any_pos) & (w.det != 0.0f);
}

/// The figures of a triangle test per lane (watertight: all five; Moller-
/// Trumbore: t, u, v).
template <class F>
struct LaneFigures {
  F T, det, t, u, v;
};

/// Stage two, for lanes inside or special: the distance T, the late special
/// lanes (tiny det, T not finite or tiny), the tmin side of the scaled
/// compare and t >= tmin (in w.ok), and the figures into `out`.
template <class F>
[[gnu::always_inline]] inline void watertight_lanes_distance(const F& sz, const F& tmin, WatertightLanes<F>& w,
                                                             LaneFigures<F>& out) {
  using I = LaneMask<F>;
  const I abs_mask = I{} + 0x7FFFFFFF;
  const I tiny_det = w.ok & (reinterpret_cast<F>(reinterpret_cast<I>(w.det) & abs_mask) < kWatertightLowRange);
  const F az = sz * w.Az, bz = sz * w.Bz, cz = sz * w.Cz;
  const F T = (w.U * az + w.V * bz) + w.W * cz;
  const F absT = reinterpret_cast<F>(reinterpret_cast<I>(T) & abs_mask);
  const I bad_T = ~((T - T) == 0.0f) | ((absT < kWatertightLowRange) & (T != 0.0f));
  const I special_late = ~tiny_det & (w.ok & bad_T);
  w.late = tiny_det | special_late;
  w.ok = ~w.late & w.ok;
  // tmin side of the scaled compare: det > 0: T >= tmin·det; det < 0: T <= tmin·det.
  const F tmin_det = tmin * w.det;
  const I pos = w.det > 0.0f;
  w.ok &= (pos & (T >= tmin_det)) | (~pos & (T <= tmin_det));
  const F rcp = (F{} + 1.0f) / w.det;
  out.T = T;
  out.det = w.det;
  out.t = T * rcp;
  w.ok &= out.t >= tmin;
  out.u = w.V * rcp;
  out.v = w.W * rcp;
}

/// intersect_moller_trumbore_inline (core/geometry/triangle_inline.h) per
/// lane: the same operations in the same order (glm::cross, glm::dot as
/// (x + y) + z, one IEEE division), so each lane's t, u, v and outcome are
/// bit for bit the scalar test's (the core library never contracts to
/// FMA). p0, p1, p2 are the vertices, o and d the ray. t, u, v go to `out`,
/// the candidate lanes to `ok` (a lane is a hit when it is a candidate and
/// t <= tmax, the scalar test's last check; NaN compares false in both, so a
/// NaN u or v passes and a NaN t fails in both).
template <class F>
[[gnu::always_inline]] inline void mt_lanes(const Vec3Lanes<F>& p0, const Vec3Lanes<F>& p1, const Vec3Lanes<F>& p2,
                                            const Vec3Lanes<F>& o, const Vec3Lanes<F>& d, const F& tmin,
                                            LaneFigures<F>& out, LaneMask<F>& ok) {
  const F e1x = p1.x - p0.x, e1y = p1.y - p0.y, e1z = p1.z - p0.z;
  const F e2x = p2.x - p0.x, e2y = p2.y - p0.y, e2z = p2.z - p0.z;
  // p = cross(d, e2)
  const F px = d.y * e2z - e2y * d.z;
  const F py = d.z * e2x - e2z * d.x;
  const F pz = d.x * e2y - e2x * d.y;
  const F det = (e1x * px + e1y * py) + e1z * pz;
  const F inv = (F{} + 1.0f) / det;
  const F sx = o.x - p0.x, sy = o.y - p0.y, sz = o.z - p0.z;
  const F u = ((sx * px + sy * py) + sz * pz) * inv;
  // q = cross(s, e1)
  const F qx = sy * e1z - e1y * sz;
  const F qy = sz * e1x - e1z * sx;
  const F qz = sx * e1y - e1x * sy;
  const F v = ((d.x * qx + d.y * qy) + d.z * qz) * inv;
  const F t = ((e2x * qx + e2y * qy) + e2z * qz) * inv;
  const LaneMask<F> reject = (((det == 0.0f) | (u < 0.0f)) | (u > 1.0f)) | ((v < 0.0f) | ((u + v) > 1.0f));
  ok = ~reject & (t >= tmin);
  out.t = t;
  out.u = u;
  out.v = v;
}

/// A result's lanes from the stages' masks, as movemask bits (each width has
/// its own movemask): a special lane is only special; a late special one
/// (watertight_lanes_distance) too; the rest of `ok` are candidates.
template <class Result>
[[gnu::always_inline]] inline void set_lanes(Result& out, int special, int late, int ok) {
  out.special = special | (late & ~special);
  out.candidate = ok & ~special;
}

#ifdef ACCELVIZ_BVH_TRI4_SSE2

/// Lanes of x that are finite (the 8-wide box test's ray set-up uses it).
[[gnu::always_inline]] inline __m128 finite_mask(__m128 x) {
  // x - x is 0 for finite x, NaN for inf/NaN; (0 == 0) true, NaN compares false.
  return _mm_cmpeq_ps(_mm_sub_ps(x, x), _mm_setzero_ps());
}

/// N float lanes and N int32 masks (-1 true, 0 false) as GCC vector
/// extensions: N = 4 is one SSE register, N = 8 one AVX register (used only
/// inside AVX2 functions, bvh_tri8.h). The lane tests below are written once
/// for both widths; their operations are IEEE like the scalar ones.
template <int N>
struct Lanes;
template <>
struct Lanes<4> {
  typedef float F __attribute__((vector_size(16)));
  typedef std::int32_t I __attribute__((vector_size(16)));
};
template <>
struct Lanes<8> {
  typedef float F __attribute__((vector_size(32)));
  typedef std::int32_t I __attribute__((vector_size(32)));
};

/// Row `row` of the N / 4 consecutive blocks b[0..N/4) (lanes 0-3 from
/// b[0], 4-7 from b[1]), written to `out` (a 256-bit value is not returned
/// from a function that is not compiled for AVX).
template <int N>
[[gnu::always_inline]] inline void lane_row(const TriBlock4* b, int row, typename Lanes<N>::F& out) {
  static_assert(N == 4 || N == 8);
  __builtin_memcpy(&out, b[0].v[row], sizeof(b[0].v[row]));
  if constexpr (N == 8) __builtin_memcpy(reinterpret_cast<char*>(&out) + 16, b[1].v[row], sizeof(b[1].v[row]));
}

/// Per-ray constants of the N-lane watertight test.
template <int N>
struct TriLanesRay {
  using F = typename Lanes<N>::F;
  Vec3Lanes<F> o;  ///< origin[kx], [ky], [kz]
  F sx, sy, sz;
  int kx = 0, ky = 1, kz = 2;
  TriLanesRay() = default;  ///< unset; assign before use
  [[gnu::always_inline]] explicit TriLanesRay(const InlineWatertightRay& r)
      : o{F{} + r.ox, F{} + r.oy, F{} + r.oz},
        sx(F{} + r.wr.sx),
        sy(F{} + r.wr.sy),
        sz(F{} + r.wr.sz),
        kx(r.wr.kx),
        ky(r.wr.ky),
        kz(r.wr.kz) {}
};
using Tri4Ray = TriLanesRay<4>;

/// The tmax-independent part of the watertight test on N lanes.
template <int N>
struct TriLanesResult {
  alignas(4 * N) float T[N], det[N], t[N], u[N], v[N];
  int candidate = 0;  ///< lanes inside, det != 0, and t >= tmin with t finite (tmax not yet applied)
  int special = 0;    ///< lanes the scalar function must answer
};
using Tri4Result = TriLanesResult<4>;

/// The vertices of the N / 4 blocks b[0..N/4) in the ray's axis order
/// (kx, ky, kz), loaded straight from the blocks (the axes are per ray: an
/// array of all nine rows indexed by them would go through the stack).
template <int N>
[[gnu::always_inline]] inline void lane_vertices(const TriBlock4* b, int kx, int ky, int kz,
                                                 Vec3Lanes<typename Lanes<N>::F> (&p)[3]) {
  for (int k = 0; k < 3; ++k) {
    lane_row<N>(b, 3 * k + kx, p[k].x);
    lane_row<N>(b, 3 * k + ky, p[k].y);
    lane_row<N>(b, 3 * k + kz, p[k].z);
  }
}

/// Stage one of the watertight test on the N lanes of b (watertight_lanes_edges).
template <int N>
[[gnu::always_inline]] inline void tri_lanes_edges(const TriBlock4* b, const TriLanesRay<N>& r,
                                                   WatertightLanes<typename Lanes<N>::F>& w) {
  Vec3Lanes<typename Lanes<N>::F> p[3];
  lane_vertices<N>(b, r.kx, r.ky, r.kz, p);
  watertight_lanes_edges(p[0], p[1], p[2], r.o, r.sx, r.sy, w);
}

/// Stage two on N lanes (watertight_lanes_distance), the figures into `out`.
template <int N>
[[gnu::always_inline]] inline void tri_lanes_distance(const TriLanesRay<N>& r, float tmin,
                                                      WatertightLanes<typename Lanes<N>::F>& w,
                                                      TriLanesResult<N>& out) {
  using F = typename Lanes<N>::F;
  LaneFigures<F> f;
  watertight_lanes_distance(r.sz, F{} + tmin, w, f);
  __builtin_memcpy(out.T, &f.T, sizeof f.T);
  __builtin_memcpy(out.det, &f.det, sizeof f.det);
  __builtin_memcpy(out.t, &f.t, sizeof f.t);
  __builtin_memcpy(out.u, &f.u, sizeof f.u);
  __builtin_memcpy(out.v, &f.v, sizeof f.v);
}

/// Per-ray constants of the N-lane Moller-Trumbore test.
template <int N>
struct TriLanesMtRay {
  using F = typename Lanes<N>::F;
  Vec3Lanes<F> o, d;
  TriLanesMtRay() = default;  ///< unset; assign before use
  [[gnu::always_inline]] explicit TriLanesMtRay(const Ray& r)
      : o{F{} + r.origin.x, F{} + r.origin.y, F{} + r.origin.z},
        d{F{} + r.direction.x, F{} + r.direction.y, F{} + r.direction.z} {}
};
using Tri4MtRay = TriLanesMtRay<4>;

/// The tmax-independent part of the Moller-Trumbore test on N lanes.
template <int N>
struct TriLanesMtResult {
  alignas(4 * N) float t[N], u[N], v[N];
  int candidate = 0;  ///< lanes with det != 0, u, v inside and t >= tmin (tmax not yet applied)
};
using Tri4MtResult = TriLanesMtResult<4>;

/// The Moller-Trumbore test (mt_lanes) on the N lanes of b: the figures to
/// `out`, the candidate lanes to `ok`.
template <int N>
[[gnu::always_inline]] inline void tri_lanes_mt(const TriBlock4* b, const TriLanesMtRay<N>& r, float tmin,
                                                TriLanesMtResult<N>& out, typename Lanes<N>::I& ok) {
  using F = typename Lanes<N>::F;
  Vec3Lanes<F> p[3];
  lane_vertices<N>(b, 0, 1, 2, p);
  LaneFigures<F> f;
  mt_lanes(p[0], p[1], p[2], r.o, r.d, F{} + tmin, f, ok);
  __builtin_memcpy(out.t, &f.t, sizeof f.t);
  __builtin_memcpy(out.u, &f.u, sizeof f.u);
  __builtin_memcpy(out.v, &f.v, sizeof f.v);
}

[[gnu::always_inline]] inline int lanes_mask(Lanes<4>::I m) {
  return _mm_movemask_ps(reinterpret_cast<__m128>(m));
}

/// The watertight test on the four lanes of block b (tri_lanes_edges, then
/// tri_lanes_distance unless no lane is inside or special).
[[gnu::always_inline]] inline void intersect_tri4(const TriBlock4& b, const Tri4Ray& r, float tmin, Tri4Result& out) {
  WatertightLanes<Lanes<4>::F> w;
  tri_lanes_edges<4>(&b, r, w);
  // No lane inside and none special: nothing below can make a lane a
  // candidate or special (both need `ok` or `special`), so stop here.
  if (lanes_mask(w.ok | w.special) == 0) return set_lanes(out, 0, 0, 0);
  tri_lanes_distance<4>(r, tmin, w, out);
  set_lanes(out, lanes_mask(w.special), lanes_mask(w.late), lanes_mask(w.ok));
}

/// The Moller-Trumbore test on the four lanes of block b.
[[gnu::always_inline]] inline void intersect_tri4_mt(const TriBlock4& b, const Tri4MtRay& r, float tmin,
                                                     Tri4MtResult& out) {
  Lanes<4>::I ok;
  tri_lanes_mt<4>(&b, r, tmin, out, ok);
  out.candidate = lanes_mask(ok);
}

/// The scalar test's tmax-dependent acceptance of candidate lane l.
[[gnu::always_inline]] inline bool tri4_accept(const Tri4Result& r, int l, float tmax) {
  return watertight_accept_tmax(r.det[l], r.T[l], r.t[l], tmax);
}

#endif  // ACCELVIZ_BVH_TRI4_SSE2

}  // namespace accelviz::bvh_detail
