#pragma once
// Early termination and child order, side by side on the same rays: the
// totals of the traversal counters (nodes entered, missed, culled because
// their entry lay beyond the closest hit, primitive tests, leaves skipped by
// an any-hit early exit) for unordered, front-to-back and back-to-front
// closest-hit traversal, for "x-ray" counting (the full traversal as if no
// hit ended it) and for any-hit queries. Child order, culling and x-ray are
// BVH notions; other structures report what they count.
#include <cstdint>
#include <span>
#include <string_view>

#include "core/accel/accel.h"

namespace accelviz {

enum class TraversalMode { unordered, front_to_back, back_to_front, xray, any_hit };
inline constexpr TraversalMode kTraversalModes[] = {TraversalMode::unordered, TraversalMode::front_to_back,
                                                    TraversalMode::back_to_front, TraversalMode::xray,
                                                    TraversalMode::any_hit};
std::string_view mode_name(TraversalMode m);  ///< "unordered", "front-to-back", ...

/// `base` with the mode's ordering / x-ray flags set (x-ray counts front-to-back).
QueryOptions query_for_mode(const QueryOptions& base, TraversalMode m);

struct ModeTotals {
  TraversalMode mode = TraversalMode::front_to_back;
  std::uint64_t rays = 0;
  std::uint64_t hits = 0;
  RayStats sum;  ///< counters summed over the rays (64-bit totals below)
  std::uint64_t nodes_visited = 0, nodes_missed = 0, nodes_culled = 0, prim_tests = 0, leaves_skipped = 0;
  double per_ray(std::uint64_t total) const {
    return rays ? static_cast<double>(total) / static_cast<double>(rays) : 0.0;
  }
};

/// Traces `rays` once in mode `m` and sums the counters.
ModeTotals measure_mode(const Accelerator& accel, std::span<const Ray> rays, const QueryOptions& base, TraversalMode m,
                        unsigned threads = 0);

}  // namespace accelviz
