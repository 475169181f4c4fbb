#pragma once
// The ray/box test of the BVH traversal, in two versions that give the same
// answers:
//  - slab_test_scalar: core/math/aabb.h's robust slab test as it is (Williams
//    et al. 2005; Ize 2013: sign-selected near/far planes, NaN from a ray in a
//    face plane ignored, exit distance padded by 1+2γ(3)). The reference.
//  - slab_test (SSE2, x86-64): the same operations on the three axes at once
//    in one 4-lane register. The scalar test spent ~35 instructions per box
//    (per-axis plane selection and register spills); this one ~20, which is
//    what brings single-ray traversal to about half of Embree's speed.
// tests/core/test_bvh_query.cpp checks that both agree on random and
// adversarial boxes and rays (±0 directions, origins on face planes, flat,
// empty and infinite boxes).
#include "core/accel/bvh/bvh.h"
#include "core/accel/bvh/bvh_wide.h"
#include "core/math/aabb.h"
#include "core/math/ray.h"

#if defined(__SSE2__) && !defined(ACCELVIZ_NO_SIMD)
#include <emmintrin.h>
#define ACCELVIZ_BVH_SLAB_SSE2 1
#endif

// The 8-wide test needs AVX2 (VEX 256-bit) code in a binary built for plain
// x86-64: GCC's target attribute compiles just those functions for AVX2, and
// the BVH calls them only when the CPU says it has AVX2 (and FMA: cpu_has_wide8).
#if defined(ACCELVIZ_BVH_SLAB_SSE2) && defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#include <immintrin.h>
#define ACCELVIZ_BVH_WIDE8_AVX2 1
#endif

#include <cstddef>
#include <limits>

namespace accelviz::bvh_detail {

/// Scalar twin: the project's robust slab test, unchanged.
inline bool slab_test_scalar(const BvhNode& node, const Ray& ray, float tmin, float tmax, float& t_entry,
                             float& t_exit) {
  SlabInterval iv;
  const bool hit = intersect_slab(node.bounds, ray.origin, ray.inv_dir, tmin, tmax, iv);
  t_entry = iv.t_entry;
  t_exit = iv.t_exit;
  return hit;
}

#ifdef ACCELVIZ_BVH_SLAB_SSE2

/// Per-ray constants, set up once per ray.
struct SlabRay {
  __m128 origin;    ///< (ox, oy, oz, 0)
  __m128 inv_dir;   ///< (1/dx, 1/dy, 1/dz, NaN): lane 3 always yields NaN, which the max/min ignore
  __m128 neg_mask;  ///< all ones on axes where inv_dir < 0 (hi is the near plane), as in intersect_slab

  SlabRay() = default;
  explicit SlabRay(const Ray& r)
      : origin(_mm_setr_ps(r.origin.x, r.origin.y, r.origin.z, 0.0f)),
        inv_dir(_mm_setr_ps(r.inv_dir.x, r.inv_dir.y, r.inv_dir.z, std::numeric_limits<float>::quiet_NaN())),
        neg_mask(_mm_cmplt_ps(inv_dir, _mm_setzero_ps())) {}
};

/// hi.xyz of a node with lane 3 (the node's index, read by the 16-byte load)
/// cleared to +0. Read as a float, an index below 2^23 is a denormal, and a
/// denormal operand of the subtraction below costs a microcode assist on
/// every box test: clearing it took a third off the counted heatmap walk on
/// the AMD EPYC of docs/performance.md. Lane 3 is discarded anyway (its
/// inv_dir lane is NaN, so it stays NaN, as before).
[[gnu::always_inline]] inline __m128 load_hi_xyz(const BvhNode& node) {
  return _mm_and_ps(_mm_loadu_ps(&node.bounds.hi.x), _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0)));
}

