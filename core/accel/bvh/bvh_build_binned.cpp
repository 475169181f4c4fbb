// Binned SAH splitter (Wald, "On fast Construction of SAH-based Bounding
// Volume Hierarchies", IEEE RT 2007).
//
// Instead of evaluating the SAH between every pair of sorted neighbours, the
// centroid range of the node is cut into B equal buckets on each axis; one
// streaming pass drops every primitive into its bucket on all three axes at
// once (counts and bounds), and the SAH is evaluated only at the B-1 bucket
// boundaries of each axis with two sweeps over the buckets. Cost per node:
// O(n + B), no sorting.
#include <algorithm>
#include <array>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/accel/bvh/bvh_build.h"

#if defined(__SSE2__) && !defined(ACCELVIZ_NO_SIMD)
#include <emmintrin.h>
#endif
// The binning pass has an AVX2 form (one 256-bit read-modify-write per axis)
// compiled with GCC's target attribute into the plain x86-64 binary and taken
// when the CPU has AVX2.
#if defined(__SSE2__) && !defined(ACCELVIZ_NO_SIMD) && defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#include <immintrin.h>
#define ACCELVIZ_BIN_AVX2 1
#endif

namespace accelviz::bvh_detail {

void clear_bins(Bins& bins, int buckets) {
#if defined(__SSE2__) && !defined(ACCELVIZ_NO_SIMD)
  const __m128 lo = _mm_set1_ps(kInfinity), hi = _mm_set1_ps(-kInfinity);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < buckets; ++b) {
      _mm_store_ps(bins.lo[a][b], lo);
      _mm_store_ps(bins.hi[a][b], hi);
      bins.count[a][b] = 0;
    }
#else
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < buckets; ++b) {
      for (int l = 0; l < 4; ++l) {
        bins.lo[a][b][l] = kInfinity;
        bins.hi[a][b][l] = -kInfinity;
      }
      bins.count[a][b] = 0;
    }
#endif
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
namespace {

/// The binning passes' set-up per range and per primitive: the three bucket
/// indices in one go, (c - origin)·k clamped to [0, B-1] by max/min (a NaN
/// or negative lane gives 0, as bucket_of), then truncated (lane 3 reads the
/// id and is ignored); the box as lo.xyz (+ hi.x) and hi.xyz rotated out of
/// (lo.z, hi.x, hi.y, hi.z): both loads stay inside the 40-byte record.
struct BinSetup {
  __m128 o, kv, top;
  [[gnu::always_inline]] BinSetup(const glm::vec3& origin, const float k[3], int buckets)
      : o(_mm_setr_ps(origin.x, origin.y, origin.z, 0.0f)),
        kv(_mm_setr_ps(k[0], k[1], k[2], 0.0f)),
        top(_mm_set1_ps(static_cast<float>(buckets - 1))) {}
  [[gnu::always_inline]] void prim(const BuildPrim& p, int* idx, __m128& lo, __m128& hi) const {
    const __m128 x = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(&p.centroid.x), o), kv);
    _mm_store_si128(reinterpret_cast<__m128i*>(idx),
                    _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(x, _mm_setzero_ps()), top)));
    lo = _mm_loadu_ps(&p.bounds.lo.x);
    const __m128 hz = _mm_loadu_ps(&p.bounds.lo.z);
    hi = _mm_shuffle_ps(hz, hz, _MM_SHUFFLE(0, 3, 2, 1));
  }
};

#ifdef ACCELVIZ_BIN_AVX2
/// Ranges of at least this many primitives take the AVX2 pass: below, its
/// set-up (clearing and copying back the buckets) outweighs the saving.
constexpr std::size_t kAvx2BinMin = 64;

