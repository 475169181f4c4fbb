// LBVH: the fast builder for dynamic scenes (Lauterbach et al., "Fast BVH
// Construction on GPUs", 2009; Karras, "Maximizing Parallelism in the
// Construction of BVHs, Octrees, and k-d Trees", HPG 2012).
//
// 1. Each centroid is quantised to a 10-bit grid per axis inside the root's
//    centroid bounds and its bits interleaved into a 30-bit Morton code.
// 2. The primitives are sorted by (code, id) with an LSD radix sort (four
//    8-bit passes, stable, so equal codes keep id order; parallel digit
//    counting and scatter over `threads` chunks).
// 3. Top down, a node's sorted range is cut where its highest differing code
//    bit flips (binary search): the radix tree's split, no cost model. Ranges
//    stay sorted because cutting keeps order. A node whose codes are all
//    equal is "unsplittable" and the driver falls back to its object median
//    (or a leaf), as for the other splitters.
//
// Cost: O(n) for codes and sort, O(log n) per node to find the split (over
// the sort's codes); the driver sets the boxes bottom up as its recursion
// returns (O(n); the other splitters need each child's box to choose their
// cut, a pass over its primitives per tree level). Quality: no SAH, so the tree is worse than binned SAH;
// docs/performance.md quotes both.
#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>

#include "core/accel/bvh/bvh_build.h"
#include "core/util/parallel.h"
#include "core/util/prefetch.h"