/// Takes a node, not a bare Aabb: the two 16-byte loads read lo.xyz+hi.x and
/// hi.xyz+index, which stay inside the 32-byte node.
[[gnu::always_inline]] inline bool slab_test(const BvhNode& node, const SlabRay& r, float tmin, float tmax,
                                             float& t_entry, float& t_exit) {
  const __m128 lo = _mm_loadu_ps(&node.bounds.lo.x);
  const __m128 hi = load_hi_xyz(node);
  // Swap lo and hi on the negative axes: near/far without comparisons.
  const __m128 swap = _mm_and_ps(_mm_xor_ps(lo, hi), r.neg_mask);
  const __m128 near_plane = _mm_xor_ps(lo, swap);
  const __m128 far_plane = _mm_xor_ps(hi, swap);
  const __m128 tn = _mm_mul_ps(_mm_sub_ps(near_plane, r.origin), r.inv_dir);
  const __m128 tf = _mm_mul_ps(_mm_mul_ps(_mm_sub_ps(far_plane, r.origin), r.inv_dir), _mm_set1_ps(kSlabExitScale));
  // maxps(a, b) = a > b ? a : b and minps(a, b) = a < b ? a : b: exactly the
  // scalar test's NaN-ignoring updates, one per lane; lane 3 (NaN) gives
  // tmin/tmax. Then the largest entry and smallest exit over the lanes.
  __m128 t0 = _mm_max_ps(tn, _mm_set1_ps(tmin));
  __m128 t1 = _mm_min_ps(tf, _mm_set1_ps(tmax));
  t0 = _mm_max_ps(t0, _mm_shuffle_ps(t0, t0, _MM_SHUFFLE(2, 3, 0, 1)));
  t1 = _mm_min_ps(t1, _mm_shuffle_ps(t1, t1, _MM_SHUFFLE(2, 3, 0, 1)));
  t0 = _mm_max_ss(t0, _mm_movehl_ps(t0, t0));
  t1 = _mm_min_ss(t1, _mm_movehl_ps(t1, t1));
  t_entry = _mm_cvtss_f32(t0);
  t_exit = _mm_cvtss_f32(t1);
  return t_entry <= t_exit;
}

/// Both children of an inner node at once (they are adjacent): the same
/// per-box arithmetic as slab_test, with the two horizontal reductions
/// interleaved so they share shuffles. Lane 0 of entry/exit: first child,
/// lane 1: second child.
[[gnu::always_inline]] inline void slab_pair_lanes(const BvhNode* children, const SlabRay& r, float tmin, float tmax,
                                                   __m128& entry, __m128& exit) {
  const __m128 scale = _mm_set1_ps(kSlabExitScale);
  const __m128 vmin = _mm_set1_ps(tmin), vmax = _mm_set1_ps(tmax);
  __m128 t0[2], t1[2];
  for (int c = 0; c < 2; ++c) {
    const __m128 lo = _mm_loadu_ps(&children[c].bounds.lo.x);
    const __m128 hi = load_hi_xyz(children[c]);
    const __m128 swap = _mm_and_ps(_mm_xor_ps(lo, hi), r.neg_mask);
    const __m128 tn = _mm_mul_ps(_mm_sub_ps(_mm_xor_ps(lo, swap), r.origin), r.inv_dir);
    const __m128 tf = _mm_mul_ps(_mm_mul_ps(_mm_sub_ps(_mm_xor_ps(hi, swap), r.origin), r.inv_dir), scale);
    t0[c] = _mm_max_ps(tn, vmin);
    t1[c] = _mm_min_ps(tf, vmax);
  }
  // (x0 x1 y0 y1) and (z0 z1 w0 w1) -> lane 0: child 0, lane 1: child 1.
  __m128 e = _mm_max_ps(_mm_unpacklo_ps(t0[0], t0[1]), _mm_unpackhi_ps(t0[0], t0[1]));
  __m128 x = _mm_min_ps(_mm_unpacklo_ps(t1[0], t1[1]), _mm_unpackhi_ps(t1[0], t1[1]));
  entry = _mm_max_ps(e, _mm_movehl_ps(e, e));
  exit = _mm_min_ps(x, _mm_movehl_ps(x, x));
}

/// slab_pair_lanes as a hit mask. Bit 0 of the result: first child hit,
/// bit 1: second child hit. Entry/exit distances in t_entry[2], t_exit[2].
[[gnu::always_inline]] inline int slab_test_pair(const BvhNode* children, const SlabRay& r, float tmin, float tmax,
                                                 float* t_entry, float* t_exit) {
  __m128 e, x;
  slab_pair_lanes(children, r, tmin, tmax, e, x);
  _mm_storel_pi(reinterpret_cast<__m64*>(t_entry), e);
  _mm_storel_pi(reinterpret_cast<__m64*>(t_exit), x);
  return _mm_movemask_ps(_mm_cmple_ps(e, x)) & 3;
}