/// bin_primitives with AVX2, for ranges of kAvx2BinMin to 2^30 primitives.
/// Each bucket is one 32-byte row: lo.xyz, the count (as integer bits) and
/// -hi.xyz, so one min and one integer add update the whole bucket (a
/// primitive's row is (lo.xyz, +inf, -hi.xyz, +inf)): min(acc, x) keeps
/// minps' operand order, and min(-acc, -x) = -max(acc, x) with maxps'
/// operand order (a tie or a NaN gives x's bits back once negated), so the
/// bins come out bit for bit as the SSE2 pass leaves them. The count's bits
/// stay below +inf's (n < 2^30), so the min leaves them as they are.
[[gnu::target("avx2")]] void bin_primitives_avx2(std::span<const BuildPrim> prims, const glm::vec3& origin,
                                                 const float k[3], int buckets, Bins& bins) {
  alignas(32) float rows[3][kMaxBuckets][8];
  const __m256 empty =
      _mm256_setr_ps(kInfinity, kInfinity, kInfinity, 0.0f, kInfinity, kInfinity, kInfinity, kInfinity);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < buckets; ++b) _mm256_store_ps(rows[a][b], empty);
  const BinSetup setup(origin, k, buckets);
  const __m256 negate_hi = _mm256_setr_ps(0.0f, 0.0f, 0.0f, 0.0f, -0.0f, -0.0f, -0.0f, 0.0f);
  const __m256 inf = _mm256_set1_ps(kInfinity);
  const __m256i one = _mm256_setr_epi32(0, 0, 0, 1, 0, 0, 0, 0);
  alignas(16) int idx[4];
  for (const BuildPrim& p : prims) {
    __m128 lo, hi;
    setup.prim(p, idx, lo, hi);
    // (lo.xyz, +inf, -hi.xyz, +inf): lanes 3 and 7 from `inf` (blend mask 0x88).
    const __m256 row =
        _mm256_blend_ps(_mm256_xor_ps(_mm256_insertf128_ps(_mm256_castps128_ps256(lo), hi, 1), negate_hi), inf, 0x88);
    for (int a = 0; a < 3; ++a) {
      float* r = rows[a][idx[a]];
      const __m256 m = _mm256_min_ps(_mm256_load_ps(r), row);
      _mm256_store_ps(r, _mm256_castsi256_ps(_mm256_add_epi32(_mm256_castps_si256(m), one)));
    }
  }
  // Back into `bins` with bin_primitives' operand order (its callers clear
  // it first; into bins that already hold primitives this gives the SSE2
  // pass's bits for bounds without NaN).
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < buckets; ++b) {
      const __m256 r = _mm256_load_ps(rows[a][b]);
      const __m128 row_lo = _mm256_castps256_ps128(r);
      const __m128 lo = _mm_blend_ps(row_lo, _mm_set1_ps(kInfinity), 0x8);  // lane 3 (unused) stays as cleared
      const __m128 hi = _mm_xor_ps(_mm256_extractf128_ps(r, 1), _mm_set1_ps(-0.0f));
      _mm_store_ps(bins.lo[a][b], _mm_min_ps(_mm_load_ps(bins.lo[a][b]), lo));
      _mm_store_ps(bins.hi[a][b], _mm_max_ps(_mm_load_ps(bins.hi[a][b]), hi));
      bins.count[a][b] += static_cast<std::uint32_t>(_mm_extract_epi32(_mm_castps_si128(row_lo), 3));
    }
}

// (set during static initialisation, hence the explicit __builtin_cpu_init)
const bool kCpuHasAvx2 = [] {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") != 0;
}();
#endif

}  // namespace

void bin_primitives(std::span<const BuildPrim> prims, const glm::vec3& origin, const float k[3], int buckets,
                    Bins& bins) {
#ifdef ACCELVIZ_BIN_AVX2
  if (kCpuHasAvx2 && prims.size() >= kAvx2BinMin && prims.size() < (std::size_t{1} << 30))
    return bin_primitives_avx2(prims, origin, k, buckets, bins);
#endif
  const BinSetup setup(origin, k, buckets);
  alignas(16) int idx[4];
  for (const BuildPrim& p : prims) {
    __m128 lo, hi;
    setup.prim(p, idx, lo, hi);
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

namespace {

/// acc := acc ∪ part, bucket by bucket, with bin_primitives' operand order
/// (min(acc, x) and max(acc, x) return x on a tie), so merging the slices of
/// a range in order gives the bits of one pass over the range: both keep, on
/// a tie such as -0 against +0, the last primitive's value.
void merge_bins(Bins& acc, const Bins& part, int buckets) {
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < buckets; ++b) {
#if defined(__SSE2__) && !defined(ACCELVIZ_NO_SIMD)
      _mm_store_ps(acc.lo[a][b], _mm_min_ps(_mm_load_ps(acc.lo[a][b]), _mm_load_ps(part.lo[a][b])));
      _mm_store_ps(acc.hi[a][b], _mm_max_ps(_mm_load_ps(acc.hi[a][b]), _mm_load_ps(part.hi[a][b])));
#else
      for (int l = 0; l < 4; ++l) {
        float& lo = acc.lo[a][b][l];
        float& hi = acc.hi[a][b][l];
        lo = lo < part.lo[a][b][l] ? lo : part.lo[a][b][l];
        hi = hi > part.hi[a][b][l] ? hi : part.hi[a][b][l];
      }
#endif
      acc.count[a][b] += part.count[a][b];
    }
}

/// First index of slice t when n items are cut into `parts` near-equal slices.
inline std::size_t slice_begin(std::size_t n, std::size_t t, std::size_t parts) {
  return n * t / parts;
}

}  // namespace

void bin_primitives_parallel(std::span<const BuildPrim> prims, const glm::vec3& origin, const float k[3], int buckets,
                             Bins& bins, unsigned threads, std::uint32_t* slice_counts) {
  // Slice t's counts (the buckets in use; the others are never read).
  const auto keep_counts = [&](unsigned t, const Bins& b) {
    if (slice_counts)
      for (int a = 0; a < 3; ++a)
        std::memcpy(slice_counts + (static_cast<std::size_t>(t) * 3 + a) * kMaxBuckets, b.count[a],
                    static_cast<std::size_t>(buckets) * sizeof(std::uint32_t));
  };
  if (threads <= 1) {
    bin_primitives(prims, origin, k, buckets, bins);  // `bins` held nothing before (cleared)
    keep_counts(0, bins);
    return;
  }
  const std::size_t n = prims.size();
  const std::unique_ptr<Bins[]> part(new Bins[threads]);  // left uninitialised: clear_bins sets what is used
  parallel_for(threads, threads, 1, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t t = begin; t < end; ++t) {
      clear_bins(part[t], buckets);
      const std::size_t b = slice_begin(n, t, threads), e = slice_begin(n, t + 1, threads);
      bin_primitives(prims.subspan(b, e - b), origin, k, buckets, part[t]);
      keep_counts(static_cast<unsigned>(t), part[t]);
    }
  });
  for (unsigned t = 0; t < threads; ++t) merge_bins(bins, part[t], buckets);
}

