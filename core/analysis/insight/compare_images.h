#pragma once
// A/B comparison of two metric images of the same view: one locked colour
// scale for both, and the difference B - A on a diverging colour map
// (blue: B cheaper, white: equal, red: B dearer) whose scale is symmetric
// about 0. Shared by `accelviz render --compare` and the GUI's A/B panel.
#include <span>
#include <vector>

#include "core/accel/accel.h"
#include "core/analysis/heatmap.h"

namespace accelviz {

struct ABFigures {
  double total_a = 0.0, total_b = 0.0;  ///< sums over pixels with a value in both
  double mean_a = 0.0, mean_b = 0.0;
  double max_abs_diff = 0.0;                  ///< largest |B - A|
  std::uint64_t pixels = 0;                   ///< pixels with a value in both
  std::uint64_t b_cheaper = 0, b_dearer = 0;  ///< pixels where B < A, B > A
};

/// B - A per pixel (NaN where either has no value). Throws
/// std::invalid_argument when the sizes differ.
MetricImage difference_image(const MetricImage& a, const MetricImage& b, ABFigures* figures = nullptr);

/// The locked scale for A and B: the larger of the two maxima (`fixed_max` when > 0).
float locked_scale_max(const MetricImage& a, const MetricImage& b, float fixed_max);

/// Colour of a signed difference on the diverging map, scale symmetric [-scale, +scale].
glm::u8vec3 difference_color(float value, float scale, const glm::vec3& background);

/// The difference image in colour with a legend bar below ("-S", "0", "+S",
/// "B - A"); scale <= 0: the image's own largest |value| (1 when all zero).
RgbImage colorize_difference(const MetricImage& diff, float scale, LegendPlacement legend = LegendPlacement::bottom);

/// What a choice costs in time and what it changes: one side's closest hits of
/// the view's primary rays, timed on the counter-free fast path.
struct TimedClosestHits {
  std::vector<Hit> hits;        ///< one per ray
  double trace_ms = 0.0;        ///< the median of the passes
  std::uint64_t hit_count = 0;  ///< rays that hit something
};

/// Traces `rays` `passes` times (at least 1) on `threads` threads, and more
/// (up to 64) while the passes so far took under 30 ms together, and keeps
/// the median time: a trace of a fraction of a millisecond read anything up
/// to 10x its time in three passes beside other work (the GUI's A/B dump
/// and window). `progress` is called after each pass, never inside one (it
/// would be timed too); throws BuildCancelled when it returns false.
TimedClosestHits time_closest_hits(const Accelerator& accel, std::span<const Ray> rays, const QueryOptions& query,
                                   unsigned threads, int passes = 3, const ProgressCallback& progress = {});

/// Rays whose hit differs between A and B: one hits and the other misses, or
/// they hit different triangles. Throws std::invalid_argument when the sizes differ.
std::uint64_t hits_changed(std::span<const Hit> a, std::span<const Hit> b);

}  // namespace accelviz