/// slab_test_pair plus the culling of the counted walk, without a branch:
/// bits 0-1 of the result are slab_test_pair's (children whose box the ray
/// crosses in [tmin, tmax]), bits 2-3 those of them whose entry is not
/// beyond `cull_t` (!(t_entry > cull_t), the instrumented walk's test).
/// Entry distances in t_entry[2].
[[gnu::always_inline]] inline int slab_test_pair_cull(const BvhNode* children, const SlabRay& r, float tmin, float tmax,
                                                      float cull_t, float* t_entry) {
  __m128 e, x;
  slab_pair_lanes(children, r, tmin, tmax, e, x);
  _mm_storel_pi(reinterpret_cast<__m64*>(t_entry), e);
  const __m128 hit = _mm_cmple_ps(e, x);
  const __m128 kept = _mm_andnot_ps(_mm_cmpgt_ps(e, _mm_set1_ps(cull_t)), hit);
  return (_mm_movemask_ps(hit) & 3) | ((_mm_movemask_ps(kept) & 3) << 2);
}

/// Per-ray constants of the four-box test: origin and inverse direction
/// broadcast per axis, and which row of WideNode::bounds is near/far.
struct WideSlabRay {
  __m128 origin[3], inv_dir[3];
  int near_row[3], far_row[3];

  explicit WideSlabRay(const Ray& r) {
    for (int a = 0; a < 3; ++a) {
      origin[a] = _mm_set1_ps(r.origin[a]);
      inv_dir[a] = _mm_set1_ps(r.inv_dir[a]);
      const bool neg = r.inv_dir[a] < 0.0f;  // as intersect_slab: hi is near
      near_row[a] = neg ? 3 + a : a;
      far_row[a] = neg ? a : 3 + a;
    }
  }
};

/// Four boxes of a wide node at once, lane s = slot s, the axes in the same
/// order and with the same operations as intersect_slab, so each lane is bit
/// for bit the scalar result. Unused slots are masked out. Returns the hit
/// mask; entry (and exit) distances per slot in the arrays.
[[gnu::always_inline]] inline int wide_slab_test(const WideNode& node, const WideSlabRay& r, float tmin, float tmax,
                                                 float* t_entry, float* t_exit = nullptr) {
  const __m128 scale = _mm_set1_ps(kSlabExitScale);
  __m128 t0 = _mm_set1_ps(tmin), t1 = _mm_set1_ps(tmax);
  for (int a = 0; a < 3; ++a) {
    const __m128 tn = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.bounds[r.near_row[a]]), r.origin[a]), r.inv_dir[a]);
    const __m128 tf =
        _mm_mul_ps(_mm_mul_ps(_mm_sub_ps(_mm_load_ps(node.bounds[r.far_row[a]]), r.origin[a]), r.inv_dir[a]), scale);
    t0 = _mm_max_ps(tn, t0);
    t1 = _mm_min_ps(tf, t1);
  }
  _mm_storeu_ps(t_entry, t0);
  if (t_exit) _mm_storeu_ps(t_exit, t1);
  const __m128i empty = _mm_cmpeq_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(node.meta)),
                                        _mm_set1_epi32(static_cast<int>(kWideEmpty)));
  return _mm_movemask_ps(_mm_andnot_ps(_mm_castsi128_ps(empty), _mm_cmple_ps(t0, t1)));
}

#ifdef ACCELVIZ_BVH_WIDE8_AVX2

/// The fast box test's paddings (wide_slab_test8_fast): inv_dir's factor
/// 1 − 2⁻²¹, the relative part of the pad on origin · inv (four float units
/// in the last place) and the exit's pad in units in the last place. With
/// p = 2⁻²⁴, intersect_slab's entry is at least (plane − origin)·inv_dir
/// times (1 − p)² and its exit at most that times (1 + p)³(1 + 2γ(3)), about
/// 1 + 9p; the fused test's entry is at most that times (1 − 8p)(1 + p)²
/// and its exit at least (1 − 8p)(1 − p)²(1 + 24p), about 1 + 14p.
inline constexpr float kFastInvScale = 1.0f - 0x1p-21f;
inline constexpr float kFastOriginPad = 0x1p-22f;
inline constexpr int kFastExitUlps = 24;