Aabb bucket_box(const Bins& bins, int axis, int b) {
  const float* lo = bins.lo[axis][b];
  const float* hi = bins.hi[axis][b];
  return Aabb{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}};
}

namespace {

/// cost_of[a][b] = A_L·N_L + A_R·N_R of the plane between buckets b and b+1
/// on axis a (half areas; meaningful only where both sides hold primitives).
/// The SSE2 version sweeps the three axes at once, one lane each, with the
/// scalar code's operations in the scalar code's order (Aabb::extend's
/// min/max operand order, half_area's sum order), so both give the same bits.
#if defined(__SSE2__) && !defined(ACCELVIZ_NO_SIMD)
[[gnu::always_inline]] inline void transpose3(__m128 r0, __m128 r1, __m128 r2, __m128& x, __m128& y, __m128& z) {
  // rows (x_a, y_a, z_a, -) for a = 0..2 -> columns (c_0, c_1, c_2, -)
  const __m128 t0 = _mm_unpacklo_ps(r0, r1);  // x0 x1 y0 y1
  const __m128 t1 = _mm_unpackhi_ps(r0, r1);  // z0 z1 -  -
  const __m128 t2 = _mm_unpacklo_ps(r2, r2);  // x2 x2 y2 y2
  const __m128 t3 = _mm_unpackhi_ps(r2, r2);  // z2 z2 -  -
  x = _mm_movelh_ps(t0, t2);                  // x0 x1 x2 x2
  y = _mm_movehl_ps(t2, t0);                  // y0 y1 y2 y2
  z = _mm_movelh_ps(t1, t3);                  // z0 z1 z2 z2
}

/// Half areas of the three axes' accumulated boxes, one per lane (0 where empty).
[[gnu::always_inline]] inline __m128 half_areas3(const __m128 lo[3], const __m128 hi[3]) {
  __m128 lx, ly, lz, hx, hy, hz;
  transpose3(lo[0], lo[1], lo[2], lx, ly, lz);
  transpose3(hi[0], hi[1], hi[2], hx, hy, hz);
  const __m128 empty = _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(lx, hx), _mm_cmpgt_ps(ly, hy)), _mm_cmpgt_ps(lz, hz));
  const __m128 ex = _mm_sub_ps(hx, lx), ey = _mm_sub_ps(hy, ly), ez = _mm_sub_ps(hz, lz);
  const __m128 area = _mm_add_ps(_mm_add_ps(_mm_mul_ps(ex, ey), _mm_mul_ps(ey, ez)), _mm_mul_ps(ez, ex));
  return _mm_andnot_ps(empty, area);
}

/// Every candidate plane of the three axes, one lane per axis: cost[b] =
/// A_L·N_L + A_R·N_R of the plane between buckets b and b+1, left[b] = N_L.
struct SweepOut {
  alignas(16) float cost[kMaxBuckets][4];
  alignas(16) std::int32_t left[kMaxBuckets][4];
};

void sweep_planes(const Bins& bins, int nb, SweepOut& out) {
  alignas(16) float right_area[kMaxBuckets][4];
  alignas(16) float right_count[kMaxBuckets][4];
  __m128 lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = _mm_set1_ps(kInfinity);
    hi[a] = _mm_set1_ps(-kInfinity);
  }
  __m128i cnt = _mm_setzero_si128();
  for (int b = nb - 1; b > 0; --b) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = _mm_min_ps(_mm_load_ps(bins.lo[a][b]), lo[a]);  // glm::min(acc, box)
      hi[a] = _mm_max_ps(_mm_load_ps(bins.hi[a][b]), hi[a]);  // glm::max(acc, box)
    }
    cnt = _mm_add_epi32(cnt, _mm_setr_epi32(static_cast<int>(bins.count[0][b]), static_cast<int>(bins.count[1][b]),
                                            static_cast<int>(bins.count[2][b]), 0));
    _mm_store_ps(right_area[b - 1], half_areas3(lo, hi));
    _mm_store_ps(right_count[b - 1], _mm_cvtepi32_ps(cnt));
  }
  for (int a = 0; a < 3; ++a) {
    lo[a] = _mm_set1_ps(kInfinity);
    hi[a] = _mm_set1_ps(-kInfinity);
  }
  cnt = _mm_setzero_si128();
  for (int b = 0; b < nb - 1; ++b) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = _mm_min_ps(_mm_load_ps(bins.lo[a][b]), lo[a]);
      hi[a] = _mm_max_ps(_mm_load_ps(bins.hi[a][b]), hi[a]);
    }
    cnt = _mm_add_epi32(cnt, _mm_setr_epi32(static_cast<int>(bins.count[0][b]), static_cast<int>(bins.count[1][b]),
                                            static_cast<int>(bins.count[2][b]), 0));
    _mm_store_ps(out.cost[b], _mm_add_ps(_mm_mul_ps(half_areas3(lo, hi), _mm_cvtepi32_ps(cnt)),
                                         _mm_mul_ps(_mm_load_ps(right_area[b]), _mm_load_ps(right_count[b]))));
    _mm_store_si128(reinterpret_cast<__m128i*>(out.left[b]), cnt);
  }
}

