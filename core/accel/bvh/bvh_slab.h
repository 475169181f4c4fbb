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
// the BVH calls them only when the CPU says it has AVX2 (cpu_has_wide8).
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

/// Per-ray constants of the eight-box tests (WideSlabRay in 256-bit lanes).
struct WideSlabRay8 {
  __m256 origin[3], inv_dir[3];
  __m256 inv_far[3];  ///< inv_dir · kSlabExitScale: the far planes' factor of wide_slab_test8_fast
  int near_row[3], far_row[3];
  /// wide_slab_test8_fast applies: origin and inv_far finite (so inv_dir is
  /// finite and not zero: no box distance can be NaN), tmin >= 0 and tmax not
  /// NaN. False for a ray with a ±0 (or denormal) direction component, a
  /// non-finite origin or a negative or NaN tmin: those take wide_slab_test8.
  bool fast;

  [[gnu::target("avx2")]] explicit WideSlabRay8(const Ray& r) {
    // The checks branch-free on four lanes (many rays visit two or three
    // nodes: their set-up counts): (ox, oy, oz, tmin) and (tmax, ix, iy, iz)
    // as laid out in Ray; finite_mask is bvh_tri4.h's (via bvh_wide.h).
    static_assert(offsetof(Ray, tmin) == 12 && offsetof(Ray, tmax) == 28 && offsetof(Ray, inv_dir) == 32);
    const __m128 o4 = _mm_loadu_ps(&r.origin.x);
    const __m128 i4 = _mm_loadu_ps(&r.tmax);
    const __m128 f4 = _mm_mul_ps(i4, _mm_set1_ps(kSlabExitScale));
    const __m128 zero = _mm_setzero_ps();
    const int o_finite = _mm_movemask_ps(finite_mask(o4));
    const int f_finite = _mm_movemask_ps(finite_mask(f4));
    const int tmin_ok = _mm_movemask_ps(_mm_cmpge_ps(o4, zero));  // lane 3: tmin >= 0 (false for NaN)
    const int tmax_ok = _mm_movemask_ps(_mm_cmpeq_ps(i4, i4));    // lane 0: tmax is not NaN
    fast = (o_finite & 7) == 7 && (f_finite & 14) == 14 && (tmin_ok & 8) != 0 && (tmax_ok & 1) != 0;
    alignas(16) float far_factor[4];
    _mm_store_ps(far_factor, f4);
    for (int a = 0; a < 3; ++a) {
      origin[a] = _mm256_set1_ps(r.origin[a]);
      inv_dir[a] = _mm256_set1_ps(r.inv_dir[a]);
      inv_far[a] = _mm256_set1_ps(far_factor[1 + a]);
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
    const __m256 tn =
        _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.bounds[r.near_row[a]]), r.origin[a]), r.inv_dir[a]);
    const __m256 tf = _mm256_mul_ps(
        _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.bounds[r.far_row[a]]), r.origin[a]), r.inv_dir[a]), scale);
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
/// performance.md, "A shorter box test": 3-6 % more single rays per second
/// on the dragon, 9-11 % on the bunny, on an Intel Xeon).
///  - Far planes times inv_far (inv_dir · kSlabExitScale, once per ray)
///    instead of a third multiplication per plane: four roundings on
///    (plane − origin) / direction, as in intersect_slab, so the exit is
///    padded as robustly, though not always bit for bit the same.
///  - No NaN can arise (finite origin and inv_far; bounds are never NaN, as
///    class Bvh asks finite triangles, and an empty slot's ±inf bounds give a
///    +inf entry and a −inf exit, a miss, so empty slots need no mask), so
///    the axes and [tmin, tmax] are reduced as signed integers (vpmaxsd,
///    vpminsd: one cycle each against four for maxps, minps on recent Intel
///    cores). Integers order non-negative floats as floats do and negative
///    ones backwards (and −0 below everything):
///    with tmin >= 0 (−0 made +0 first) the entry is the largest candidate,
///    >= 0, so it is intersect_slab's bit for bit, and an exit the integers
///    get wrong is negative, as the true one is (a miss either way), or −0
///    beside a negative exit, which keeps a box touched at t = 0 only: one
///    box more, never one fewer.
/// tests/core/test_bvh_query.cpp holds it to intersect_slab.
[[gnu::target("avx2"), gnu::always_inline]] inline int wide_slab_test8_fast(const WideNode8& node,
                                                                            const WideSlabRay8& r, float tmin,
                                                                            float tmax, float* t_entry,
                                                                            float* t_exit = nullptr) {
  __m256i tn[3], tf[3];
  for (int a = 0; a < 3; ++a) {
    tn[a] = _mm256_castps_si256(
        _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.bounds[r.near_row[a]]), r.origin[a]), r.inv_dir[a]));
    tf[a] = _mm256_castps_si256(
        _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.bounds[r.far_row[a]]), r.origin[a]), r.inv_far[a]));
  }
  // tmin + 0: a −0 tmin becomes +0 (as an integer, −0 is the smallest value).
  const __m256i lo = _mm256_castps_si256(_mm256_set1_ps(tmin + 0.0f));
  const __m256i hi = _mm256_castps_si256(_mm256_set1_ps(tmax));
  const __m256 t0 = _mm256_castsi256_ps(_mm256_max_epi32(_mm256_max_epi32(tn[0], tn[1]), _mm256_max_epi32(tn[2], lo)));
  const __m256 t1 = _mm256_castsi256_ps(_mm256_min_epi32(_mm256_min_epi32(tf[0], tf[1]), _mm256_min_epi32(tf[2], hi)));
  _mm256_storeu_ps(t_entry, t0);
  if (t_exit) _mm256_storeu_ps(t_exit, t1);
  // Compared as floats: an exit of −0 (an origin on a far plane) is the
  // smallest integer, but 0 <= −0 (the box is touched at t = 0).
  return _mm256_movemask_ps(_mm256_cmp_ps(t0, t1, _CMP_LE_OQ));
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