/// Per-ray constants of the eight-box tests (WideSlabRay in 256-bit lanes).
struct WideSlabRay8 {
  const Ray* ray;  ///< wide_slab_test8 broadcasts its origin and inv_dir at each node (few rays take it)
  /// wide_slab_test8_fast's: a plane's distance is plane · inv − c in one
  /// fused multiply-subtract, inv = inv_dir · kFastInvScale, c = origin · inv
  /// rounded up past its error for the near planes (c_near) and down for
  /// the far ones (c_far).
  __m256 inv[3], c_near[3], c_far[3];
  __m256i lo;  ///< tmin + 0 (a −0 made +0: as an integer −0 is the smallest value)
  int near_row[3], far_row[3];
  /// wide_slab_test8_fast applies: both c finite (so origin and inv are: a
  /// product with an infinite or NaN factor is not finite), tmin >= 0 and
  /// tmax >= 0. False for a ray with a ±0 (or denormal) direction component,
  /// a non-finite or huge origin, a negative or NaN tmin or a negative or
  /// NaN tmax: those take wide_slab_test8.
  bool fast;

  [[gnu::target("avx2")]] explicit WideSlabRay8(const Ray& r) : ray(&r) {
    // On four lanes, branch-free (many rays visit two or three nodes: their
    // set-up counts): (ox, oy, oz, tmin) and (tmax, ix, iy, iz) as laid out in
    // Ray, the latter turned to (ix, iy, iz, tmax); finite_mask is
    // bvh_tri4.h's (via bvh_wide.h).
    static_assert(offsetof(Ray, tmin) == 12 && offsetof(Ray, tmax) == 28 && offsetof(Ray, inv_dir) == 32);
    const __m128 o4 = _mm_loadu_ps(&r.origin.x);
    const __m128 t4 = _mm_loadu_ps(&r.tmax);
    const __m128 i4 = _mm_mul_ps(_mm_shuffle_ps(t4, t4, _MM_SHUFFLE(0, 3, 2, 1)), _mm_set1_ps(kFastInvScale));
    // |c − origin · inv| <= 2⁻²⁴·|c| + 2⁻¹⁵⁰ (round to nearest, subnormals
    // included); the pad 2⁻²²·|c| + 2⁻¹⁴⁷ survives the rounding of c ± pad
    // with at least 2⁻¹⁴⁸ to spare, more than a distance intersect_slab
    // rounds to an exit of ±0: the fast test's exit for such a box (and for
    // a box whose far plane holds the origin) is > 0, never −0.
    const __m128 c = _mm_mul_ps(o4, i4);
    const __m128 abs_c = _mm_and_ps(c, _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF)));
    const __m128 pad = _mm_add_ps(_mm_mul_ps(abs_c, _mm_set1_ps(kFastOriginPad)), _mm_set1_ps(0x1p-147f));
    const __m128 c_up = _mm_add_ps(c, pad), c_down = _mm_sub_ps(c, pad);
    // Both c finite in one check: their difference is not finite when
    // either is not (or, harmlessly, when it overflows).
    const int finite = _mm_movemask_ps(finite_mask(_mm_sub_ps(c_up, c_down)));
    const int tmin_ok = _mm_movemask_ps(_mm_cmpge_ps(o4, _mm_setzero_ps()));  // lane 3: tmin >= 0 (false for NaN)
    const int tmax_ok = _mm_movemask_ps(_mm_cmpge_ps(t4, _mm_setzero_ps()));  // lane 0: tmax >= 0 (not NaN)
    fast = (finite & 7) == 7 && (tmin_ok & 8) != 0 && (tmax_ok & 1) != 0;
    alignas(16) float v[3][4];
    _mm_store_ps(v[0], i4);
    _mm_store_ps(v[1], c_up);
    _mm_store_ps(v[2], c_down);
    lo = _mm256_castps_si256(_mm256_set1_ps(r.tmin + 0.0f));
    for (int a = 0; a < 3; ++a) {
      inv[a] = _mm256_set1_ps(v[0][a]);
      c_near[a] = _mm256_set1_ps(v[1][a]);
      c_far[a] = _mm256_set1_ps(v[2][a]);
      const bool neg = r.inv_dir[a] < 0.0f;  // as intersect_slab: hi is near
      near_row[a] = neg ? 3 + a : a;
      far_row[a] = neg ? a : 3 + a;
    }
  }
};