void sweep_costs(const Bins& bins, int nb, float (&cost_of)[3][kMaxBuckets]) {
  SweepOut out;
  sweep_planes(bins, nb, out);
  for (int b = 0; b < nb - 1; ++b)
    for (int a = 0; a < 3; ++a) cost_of[a][b] = out.cost[b][a];
}

/// The candidate loop of search_impl (better_split over axes, then planes,
/// in order) without its branches: the winner is the cheapest candidate
/// (NaN never wins), among equally cheap ones the most balanced, and among
/// those the first in (axis, plane) order, which is what the sequential
/// loop keeps. Needs n < 2^30 (imbalances in int32 lanes).
void select_plane(const SweepOut& sw, int nb, std::size_t n, const bool usable[3], BinnedSahSearch& s) {
  const __m128i zero = _mm_setzero_si128(), nv = _mm_set1_epi32(static_cast<int>(n));
  const __m128i use = _mm_setr_epi32(usable[0] ? -1 : 0, usable[1] ? -1 : 0, usable[2] ? -1 : 0, 0);
  const __m128 inf = _mm_set1_ps(kInfinity);
  const auto valid_at = [&](int b) {  // usable axis, both sides non-empty
    const __m128i l = _mm_load_si128(reinterpret_cast<const __m128i*>(sw.left[b]));
    return _mm_andnot_si128(_mm_or_si128(_mm_cmpeq_epi32(l, zero), _mm_cmpeq_epi32(l, nv)), use);
  };
  // 1. The lowest cost of a candidate (min ignores NaN: _mm_min_ps returns its second operand then).
  __m128 m = inf;
  for (int b = 0; b < nb - 1; ++b) {
    const __m128 valid = _mm_castsi128_ps(valid_at(b));
    const __m128 c = _mm_or_ps(_mm_and_ps(valid, _mm_load_ps(sw.cost[b])), _mm_andnot_ps(valid, inf));
    m = _mm_min_ps(c, m);
  }
  m = _mm_min_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(2, 3, 0, 1)));
  m = _mm_min_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
  // 2. Per axis, the first plane of that cost with the smallest imbalance |2·N_L - n|.
  const __m128i big = _mm_set1_epi32(std::numeric_limits<std::int32_t>::max());
  __m128i best_key = big, best_b = _mm_set1_epi32(-1);
  for (int b = 0; b < nb - 1; ++b) {
    const __m128i eq = _mm_and_si128(valid_at(b), _mm_castps_si128(_mm_cmpeq_ps(_mm_load_ps(sw.cost[b]), m)));
    const __m128i l = _mm_load_si128(reinterpret_cast<const __m128i*>(sw.left[b]));
    const __m128i d = _mm_sub_epi32(_mm_add_epi32(l, l), nv);
    const __m128i sign = _mm_srai_epi32(d, 31);
    const __m128i imb = _mm_sub_epi32(_mm_xor_si128(d, sign), sign);
    const __m128i key = _mm_or_si128(_mm_and_si128(eq, imb), _mm_andnot_si128(eq, big));
    const __m128i take = _mm_cmplt_epi32(key, best_key);
    best_key = _mm_or_si128(_mm_and_si128(take, key), _mm_andnot_si128(take, best_key));
    best_b = _mm_or_si128(_mm_and_si128(take, _mm_set1_epi32(b)), _mm_andnot_si128(take, best_b));
  }
  alignas(16) std::int32_t key[4], bb[4];
  _mm_store_si128(reinterpret_cast<__m128i*>(key), best_key);
  _mm_store_si128(reinterpret_cast<__m128i*>(bb), best_b);
  // 3. Across axes: the smallest imbalance, the first axis on a tie.
  std::int32_t best = std::numeric_limits<std::int32_t>::max();
  for (int a = 0; a < 3; ++a)
    if (key[a] < best) {
      best = key[a];
      s.best_axis = a;
      s.best_bucket = bb[a];
      s.best_left = static_cast<std::size_t>(sw.left[bb[a]][a]);
      s.best_cost = sw.cost[bb[a]][a];
    }
}
#else
void sweep_costs(const Bins& bins, int nb, float (&cost_of)[3][kMaxBuckets]) {
  for (int a = 0; a < 3; ++a) {
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
      cost_of[a][b] = acc.half_area() * static_cast<float>(cnt) + right_area[b] * static_cast<float>(right_count[b]);
    }
  }
}
#endif

