#include "core/analysis/insight/compare_images.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/query/batch.h"

namespace accelviz {

MetricImage difference_image(const MetricImage& a, const MetricImage& b, ABFigures* figures) {
  if (a.width != b.width || a.height != b.height || a.values.size() != b.values.size())
    throw std::invalid_argument("difference_image: A is " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                                ", B is " + std::to_string(b.width) + "x" + std::to_string(b.height));
  MetricImage d;
  d.width = a.width;
  d.height = a.height;
  d.metric = a.metric;
  d.values.resize(a.values.size());
  ABFigures f;
  for (std::size_t i = 0; i < a.values.size(); ++i) {
    const float va = a.values[i], vb = b.values[i];
    if (!std::isfinite(va) || !std::isfinite(vb)) {
      d.values[i] = std::numeric_limits<float>::quiet_NaN();
      continue;
    }
    d.values[i] = vb - va;
    ++f.pixels;
    f.total_a += va;
    f.total_b += vb;
    f.max_abs_diff = std::max(f.max_abs_diff, static_cast<double>(std::abs(vb - va)));
    if (vb < va) ++f.b_cheaper;
    if (vb > va) ++f.b_dearer;
  }
  if (f.pixels > 0) {
    f.mean_a = f.total_a / static_cast<double>(f.pixels);
    f.mean_b = f.total_b / static_cast<double>(f.pixels);
  }
  if (figures) *figures = f;
  return d;
}

float locked_scale_max(const MetricImage& a, const MetricImage& b, float fixed_max) {
  if (fixed_max > 0.0f) return fixed_max;
  return std::max(heatmap_scale_max(a, 0.0f), heatmap_scale_max(b, 0.0f));
}

glm::u8vec3 difference_color(float value, float scale, const glm::vec3& background) {
  if (!std::isfinite(value)) return to_rgb8(background);
  const float s = scale > 0.0f ? scale : 1.0f;
  return to_rgb8(colormap(ColorMap::diverging, 0.5f + 0.5f * std::clamp(value / s, -1.0f, 1.0f)));
}

RgbImage colorize_difference(const MetricImage& diff, float scale, LegendPlacement legend) {
  float s = scale;
  if (!(s > 0.0f)) {
    s = 0.0f;
    for (const float v : diff.values)
      if (std::isfinite(v)) s = std::max(s, std::abs(v));
    if (s == 0.0f) s = 1.0f;
  }
  const int w = diff.width, h = diff.height;
  const glm::vec3 background{0.3f, 0.3f, 0.3f};
  const int g = std::max(w, h) >= 480 ? 2 : 1;
  const int pad = 4 * g, glyph_h = 7 * g, bar = 10 * g;
  const int extra_h = legend == LegendPlacement::none ? 0 : pad + glyph_h + pad + bar + pad + glyph_h + pad;
  const glm::u8vec3 panel(24, 24, 24), ink(235, 235, 235);
  RgbImage out(w, h + extra_h, panel);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) out.set(x, y, difference_color(diff.at(x, y), s, background));
  if (legend == LegendPlacement::none) return out;
  const std::string title = "b - a  " + std::string(metric_name(diff.metric)) + "  (blue: b cheaper, red: b dearer)";
  draw_text(out, pad, h + pad, title, ink, g);
  const int bar_y = h + pad + glyph_h + pad;
  std::string lo = format_tick(s), hi = lo;
  lo.insert(lo.begin(), '-');  // (insert, not "-" + str: GCC 12 warns falsely on the latter)
  hi.insert(hi.begin(), '+');
  const int xl = pad + text_width(lo, g) / 2, xr = std::max(xl + 1, w - 1 - pad - text_width(hi, g) / 2);
  for (int x = xl; x <= xr; ++x) {
    const float t = static_cast<float>(x - xl) / static_cast<float>(xr - xl);
    const glm::u8vec3 c = to_rgb8(colormap(ColorMap::diverging, t));
    for (int y = bar_y; y < bar_y + bar; ++y) out.set(x, y, c);
  }
  const int ty = bar_y + bar + pad;
  draw_text(out, std::max(0, xl - text_width(lo, g) / 2), ty, lo, ink, g);
  draw_text(out, (xl + xr) / 2 - text_width("0", g) / 2, ty, "0", ink, g);
  draw_text(out, std::max(0, xr - text_width(hi, g) / 2), ty, hi, ink, g);
  return out;
}

TimedClosestHits time_closest_hits(const Accelerator& accel, std::span<const Ray> rays, const QueryOptions& query,
                                   unsigned threads, int passes, const ProgressCallback& progress) {
  TimedClosestHits out;
  out.hits.resize(rays.size());
  std::vector<double> runs;
  const int n = std::max(passes, 1);
  constexpr int kMostPasses = 64;
  constexpr double kEnoughMs = 30.0;  // a short trace: more passes, so that the median is not one unlucky pass
  double total = 0.0;
  for (int k = 0; k < n || (total < kEnoughMs && k < kMostPasses); ++k) {
    // No callback inside a timed pass (it would be timed too): progress and a cancel between passes.
    const auto t0 = std::chrono::steady_clock::now();
    trace_closest(accel, rays, out.hits, query, BatchOptions{threads});
    runs.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    total += runs.back();
    if (progress && !progress(std::min(1.0, static_cast<double>(k + 1) / n))) throw BuildCancelled();
  }
  std::sort(runs.begin(), runs.end());
  out.trace_ms = runs[runs.size() / 2];
  out.hit_count = static_cast<std::uint64_t>(
      std::count_if(out.hits.begin(), out.hits.end(), [](const Hit& h) { return h.valid(); }));
  return out;
}

std::uint64_t hits_changed(std::span<const Hit> a, std::span<const Hit> b) {
  if (a.size() != b.size())
    throw std::invalid_argument("hits_changed: A has " + std::to_string(a.size()) + " hits, B " +
                                std::to_string(b.size()));
  std::uint64_t changed = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    changed += a[i].valid() != b[i].valid() || (a[i].valid() && a[i].prim != b[i].prim);
  return changed;
}

}  // namespace accelviz