/// Eight boxes of an 8-wide node at once: wide_slab_test's operations, in
/// its order, on 256-bit registers (no FMA: AVX2 without -mfma), so each lane
/// is bit for bit intersect_slab's result. _CMP_LE_OQ is cmpleps.
[[gnu::target("avx2"), gnu::always_inline]] inline int wide_slab_test8(const WideNode8& node, const WideSlabRay8& r,
                                                                       float tmin, float tmax, float* t_entry,
                                                                       float* t_exit = nullptr) {
  const __m256 scale = _mm256_set1_ps(kSlabExitScale);
  __m256 t0 = _mm256_set1_ps(tmin), t1 = _mm256_set1_ps(tmax);
  for (int a = 0; a < 3; ++a) {
    const __m256 origin = _mm256_set1_ps(r.ray->origin[a]), inv_dir = _mm256_set1_ps(r.ray->inv_dir[a]);
    const __m256 tn = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.bounds[r.near_row[a]]), origin), inv_dir);
    const __m256 tf =
        _mm256_mul_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.bounds[r.far_row[a]]), origin), inv_dir), scale);
    t0 = _mm256_max_ps(tn, t0);
    t1 = _mm256_min_ps(tf, t1);
  }
  _mm256_storeu_ps(t_entry, t0);
  if (t_exit) _mm256_storeu_ps(t_exit, t1);
  const __m256i empty = _mm256_cmpeq_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(node.meta)),
                                           _mm256_set1_epi32(static_cast<int>(kWideEmpty)));
  return _mm256_movemask_ps(_mm256_andnot_ps(_mm256_castsi256_ps(empty), _mm256_cmp_ps(t0, t1, _CMP_LE_OQ)));
}