/// Centroid bounds gathered during the partition: Aabb::extend with the
/// same min/max operand order, on SSE registers where available (lane 3
/// reads the record's id and is dropped).
#if defined(__SSE2__) && !defined(ACCELVIZ_NO_SIMD)
struct CentroidBounds {
  __m128 lo = _mm_set1_ps(kInfinity), hi = _mm_set1_ps(-kInfinity);
  void extend(const BuildPrim& p) {
    const __m128 c = _mm_loadu_ps(&p.centroid.x);
    lo = _mm_min_ps(c, lo);  // glm::min(lo, c)
    hi = _mm_max_ps(c, hi);  // glm::max(hi, c)
  }
  /// Then the centroids that `later` has seen, as if extend had gone on
  /// over them (min(x, acc): a tie keeps what was seen first).
  void merge(const CentroidBounds& later) {
    lo = _mm_min_ps(later.lo, lo);
    hi = _mm_max_ps(later.hi, hi);
  }
  Aabb get() const {
    alignas(16) float l[4], h[4];
    _mm_store_ps(l, lo);
    _mm_store_ps(h, hi);
    return Aabb{{l[0], l[1], l[2]}, {h[0], h[1], h[2]}};
  }
};
#else
struct CentroidBounds {
  Aabb box;
  void extend(const BuildPrim& p) { box.extend(p.centroid); }
  void merge(const CentroidBounds& later) { box.extend(later.box); }
  Aabb get() const { return box; }
};
#endif