namespace accelviz::bvh_detail {

namespace {

/// Spreads the low 10 bits of x so that two zeros separate each bit.
inline std::uint32_t spread_bits_10(std::uint32_t x) {
  x &= 0x3FFu;
  x = (x | (x << 16)) & 0x030000FFu;
  x = (x | (x << 8)) & 0x0300F00Fu;
  x = (x | (x << 4)) & 0x030C30C3u;
  x = (x | (x << 2)) & 0x09249249u;
  return x;
}

inline std::uint32_t quantise(float c, float lo, float scale) {
  const float x = (c - lo) * scale;
  if (!(x > 0.0f)) return 0;  // NaN and below the box
  return x >= 1023.0f ? 1023u : static_cast<std::uint32_t>(x);
}

/// The sort's record gather prefetches this many records ahead.
constexpr std::size_t kGatherAhead = 16;

}  // namespace

std::uint32_t morton_code(const glm::vec3& c, const MortonFrame& f) {
  return (spread_bits_10(quantise(c.x, f.origin.x, f.scale[0])) << 2) |
         (spread_bits_10(quantise(c.y, f.origin.y, f.scale[1])) << 1) |
         spread_bits_10(quantise(c.z, f.origin.z, f.scale[2]));
}

MortonFrame morton_frame(const Aabb& centroid_bounds) {
  MortonFrame f;
  f.origin = centroid_bounds.lo;
  for (int a = 0; a < 3; ++a) {
    const float extent = centroid_bounds.hi[a] - centroid_bounds.lo[a];
    // 1024 cells over the extent; a flat (or non-finite) axis maps to cell 0.
    f.scale[a] = extent > 0.0f && std::isfinite(extent) ? 1024.0f / extent : 0.0f;
  }
  return f;
}

HugePageVector<std::uint32_t> lbvh_sort(std::span<BuildPrim> prims, const MortonFrame& frame, unsigned threads) {
  const std::size_t n = prims.size();
  if (n < 2) {
    HugePageVector<std::uint32_t> codes(n);
    if (n == 1) codes[0] = morton_code(prims[0].centroid, frame);
    return codes;
  }
  threads = std::max(1u, std::min<unsigned>(threads, static_cast<unsigned>((n + 65535) / 65536)));
  HugePageVector<std::uint32_t> keys(n), keys_tmp(n), order(n), order_tmp(n);
  const auto chunk = [&](unsigned t) {
    return std::pair<std::size_t, std::size_t>{n * t / threads, n * (t + 1) / threads};
  };
  fork_join(threads, [&](unsigned t) {
    const auto [b, e] = chunk(t);
    for (std::size_t i = b; i < e; ++i) {
      keys[i] = morton_code(prims[i].centroid, frame);
      order[i] = static_cast<std::uint32_t>(i);
    }
  });
  // The input is in id order (build_bvh fills it so), and the radix sort is
  // stable: equal codes stay in id order.
  std::vector<std::array<std::size_t, 256>> hist(threads);
  for (int pass = 0; pass < 4; ++pass) {
    const int shift = 8 * pass;
    fork_join(threads, [&](unsigned t) {
      const auto [b, e] = chunk(t);
      hist[t].fill(0);
      for (std::size_t i = b; i < e; ++i) ++hist[t][(keys[i] >> shift) & 0xFFu];
    });
    // Exclusive prefix over (digit, chunk): chunk t's digit d starts after
    // every smaller digit and after chunks < t with digit d.
    std::size_t sum = 0;
    for (int d = 0; d < 256; ++d)
      for (unsigned t = 0; t < threads; ++t) {
        const std::size_t c = hist[t][d];
        hist[t][d] = sum;
        sum += c;
      }
    fork_join(threads, [&](unsigned t) {
      const auto [b, e] = chunk(t);
      auto& h = hist[t];
      for (std::size_t i = b; i < e; ++i) {
        const std::size_t dst = h[(keys[i] >> shift) & 0xFFu]++;
        keys_tmp[dst] = keys[i];
        order_tmp[dst] = order[i];
      }
    });
    keys.swap(keys_tmp);
    order.swap(order_tmp);
  }
  HugePageVector<BuildPrim> sorted(n);
  fork_join(threads, [&](unsigned t) {
    const auto [b, e] = chunk(t);
    for (std::size_t i = b; i < e; ++i) {
      // A gather at random: each record's fetch is started kGatherAhead records ahead.
      if (i + kGatherAhead < e) prefetch_object(&prims[order[i + kGatherAhead]]);
      sorted[i] = prims[order[i]];
    }
  });
  std::copy(sorted.begin(), sorted.end(), prims.begin());
  return keys;
}

SplitOutcome split_lbvh(const SplitParams& params, std::span<BuildPrim> prims, const Aabb& /*bounds*/,
                        const Aabb& /*centroid_bounds*/, SplitScratch& /*scratch*/, SplitResult& out) {
  const MortonFrame& f = params.morton;
  const std::size_t n = prims.size();
  // The sort's codes where the caller kept them (the build does; in step
  // with the records, see SplitParams::morton_codes), else recomputed from
  // the centroids.
  const std::uint32_t* codes = nullptr;
  if (params.morton_base != nullptr) {
    codes = params.morton_codes.data() + (prims.data() - params.morton_base);
    assert(codes[0] == morton_code(prims.front().centroid, f) && codes[n - 1] == morton_code(prims.back().centroid, f));
  }
  const auto code = [&](std::size_t i) { return codes ? codes[i] : morton_code(prims[i].centroid, f); };
  const std::uint32_t first = code(0), last = code(n - 1);
  if (first == last) return SplitOutcome::unsplittable;
  // Highest differing bit: every code in the sorted range agrees above it;
  // the first code with that bit set starts the right child.
  const std::uint32_t bit = 1u << (31 - std::countl_zero(first ^ last));
  std::size_t lo = 0, hi = n - 1;  // codes[lo] has the bit clear, codes[hi] set
  while (hi - lo > 1) {
    const std::size_t m = lo + (hi - lo) / 2;
    if (code(m) & bit)
      hi = m;
    else
      lo = m;
  }
  out.mid = hi;  // the driver boxes the children once they are built (Splitter::bounds_after)
  return SplitOutcome::split;
}

}  // namespace accelviz::bvh_detail