/// The eight-box test of the single-ray walk for WideSlabRay8::fast rays,
/// with a shorter dependency chain than wide_slab_test8: the walk waits for
/// this chain at every node (it decides which node to load next), so its
/// latency, not its instruction count, sets the walk's pace (docs/
/// performance.md, "A shorter box test" and "A fused box test").
///  - Each plane's distance in one fused multiply-subtract, plane · inv − c
///    (Embree's form), instead of a subtraction and a multiplication. It is
///    made conservative against intersect_slab, not just close to it: inv
///    is inv_dir · (1 − 2⁻²¹), c = origin · inv is rounded up past its error
///    for the near planes and down for the far ones, and the exit is raised
///    by kFastExitUlps units in the last place (an integer add), so every
///    entry is at most intersect_slab's and every exit at least its (scaled
///    by 1 + 2γ(3)): it hits every box intersect_slab hits, and a few more
///    within a few ulps (or, for an origin far from the box compared with
///    the box's distance, within 2⁻²² of |origin / direction|).
///  - No NaN can arise (finite origin, inv and c; bounds are never NaN, as
///    class Bvh asks finite triangles, and an empty slot's ±inf bounds give a
///    +inf entry and a −inf exit, a miss, so empty slots need no mask), so
///    the axes and [tmin, tmax] are reduced, and entry and exit compared, as
///    signed integers (vpmaxsd, vpminsd, vpcmpgtd: one cycle each against
///    four for maxps, minps, cmpps on recent Intel cores). Integers order
///    non-negative floats as floats do and negative ones backwards, −0
///    below everything: with tmin >= 0 (−0 made +0 first) a negative entry
///    loses to tmin, as it does as a float; a negative exit, wherever the
///    integers put it, is below the entry (>= +0), a miss as in
///    intersect_slab; and no exit is −0 (the pad on c makes the exit of a box
///    the origin touches positive; tmax −0 is made +0).
/// The interval starts at the ray's own tmin (r.lo: the walks never test
/// from another) and ends at tmax.
/// Needs FMA as well as AVX2 (cpu_has_wide8 asks both).
/// tests/core/test_bvh_query.cpp holds it to intersect_slab.
[[gnu::target("avx2,fma"), gnu::always_inline]] inline int wide_slab_test8_fast(const WideNode8& node,
                                                                                const WideSlabRay8& r, float tmax,
                                                                                float* t_entry,
                                                                                float* t_exit = nullptr) {
  __m256i tn[3], tf[3];
  for (int a = 0; a < 3; ++a) {
    tn[a] = _mm256_castps_si256(_mm256_fmsub_ps(_mm256_load_ps(node.bounds[r.near_row[a]]), r.inv[a], r.c_near[a]));
    tf[a] = _mm256_castps_si256(_mm256_fmsub_ps(_mm256_load_ps(node.bounds[r.far_row[a]]), r.inv[a], r.c_far[a]));
  }
  // tmax + 0: a −0 becomes +0; less kFastExitUlps (an integer >= −24),
  // given back with the exit's pad below.
  const __m256i ulps = _mm256_set1_epi32(kFastExitUlps);
  const __m256i hi = _mm256_sub_epi32(_mm256_castps_si256(_mm256_set1_ps(tmax + 0.0f)), ulps);
  const __m256i t0 = _mm256_max_epi32(_mm256_max_epi32(tn[0], tn[1]), _mm256_max_epi32(tn[2], r.lo));
  const __m256i t1 =
      _mm256_add_epi32(_mm256_min_epi32(_mm256_min_epi32(tf[0], tf[1]), _mm256_min_epi32(tf[2], hi)), ulps);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(t_entry), t0);
  if (t_exit) _mm256_storeu_si256(reinterpret_cast<__m256i*>(t_exit), t1);
  // Compared as integers too (one cycle against four): the entry is >= +0,
  // and the exit is never −0, so the integers order them as floats.
  return ~_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(t0, t1))) & 0xFF;
}

#endif  // ACCELVIZ_BVH_WIDE8_AVX2

#else

struct SlabRay {
  const Ray* ray = nullptr;
  SlabRay() = default;
  explicit SlabRay(const Ray& r) : ray(&r) {}
};

inline bool slab_test(const BvhNode& node, const SlabRay& r, float tmin, float tmax, float& t_entry, float& t_exit) {
  return slab_test_scalar(node, *r.ray, tmin, tmax, t_entry, t_exit);
}

inline int slab_test_pair(const BvhNode* children, const SlabRay& r, float tmin, float tmax, float* t_entry,
                          float* t_exit) {
  const bool h0 = slab_test_scalar(children[0], *r.ray, tmin, tmax, t_entry[0], t_exit[0]);
  const bool h1 = slab_test_scalar(children[1], *r.ray, tmin, tmax, t_entry[1], t_exit[1]);
  return (h0 ? 1 : 0) | (h1 ? 2 : 0);
}

inline int slab_test_pair_cull(const BvhNode* children, const SlabRay& r, float tmin, float tmax, float cull_t,
                               float* t_entry) {
  float t_exit[2];
  const int hit = slab_test_pair(children, r, tmin, tmax, t_entry, t_exit);
  int kept = hit;
  for (int c = 0; c < 2; ++c)
    if (t_entry[c] > cull_t) kept &= ~(1 << c);
  return hit | (kept << 2);
}

struct WideSlabRay {
  const Ray* ray;
  explicit WideSlabRay(const Ray& r) : ray(&r) {}
};

inline int wide_slab_test(const WideNode& node, const WideSlabRay& r, float tmin, float tmax, float* t_entry,
                          float* t_exit = nullptr) {
  float exits[4];
  int mask = wide_slab_test_scalar<4>(node, *r.ray, tmin, tmax, t_entry, t_exit ? t_exit : exits);
  for (int s = 0; s < 4; ++s)
    if (node.meta[s] == kWideEmpty) mask &= ~(1 << s);
  return mask;
}

#endif

}  // namespace accelviz::bvh_detail