template <bool Record>
bool search_impl(int nb, std::span<const BuildPrim> prims, const Aabb& centroid_bounds, Bins& bins, BinnedSahSearch& s,
                 CandidateCosts* costs, unsigned threads, std::vector<std::uint32_t>* slice_counts) {
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
  if (slice_counts) slice_counts->resize(static_cast<std::size_t>(std::max(threads, 1u)) * 3 * kMaxBuckets);
  bin_primitives_parallel(prims, centroid_bounds.lo, s.k, nb, bins, threads,
                          slice_counts ? slice_counts->data() : nullptr);
#if defined(__SSE2__) && !defined(ACCELVIZ_NO_SIMD)
  if constexpr (!Record) {
    if (n < (std::size_t{1} << 30)) {
      SweepOut sw;
      sweep_planes(bins, nb, sw);
      select_plane(sw, nb, n, s.usable, s);
      return true;
    }
  }
#endif

  // 3. SAH at every bucket boundary: a right-to-left sweep stores the right
  //    side's area and count, a left-to-right sweep completes the cost
  //    A_L·N_L + A_R·N_R (half areas; C_trav and 1/A_N are common to all
  //    candidates and enter only the leaf test).
  float cost_of[3][kMaxBuckets];
  sweep_costs(bins, nb, cost_of);
  for (int a = 0; a < 3; ++a) {
    if (!s.usable[a]) continue;
    std::uint32_t cnt = 0;
    for (int b = 0; b < nb - 1; ++b) {
      cnt += bins.count[a][b];
      if (cnt == 0 || cnt == n) continue;  // one side empty
      const float cost = cost_of[a][b];
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

#if defined(__SSE2__) && !defined(ACCELVIZ_NO_SIMD)
/// Records per block of the block partition (offsets fit a byte).
constexpr unsigned kPartitionBlock = 64;

/// The plane test of left_of_plane on all four lanes of a record's centroid
/// (the same operations, so the same answer on lane Axis), and the record's
/// centroid added to its side's bounds without a branch: the other side
/// gets the centroid with all bits set, a NaN, which minps and maxps pass
/// over (they return their second operand, the bounds so far). Returns 1
/// for a record that goes right.
template <int Axis>
[[gnu::always_inline]] inline unsigned classify(const BuildPrim& p, __m128 lo, __m128 k, __m128 plane,
                                                CentroidBounds& left, CentroidBounds& right) {
  const __m128 c = _mm_loadu_ps(&p.centroid.x);
  const __m128 x = _mm_mul_ps(_mm_sub_ps(c, lo), k);
  const __m128 ge = _mm_cmpge_ps(x, plane);    // goes right: (c - lo)·k >= plane + 1
  const __m128 nge = _mm_cmpnge_ps(x, plane);  // goes left (NaN too, as left_of_plane)
  constexpr int kLane = _MM_SHUFFLE(Axis, Axis, Axis, Axis);
  const __m128 to_right = _mm_shuffle_ps(ge, ge, kLane), to_left = _mm_shuffle_ps(nge, nge, kLane);
  const __m128 cl = _mm_or_ps(c, to_right), cr = _mm_or_ps(c, to_left);  // NaN on the other side
  left.lo = _mm_min_ps(cl, left.lo);
  left.hi = _mm_max_ps(cl, left.hi);
  right.lo = _mm_min_ps(cr, right.lo);
  right.hi = _mm_max_ps(cr, right.hi);
  return static_cast<unsigned>(_mm_movemask_ps(ge) >> Axis) & 1u;
}

/// Edelkamp and Weiss's block partition ("BlockQuicksort", 2016): a block
/// of 64 records at each end is classified without branches, listing the
/// offsets of its misplaced records, and the listed pairs are swapped; a
/// block whose list is used up is done. What is left (under two blocks,
/// some of it classified already: those centroids are added to their side's
/// bounds again, which min and max do not mind) goes through two buffers.
/// The two-ended loop branches on every record's side, which on a node
/// whose records are not sorted by side no predictor can learn.
template <int Axis>
std::size_t partition_blocks(std::span<BuildPrim> prims, float lo_a, float k_a, int plane, CentroidBounds& left,
                             CentroidBounds& right) {
  const __m128 lo = _mm_set1_ps(lo_a), k = _mm_set1_ps(k_a), p = _mm_set1_ps(static_cast<float>(plane + 1));
  std::uint8_t off_l[kPartitionBlock], off_r[kPartitionBlock];
  unsigned num_l = 0, num_r = 0, start_l = 0, start_r = 0;
  std::size_t first = 0, last = prims.size();  // [first, last): not yet in place
  // Lists the offsets of a block's misplaced records: the left block's
  // (prims[first + i]) that go right, or the right block's (prims[last - 1 - i])
  // that go left. Returns how many.
  const auto list_block = [&]<bool RightBlock>(std::uint8_t* off) {
    unsigned num = 0;
    for (unsigned i = 0; i < kPartitionBlock; ++i) {
      off[num] = static_cast<std::uint8_t>(i);
      const unsigned goes_right = classify<Axis>(prims[RightBlock ? last - 1 - i : first + i], lo, k, p, left, right);
      num += RightBlock ? 1u - goes_right : goes_right;
    }
    return num;
  };
  while (last - first >= 2 * kPartitionBlock) {
    if (num_l == 0) {
      start_l = 0;
      num_l = list_block.template operator()<false>(off_l);
    }
    if (num_r == 0) {
      start_r = 0;
      num_r = list_block.template operator()<true>(off_r);
    }
    const unsigned num = std::min(num_l, num_r);
    for (unsigned j = 0; j < num; ++j)
      std::swap(prims[first + off_l[start_l + j]], prims[last - 1 - off_r[start_r + j]]);
    num_l -= num;
    num_r -= num;
    start_l += num;
    start_r += num;
    if (num_l == 0) first += kPartitionBlock;
    if (num_r == 0) last -= kPartitionBlock;
  }
  // The rest, under two blocks: each record copied to both of two buffers,
  // each buffer's cursor moved on for its own side's records, and the
  // buffers copied back (a stable partition: records in place stay put).
  // (Raw bytes: BuildPrim's Aabb would initialise every element.)
  static_assert(std::is_trivially_copyable_v<BuildPrim>);
  constexpr std::size_t kRest = 2 * kPartitionBlock - 1, kSize = sizeof(BuildPrim);
  alignas(BuildPrim) unsigned char to_left[kRest * kSize], to_right[kRest * kSize];
  std::size_t nl = 0, nr = 0;
  for (std::size_t i = first; i < last; ++i) {
    const unsigned goes_right = classify<Axis>(prims[i], lo, k, p, left, right);
    std::memcpy(to_left + nl * kSize, &prims[i], kSize);
    std::memcpy(to_right + nr * kSize, &prims[i], kSize);
    nl += 1u - goes_right;
    nr += goes_right;
  }
  std::memcpy(prims.data() + first, to_left, nl * kSize);
  std::memcpy(prims.data() + first + nl, to_right, nr * kSize);
  return first + nl;
}
#else
/// The two-ended (Hoare) partition of prims[first, last): returns where the
/// right side starts. Every record it passes is added to its side's bounds.
template <class GoesLeft>
std::size_t partition_two_ended(std::span<BuildPrim> prims, std::size_t first, std::size_t last,
                                const GoesLeft& goes_left, CentroidBounds& left, CentroidBounds& right) {
  std::size_t i = first, j = last;
  for (;;) {
    while (i < j && goes_left(prims[i])) left.extend(prims[i++]);
    while (i < j && !goes_left(prims[j - 1])) right.extend(prims[--j]);
    if (i >= j) return i;
    std::swap(prims[i], prims[j - 1]);
    left.extend(prims[i++]);
    right.extend(prims[--j]);
  }
}
#endif

}  // namespace

std::size_t partition_at_plane(std::span<BuildPrim> prims, int axis, float lo, float k, int plane, Aabb& left_centroids,
                               Aabb& right_centroids) {
  CentroidBounds left, right;
  std::size_t mid;
#if defined(__SSE2__) && !defined(ACCELVIZ_NO_SIMD)
  mid = axis == 0   ? partition_blocks<0>(prims, lo, k, plane, left, right)
        : axis == 1 ? partition_blocks<1>(prims, lo, k, plane, left, right)
                    : partition_blocks<2>(prims, lo, k, plane, left, right);
#else
  const auto goes_left = [&](const BuildPrim& r) { return left_of_plane(r.centroid[axis], lo, k, plane); };
  mid = partition_two_ended(prims, 0, prims.size(), goes_left, left, right);
#endif
  left_centroids = left.get();
  right_centroids = right.get();
  return mid;
}

namespace {

/// One slice of partition_to: each record, in order, copied to its side's
/// next place in `dst` (from `next_left` and `next_right` on; both moved
/// on), and its centroid added to its side's bounds. The place is clamped
/// to dst's last record, so counts that are not the slice's own cannot
/// write outside `dst` (partition_to then throws).
template <int Axis>
void scatter_slice(std::span<const BuildPrim> src, std::span<BuildPrim> dst, std::size_t& next_left,
                   std::size_t& next_right, float lo_a, float k_a, int plane, CentroidBounds& left_out,
                   CentroidBounds& right_out) {
  const std::size_t last = dst.size() - 1;
  std::size_t l = next_left, r = next_right;
  // Local bounds, stored once at the end: the record copies may alias
  // anything, so bounds behind a reference would be stored after every
  // record, and the slices' bounds share cache lines.
  CentroidBounds left, right;
#if defined(__SSE2__) && !defined(ACCELVIZ_NO_SIMD)
  const __m128 lo = _mm_set1_ps(lo_a), k = _mm_set1_ps(k_a), p = _mm_set1_ps(static_cast<float>(plane + 1));
  for (const BuildPrim& rec : src) {
    // The place without a branch (on records in no spatial order a branch
    // on the side is mispredicted half the time: the 1M soup's one-thread
    // build took 8% longer with the conditional form, which GCC compiled
    // to a jump).
    const std::size_t goes_right = classify<Axis>(rec, lo, k, p, left, right);
    const std::size_t at = l ^ ((l ^ r) & (0 - goes_right));
    std::memcpy(&dst[std::min(at, last)], &rec, sizeof(BuildPrim));
    l += 1 - goes_right;
    r += goes_right;
  }
#else
  for (const BuildPrim& rec : src) {
    const bool goes_left = left_of_plane(rec.centroid[Axis], lo_a, k_a, plane);
    (goes_left ? left : right).extend(rec);
    const std::size_t at = goes_left ? l++ : r++;
    std::memcpy(&dst[std::min(at, last)], &rec, sizeof(BuildPrim));
  }
#endif
  next_left = l;
  next_right = r;
  left_out = left;
  right_out = right;
}

}  // namespace

std::size_t partition_to(std::span<const BuildPrim> src, std::span<BuildPrim> dst, int axis, float lo, float k,
                         int plane, std::span<const std::size_t> slice_left, Aabb& left_centroids,
                         Aabb& right_centroids) {
  const std::size_t n = src.size(), slices = slice_left.size();
  if (dst.size() != n || slices == 0 || slices > n || axis < 0 || axis > 2)
    throw std::logic_error("partition_to: bad arguments");
  // Per slice: where its left and right records start (the left ones of
  // all slices in slice order, then the right ones), where they ended, and
  // their bounds; one cache line each. On the stack for a few slices (most
  // calls have one: a node is partitioned out of place on any thread count).
  struct alignas(64) SliceWork {
    std::size_t left_at, right_at, left_end, right_end;
    CentroidBounds left, right;
  };
  constexpr std::size_t kOnStack = 4;
  SliceWork on_stack[kOnStack];
  std::unique_ptr<SliceWork[]> on_heap;
  if (slices > kOnStack) on_heap.reset(new SliceWork[slices]);
  SliceWork* work = on_heap ? on_heap.get() : on_stack;
  std::size_t mid = 0;
  for (std::size_t t = 0; t < slices; ++t) {
    if (slice_left[t] > slice_begin(n, t + 1, slices) - slice_begin(n, t, slices))
      throw std::logic_error("partition_to: a slice's left count exceeds its size");
    work[t].left_at = mid;
    mid += slice_left[t];
  }
  for (std::size_t t = 0, r = mid; t < slices; ++t) {
    work[t].right_at = r;
    r += slice_begin(n, t + 1, slices) - slice_begin(n, t, slices) - slice_left[t];
  }
  parallel_for(slices, static_cast<unsigned>(slices), 1, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t t = begin; t < end; ++t) {
      SliceWork& w = work[t];
      const std::size_t b = slice_begin(n, t, slices), e = slice_begin(n, t + 1, slices);
      const std::span<const BuildPrim> part = src.subspan(b, e - b);
      w.left_end = w.left_at;
      w.right_end = w.right_at;
      if (axis == 0) scatter_slice<0>(part, dst, w.left_end, w.right_end, lo, k, plane, w.left, w.right);
      if (axis == 1) scatter_slice<1>(part, dst, w.left_end, w.right_end, lo, k, plane, w.left, w.right);
      if (axis == 2) scatter_slice<2>(part, dst, w.left_end, w.right_end, lo, k, plane, w.left, w.right);
    }
  });
  for (std::size_t t = 0; t < slices; ++t)
    if (work[t].left_end != work[t].left_at + slice_left[t] ||
        work[t].right_end != (t + 1 < slices ? work[t + 1].right_at : n))
      throw std::logic_error("partition_to: a slice's left count is not the one its records give");
  for (std::size_t t = 1; t < slices; ++t) {
    work[0].left.merge(work[t].left);
    work[0].right.merge(work[t].right);
  }
  left_centroids = work[0].left.get();
  right_centroids = work[0].right.get();
  return mid;
}

bool binned_sah_search(int buckets, std::span<const BuildPrim> prims, const Aabb& centroid_bounds, Bins& bins,
                       BinnedSahSearch& out, CandidateCosts* costs, unsigned threads,
                       std::vector<std::uint32_t>* slice_counts) {
  return costs ? search_impl<true>(buckets, prims, centroid_bounds, bins, out, costs, threads, slice_counts)
               : search_impl<false>(buckets, prims, centroid_bounds, bins, out, nullptr, threads, slice_counts);
}

SplitOutcome split_binned_sah(const SplitParams& params, std::span<BuildPrim> prims, const Aabb& bounds,
                              const Aabb& centroid_bounds, SplitScratch& scratch, SplitResult& out) {
  const std::size_t n = prims.size();
  const int nb = binned_bucket_count(params.buckets, params.small_node_buckets, n);
  const unsigned threads = scratch.helpers + 1;  // the builder lends threads to large nodes only

  // 1-3. Scale, binning and the SAH at every bucket boundary (shared with the
  //      explainer in core/analysis/insight). Bins is left uninitialised.
  Bins bins;
  BinnedSahSearch search;
  const bool move = !scratch.move_to.empty();
  if (move && scratch.move_to.size() != n) throw std::logic_error("split_binned_sah: move_to is not the node's size");
  out.moved = false;
  if (!binned_sah_search(nb, prims, centroid_bounds, bins, search, nullptr, threads,
                         move ? &scratch.slice_counts : nullptr))
    return SplitOutcome::unsplittable;
  const float best_cost = search.best_cost;
  const int best_axis = search.best_axis, best_bucket = search.best_bucket;
  const glm::vec3 lo = centroid_bounds.lo;
  const float* k = search.k;
  if (best_axis < 0) return SplitOutcome::unsplittable;
  if (sah_prefers_leaf(params, n, bounds.half_area(), best_cost)) return SplitOutcome::leaf;

  // 4. Children's bounds are the unions of their buckets' bounds.
  Aabb child_bounds[2];
#if defined(__SSE2__) && !defined(ACCELVIZ_NO_SIMD)
  for (int side = 0; side < 2; ++side) {
    __m128 cl = _mm_set1_ps(kInfinity), ch = _mm_set1_ps(-kInfinity);
    for (int b = side == 0 ? 0 : best_bucket + 1; b < (side == 0 ? best_bucket + 1 : nb); ++b) {
      cl = _mm_min_ps(_mm_load_ps(bins.lo[best_axis][b]), cl);  // Aabb::extend: glm::min(acc, box)
      ch = _mm_max_ps(_mm_load_ps(bins.hi[best_axis][b]), ch);
    }
    alignas(16) float l[4], h[4];
    _mm_store_ps(l, cl);
    _mm_store_ps(h, ch);
    child_bounds[side] = Aabb{{l[0], l[1], l[2]}, {h[0], h[1], h[2]}};
  }
#else
  for (int b = 0; b < nb; ++b) child_bounds[b <= best_bucket ? 0 : 1].extend(bucket_box(bins, best_axis, b));
#endif

  // 5. The partition, gathering the children's centroid bounds on the way:
  //    into scratch.move_to when the builder asks for it, on the lent
  //    threads, each its slice of the binning with the left counts the
  //    binning found there; else in place, on this thread. (An in-place
  //    parallel version, each thread listing its slice's misplaced records
  //    and then the k-th pairs swapped, measured 5.6-11.1 ms on the
  //    dragon's root against 3.1-7.0 ms serial on 2 vCPUs: a second pass.)
  if (move) {
    const std::size_t slices = scratch.slice_counts.size() / (3 * kMaxBuckets);
    std::vector<std::size_t>& slice_left = scratch.slice_left;
    slice_left.resize(slices);
    for (std::size_t t = 0; t < slices; ++t) {
      const std::uint32_t* c = &scratch.slice_counts[(t * 3 + static_cast<std::size_t>(best_axis)) * kMaxBuckets];
      std::size_t sum = 0;
      for (int b = 0; b <= best_bucket; ++b) sum += c[b];
      slice_left[t] = sum;
    }
    out.mid = partition_to(prims, scratch.move_to, best_axis, lo[best_axis], k[best_axis], best_bucket, slice_left,
                           out.centroid_bounds[0], out.centroid_bounds[1]);
    out.moved = true;
  } else {
    out.mid = partition_at_plane(prims, best_axis, lo[best_axis], k[best_axis], best_bucket, out.centroid_bounds[0],
                                 out.centroid_bounds[1]);
  }
  out.bounds[0] = child_bounds[0];
  out.bounds[1] = child_bounds[1];
  return SplitOutcome::split;
}

}  // namespace accelviz::bvh_detail
