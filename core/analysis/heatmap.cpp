#include "core/analysis/heatmap.h"

#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <stdexcept>

#include "core/query/batch.h"
#include "core/query/camera.h"
#include "core/util/file_checks.h"
#include "core/util/json_text.h"
#include "core/util/output_file.h"
#include "core/util/parallel.h"
#include "core/util/timing.h"

namespace accelviz {

// ---- metrics -------------------------------------------------------------------

std::string_view metric_name(HeatMetric m) {
  switch (m) {
    case HeatMetric::nodes:
      return "nodes";
    case HeatMetric::prims:
      return "prims";
    case HeatMetric::cost:
      return "cost";
    case HeatMetric::shaded:
      return "shaded";
    case HeatMetric::depth:
      return "depth";
    case HeatMetric::instances:
      return "instances";
  }
  return "nodes";
}

std::string_view metric_short_label(HeatMetric m) {
  return m == HeatMetric::depth ? "distance" : metric_name(m);
}

std::string_view metric_label(HeatMetric m) {
  switch (m) {
    case HeatMetric::nodes:
      return "nodes visited per ray";
    case HeatMetric::prims:
      return "primitive tests per ray";
    case HeatMetric::cost:
      return "cost per ray (ctrav nodes + cisect prims)";
    case HeatMetric::shaded:
      return "shaded";
    case HeatMetric::depth:
      return "hit distance";
    case HeatMetric::instances:
      return "instances visited per ray";
  }
  return "";
}

namespace {

/// What `structure` calls the nodes it visits, where not "nodes".
std::string_view node_word(std::string_view structure) {
  if (structure == "grid") return "cells";
  if (structure == "voxels") return "octants";
  return {};
}

}  // namespace

std::string metric_label(HeatMetric m, std::string_view structure) {
  const std::string_view word = node_word(structure);
  if (m != HeatMetric::nodes || word.empty()) return std::string(metric_label(m));
  return std::string(word) + " visited per ray";
}

std::string metric_short_label(HeatMetric m, std::string_view structure) {
  const std::string_view word = node_word(structure);
  if (m != HeatMetric::nodes || word.empty()) return std::string(metric_short_label(m));
  return std::string(word);
}

std::string metric_not_counted(HeatMetric m, std::string_view structure) {
  if (m == HeatMetric::prims && structure == "voxels") return "the sparse voxels test no triangles (a hit is a voxel)";
  if (m == HeatMetric::instances && !structure.empty() && structure != "tlas")
    return "only a two-level structure (tlas) enters instances";
  return "";
}

std::optional<HeatMetric> parse_metric(std::string_view name) {
  for (HeatMetric m : {HeatMetric::nodes, HeatMetric::prims, HeatMetric::cost, HeatMetric::shaded, HeatMetric::depth,
                       HeatMetric::instances})
    if (metric_name(m) == name) return m;
  return std::nullopt;
}

bool metric_needs_stats(HeatMetric m) {
  return m == HeatMetric::nodes || m == HeatMetric::prims || m == HeatMetric::cost || m == HeatMetric::instances;
}

bool metric_counts(HeatMetric m) {
  return metric_needs_stats(m) && m != HeatMetric::cost;  // cost weighs its counts with C_trav and C_isect
}

float metric_value(HeatMetric m, const Ray& ray, const Hit& hit, const RayStats& stats, float c_trav, float c_isect) {
  constexpr float kNoValue = std::numeric_limits<float>::quiet_NaN();
  switch (m) {
    case HeatMetric::nodes:
      return static_cast<float>(stats.nodes_visited);
    case HeatMetric::prims:
      return static_cast<float>(stats.prim_tests);
    case HeatMetric::cost:
      return c_trav * static_cast<float>(stats.nodes_visited) + c_isect * static_cast<float>(stats.prim_tests);
    case HeatMetric::shaded: {
      if (!hit.valid()) return kNoValue;
      // Headlight: the light sits at the eye, so N·L is the cosine between the
      // normal and the ray; both sides of a surface are lit.
      const float len = glm::length(ray.direction);
      return len > 0.0f ? std::min(1.0f, std::abs(glm::dot(hit.ng, ray.direction)) / len) : 0.0f;
    }
    case HeatMetric::depth:
      return hit.valid() ? hit.t : kNoValue;
    case HeatMetric::instances:
      return static_cast<float>(stats.instances_visited);
  }
  return kNoValue;
}

MetricImage render_metric(const Accelerator& accel, const Camera& camera, const HeatmapOptions& opts,
                          HeatmapFigures* figures) {
  if (opts.width <= 0 || opts.height <= 0) throw std::invalid_argument("heatmap: image size must be positive");
  const std::size_t n = static_cast<std::size_t>(opts.width) * static_cast<std::size_t>(opts.height);
  const bool counted = metric_needs_stats(opts.metric);
  // Each block's pixels traced and turned into values on the way, 64 rays at a
  // time (one closest_hits call: a BVH walks them several rays in turns), so
  // no image-sized array of rays, hits or counters is made: at 1920x1080 those
  // were 200 MB to allocate and touch, more than the tracing took.
  constexpr std::size_t kRun = 64;
  static_assert(kMetricBlock % kRun == 0);
  const auto w = static_cast<std::size_t>(opts.width);
  MetricImage img;
  const auto t0 = std::chrono::steady_clock::now();
  const bool done = metric_image_by_blocks(
      n, opts, 0.0, figures,
      [&](std::size_t i0, std::size_t i1, float* values) {
        std::array<Ray, kRun> rays;
        std::array<Hit, kRun> hits;
        std::array<RayStats, kRun> stats;
        std::uint64_t hit_count = 0;
        for (std::size_t r0 = i0; r0 < i1; r0 += kRun) {
          const std::size_t count = std::min(kRun, i1 - r0);
          for (std::size_t k = 0; k < count; ++k) {
            const std::size_t i = r0 + k;
            rays[k] = primary_ray(camera, static_cast<int>(i % w), static_cast<int>(i / w), opts.width, opts.height);
            stats[k] = RayStats{};
          }
          accel.closest_hits(std::span<const Ray>(rays.data(), count), std::span<Hit>(hits.data(), count), opts.query,
                             counted ? std::span<RayStats>(stats.data(), count) : std::span<RayStats>{});
          for (std::size_t k = 0; k < count; ++k) {
            values[r0 - i0 + k] = metric_value(opts.metric, rays[k], hits[k], stats[k], opts.c_trav, opts.c_isect);
            if (hits[k].valid()) ++hit_count;
          }
        }
        return hit_count;
      },
      img);
  if (!done) throw BuildCancelled();
  if (figures) set_render_time(*figures, ms_since(t0));
  return img;
}

MetricImage metric_image_from_hits(std::span<const Ray> rays, std::span<const Hit> hits,
                                   std::span<const RayStats> stats, const HeatmapOptions& opts, double trace_ms,
                                   HeatmapFigures* figures) {
  const std::size_t n = hits.size();
  if (rays.size() != n && !(rays.empty() && opts.metric != HeatMetric::shaded))
    throw std::invalid_argument("heatmap: " + std::to_string(rays.size()) + " rays for " + std::to_string(n) + " hits");
  const RayStats none;
  const Ray no_ray;
  MetricImage img;
  HeatmapOptions no_progress = opts;  // values of traced rays: nothing to cancel
  no_progress.progress = nullptr;
  metric_image_by_blocks(
      n, no_progress, trace_ms, figures,
      [&](std::size_t i0, std::size_t i1, float* values) {
        std::uint64_t hit_count = 0;
        for (std::size_t i = i0; i < i1; ++i) {
          values[i - i0] = metric_value(opts.metric, rays.empty() ? no_ray : rays[i], hits[i],
                                        stats.empty() ? none : stats[i], opts.c_trav, opts.c_isect);
          if (hits[i].valid()) ++hit_count;
        }
        return hit_count;
      },
      img);
  return img;
}

void set_render_time(HeatmapFigures& figures, double render_ms) {
  figures.render_ms = render_ms;
  figures.rays_per_s = render_ms > 0.0 ? static_cast<double>(figures.rays) / (render_ms * 1e-3) : 0.0;
}

bool metric_image_by_blocks(std::size_t n, const HeatmapOptions& opts, double trace_ms, HeatmapFigures* figures,
                            const MetricBlockFill& fill, MetricImage& into) {
  into.width = opts.width;
  into.height = opts.height;
  into.metric = opts.metric;
  into.values.resize(n);
  // Blocks of pixels on all threads; each block's sum, maximum and counts are
  // then combined in block order, so the figures do not depend on the threads.
  struct Block {
    double sum = 0.0, max = 0.0;
    std::uint64_t counted = 0, hits = 0;
  };
  std::vector<Block> blocks((n + kMetricBlock - 1) / kMetricBlock);
  BatchOptions batch{.threads = opts.threads, .chunk = 1};
  batch.progress = opts.progress;
  const bool done = for_each_chunk(blocks.size(), batch, [&](std::size_t b0, std::size_t b1) {
    for (std::size_t b = b0; b < b1; ++b) {
      Block& blk = blocks[b];
      const std::size_t i0 = b * kMetricBlock, i1 = std::min(n, i0 + kMetricBlock);
      float* values = into.values.data() + i0;
      blk.hits = fill(i0, i1, values);
      for (std::size_t k = 0; k < i1 - i0; ++k) {
        const float v = values[k];
        if (std::isfinite(v)) {
          blk.sum += v;
          blk.max = blk.counted == 0 ? v : std::max<double>(blk.max, v);
          ++blk.counted;
        }
      }
    }
  });
  double sum = 0.0, max = 0.0;
  std::uint64_t counted = 0, hit_count = 0;
  for (const Block& blk : blocks) {
    hit_count += blk.hits;
    if (blk.counted == 0) continue;
    sum += blk.sum;
    max = counted == 0 ? blk.max : std::max(max, blk.max);
    counted += blk.counted;
  }
  if (figures) {
    figures->rays = n;
    figures->hits = hit_count;
    figures->mean = counted ? sum / static_cast<double>(counted) : 0.0;
    figures->max = max;
    set_render_time(*figures, trace_ms);
  }
  return done;
}

// ---- images --------------------------------------------------------------------

RgbImage::RgbImage(int w, int h, glm::u8vec3 fill) : width(w), height(h) {
  pixels.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3);
  for (std::size_t i = 0; i < pixels.size(); i += 3) {
    pixels[i] = fill.x;
    pixels[i + 1] = fill.y;
    pixels[i + 2] = fill.z;
  }
}

glm::u8vec3 RgbImage::at(int x, int y) const {
  const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 3;
  return {pixels[i], pixels[i + 1], pixels[i + 2]};
}

void RgbImage::set(int x, int y, glm::u8vec3 c) {
  if (x < 0 || y < 0 || x >= width || y >= height) return;
  const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 3;
  pixels[i] = c.x;
  pixels[i + 1] = c.y;
  pixels[i + 2] = c.z;
}

glm::u8vec3 to_rgb8(const glm::vec3& c) {
  auto q = [](float v) {
    v = std::isnan(v) ? 0.0f : std::clamp(v, 0.0f, 1.0f);
    return static_cast<std::uint8_t>(std::lround(v * 255.0f));
  };
  return {q(c.x), q(c.y), q(c.z)};
}

std::optional<LegendPlacement> parse_legend_placement(std::string_view name) {
  if (name == "none") return LegendPlacement::none;
  if (name == "bottom") return LegendPlacement::bottom;
  if (name == "right") return LegendPlacement::right;
  return std::nullopt;
}

ValueRange metric_value_range(const MetricImage& image) {
  // Blocks on all threads, then the extremes of their extremes (the same
  // whatever the order).
  constexpr std::size_t kBlock = 16384;
  constexpr float inf = std::numeric_limits<float>::infinity();
  std::vector<ValueRange> block((image.values.size() + kBlock - 1) / kBlock, ValueRange{inf, -inf});
  parallel_for(block.size(), 0, 4, [&](std::size_t b0, std::size_t b1, unsigned) {
    for (std::size_t b = b0; b < b1; ++b) {
      ValueRange r{inf, -inf};
      for (std::size_t i = b * kBlock; i < std::min(image.values.size(), (b + 1) * kBlock); ++i)
        if (std::isfinite(image.values[i])) {
          r.min = std::min(r.min, image.values[i]);
          r.max = std::max(r.max, image.values[i]);
        }
      block[b] = r;
    }
  });
  ValueRange all{inf, -inf};
  for (const ValueRange& r : block) {
    all.min = std::min(all.min, r.min);
    all.max = std::max(all.max, r.max);
  }
  return all.min <= all.max ? all : ValueRange{};
}

float heatmap_scale_max(const ValueRange& values, float fixed_max) {
  if (fixed_max > 0.0f && std::isfinite(fixed_max)) return fixed_max;
  return values.max > 0.0f ? values.max : 1.0f;
}

float metric_percentile(std::span<const MetricImage* const> images, double percent) {
  std::vector<float> values;
  for (const MetricImage* img : images)
    for (const float v : img->values)
      if (std::isfinite(v) && v > 0.0f) values.push_back(v);
  if (values.empty()) return 0.0f;
  const double p = std::clamp(percent, 0.0, 100.0) / 100.0;
  const std::size_t rank = std::min(
      values.size() - 1, static_cast<std::size_t>(std::ceil(p * static_cast<double>(values.size()))) - (p > 0.0));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(rank), values.end());
  return values[rank];
}

float heatmap_scale_max(const MetricImage& image, float fixed_max) {
  if (fixed_max > 0.0f && std::isfinite(fixed_max)) return fixed_max;
  return heatmap_scale_max(metric_value_range(image), fixed_max);
}

glm::u8vec3 heatmap_color(HeatMetric metric, float value, float scale_max, const ColorizeOptions& opts) {
  if (!std::isfinite(value)) return to_rgb8(opts.background);
  if (metric == HeatMetric::shaded) {
    const float grey = 0.1f + 0.85f * std::clamp(value, 0.0f, 1.0f);
    return to_rgb8(glm::vec3(grey));
  }
  return to_rgb8(colormap(opts.map, value / scale_max));
}

// ---- bitmap font -----------------------------------------------------------------

namespace {

/// 5×7 glyphs with two rows of descender below (g, j, p, q, y, the comma
/// and semicolon, the underscore), one byte per row from the top, bit 4 =
/// the leftmost column. Drawn for this project: digits, letters, and the signs
/// legends, charts and screenshot captions use.
struct Glyph {
  char c;
  std::uint8_t rows[9];
};

constexpr Glyph kFont[] = {
    {'0', {0b01110, 0b10001, 0b10011, 0b10101, 0b11001, 0b10001, 0b01110}},
    {'1', {0b00100, 0b01100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110}},
    {'2', {0b01110, 0b10001, 0b00001, 0b00010, 0b00100, 0b01000, 0b11111}},
    {'3', {0b11111, 0b00010, 0b00100, 0b00010, 0b00001, 0b10001, 0b01110}},
    {'4', {0b00010, 0b00110, 0b01010, 0b10010, 0b11111, 0b00010, 0b00010}},
    {'5', {0b11111, 0b10000, 0b11110, 0b00001, 0b00001, 0b10001, 0b01110}},
    {'6', {0b00110, 0b01000, 0b10000, 0b11110, 0b10001, 0b10001, 0b01110}},
    {'7', {0b11111, 0b00001, 0b00010, 0b00100, 0b01000, 0b01000, 0b01000}},
    {'8', {0b01110, 0b10001, 0b10001, 0b01110, 0b10001, 0b10001, 0b01110}},
    {'9', {0b01110, 0b10001, 0b10001, 0b01111, 0b00001, 0b00010, 0b01100}},
    {'.', {0b00000, 0b00000, 0b00000, 0b00000, 0b00000, 0b01100, 0b01100}},
    {'-', {0b00000, 0b00000, 0b00000, 0b11111, 0b00000, 0b00000, 0b00000}},
    {'+', {0b00000, 0b00100, 0b00100, 0b11111, 0b00100, 0b00100, 0b00000}},
    {':', {0b00000, 0b01100, 0b01100, 0b00000, 0b01100, 0b01100, 0b00000}},
    {'/', {0b00000, 0b00001, 0b00010, 0b00100, 0b01000, 0b10000, 0b00000}},
    {'(', {0b00010, 0b00100, 0b01000, 0b01000, 0b01000, 0b00100, 0b00010}},
    {')', {0b01000, 0b00100, 0b00010, 0b00010, 0b00010, 0b00100, 0b01000}},
    {'=', {0b00000, 0b00000, 0b11111, 0b00000, 0b11111, 0b00000, 0b00000}},
    {',', {0b00000, 0b00000, 0b00000, 0b00000, 0b00000, 0b01100, 0b01100, 0b00100, 0b01000}},
    {'M', {0b10001, 0b11011, 0b10101, 0b10101, 0b10001, 0b10001, 0b10001}},
    {';', {0b00000, 0b00000, 0b01100, 0b01100, 0b00000, 0b01100, 0b01100, 0b00100, 0b01000}},
    {'\'', {0b00100, 0b00100, 0b01000, 0b00000, 0b00000, 0b00000, 0b00000}},
    {'"', {0b01010, 0b01010, 0b01010, 0b00000, 0b00000, 0b00000, 0b00000}},
    {'%', {0b11001, 0b11010, 0b00010, 0b00100, 0b01000, 0b01011, 0b10011}},
    {'_', {0b00000, 0b00000, 0b00000, 0b00000, 0b00000, 0b00000, 0b00000, 0b11111}},
    {'[', {0b01110, 0b01000, 0b01000, 0b01000, 0b01000, 0b01000, 0b01110}},
    {']', {0b01110, 0b00010, 0b00010, 0b00010, 0b00010, 0b00010, 0b01110}},
    {'<', {0b00010, 0b00100, 0b01000, 0b10000, 0b01000, 0b00100, 0b00010}},
    {'>', {0b01000, 0b00100, 0b00010, 0b00001, 0b00010, 0b00100, 0b01000}},
    {'*', {0b00000, 0b00100, 0b10101, 0b01110, 0b10101, 0b00100, 0b00000}},
    {'#', {0b01010, 0b01010, 0b11111, 0b01010, 0b11111, 0b01010, 0b01010}},
    {'!', {0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00000, 0b00100}},
    {'?', {0b01110, 0b10001, 0b00001, 0b00010, 0b00100, 0b00000, 0b00100}},
    {'&', {0b01100, 0b10010, 0b10100, 0b01000, 0b10101, 0b10010, 0b01101}},
    {'|', {0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100}},
    {'~', {0b00000, 0b00000, 0b01000, 0b10101, 0b00010, 0b00000, 0b00000}},
    {'A', {0b01110, 0b10001, 0b10001, 0b11111, 0b10001, 0b10001, 0b10001}},
    {'B', {0b11110, 0b10001, 0b10001, 0b11110, 0b10001, 0b10001, 0b11110}},
    {'C', {0b01110, 0b10001, 0b10000, 0b10000, 0b10000, 0b10001, 0b01110}},
    {'D', {0b11100, 0b10010, 0b10001, 0b10001, 0b10001, 0b10010, 0b11100}},
    {'E', {0b11111, 0b10000, 0b10000, 0b11110, 0b10000, 0b10000, 0b11111}},
    {'F', {0b11111, 0b10000, 0b10000, 0b11110, 0b10000, 0b10000, 0b10000}},
    {'G', {0b01110, 0b10001, 0b10000, 0b10111, 0b10001, 0b10001, 0b01111}},
    {'H', {0b10001, 0b10001, 0b10001, 0b11111, 0b10001, 0b10001, 0b10001}},
    {'I', {0b01110, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110}},
    {'J', {0b00111, 0b00010, 0b00010, 0b00010, 0b00010, 0b10010, 0b01100}},
    {'K', {0b10001, 0b10010, 0b10100, 0b11000, 0b10100, 0b10010, 0b10001}},
    {'L', {0b10000, 0b10000, 0b10000, 0b10000, 0b10000, 0b10000, 0b11111}},
    {'N', {0b10001, 0b10001, 0b11001, 0b10101, 0b10011, 0b10001, 0b10001}},
    {'O', {0b01110, 0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b01110}},
    {'P', {0b11110, 0b10001, 0b10001, 0b11110, 0b10000, 0b10000, 0b10000}},
    {'Q', {0b01110, 0b10001, 0b10001, 0b10001, 0b10101, 0b10010, 0b01101}},
    {'R', {0b11110, 0b10001, 0b10001, 0b11110, 0b10100, 0b10010, 0b10001}},
    {'S', {0b01111, 0b10000, 0b10000, 0b01110, 0b00001, 0b00001, 0b11110}},
    {'T', {0b11111, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100}},
    {'U', {0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b01110}},
    {'V', {0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b01010, 0b00100}},
    {'W', {0b10001, 0b10001, 0b10001, 0b10101, 0b10101, 0b10101, 0b01010}},
    {'X', {0b10001, 0b10001, 0b01010, 0b00100, 0b01010, 0b10001, 0b10001}},
    {'Y', {0b10001, 0b10001, 0b10001, 0b01010, 0b00100, 0b00100, 0b00100}},
    {'Z', {0b11111, 0b00001, 0b00010, 0b00100, 0b01000, 0b10000, 0b11111}},
    {'a', {0b00000, 0b00000, 0b01110, 0b00001, 0b01111, 0b10001, 0b01111}},
    {'b', {0b10000, 0b10000, 0b10110, 0b11001, 0b10001, 0b10001, 0b11110}},
    {'c', {0b00000, 0b00000, 0b01110, 0b10000, 0b10000, 0b10001, 0b01110}},
    {'d', {0b00001, 0b00001, 0b01101, 0b10011, 0b10001, 0b10001, 0b01111}},
    {'e', {0b00000, 0b00000, 0b01110, 0b10001, 0b11111, 0b10000, 0b01110}},
    {'f', {0b00110, 0b01001, 0b01000, 0b11100, 0b01000, 0b01000, 0b01000}},
    {'g', {0b00000, 0b00000, 0b01111, 0b10001, 0b10001, 0b10001, 0b01111, 0b00001, 0b01110}},
    {'h', {0b10000, 0b10000, 0b10110, 0b11001, 0b10001, 0b10001, 0b10001}},
    {'i', {0b00100, 0b00000, 0b01100, 0b00100, 0b00100, 0b00100, 0b01110}},
    {'j', {0b00010, 0b00000, 0b00110, 0b00010, 0b00010, 0b00010, 0b00010, 0b10010, 0b01100}},
    {'k', {0b10000, 0b10000, 0b10010, 0b10100, 0b11000, 0b10100, 0b10010}},
    {'l', {0b01100, 0b00100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110}},
    {'m', {0b00000, 0b00000, 0b11010, 0b10101, 0b10101, 0b10001, 0b10001}},
    {'n', {0b00000, 0b00000, 0b10110, 0b11001, 0b10001, 0b10001, 0b10001}},
    {'o', {0b00000, 0b00000, 0b01110, 0b10001, 0b10001, 0b10001, 0b01110}},
    {'p', {0b00000, 0b00000, 0b11110, 0b10001, 0b10001, 0b10001, 0b11110, 0b10000, 0b10000}},
    {'q', {0b00000, 0b00000, 0b01111, 0b10001, 0b10001, 0b10001, 0b01111, 0b00001, 0b00001}},
    {'r', {0b00000, 0b00000, 0b10110, 0b11001, 0b10000, 0b10000, 0b10000}},
    {'s', {0b00000, 0b00000, 0b01110, 0b10000, 0b01110, 0b00001, 0b11110}},
    {'t', {0b01000, 0b01000, 0b11100, 0b01000, 0b01000, 0b01001, 0b00110}},
    {'u', {0b00000, 0b00000, 0b10001, 0b10001, 0b10001, 0b10011, 0b01101}},
    {'v', {0b00000, 0b00000, 0b10001, 0b10001, 0b10001, 0b01010, 0b00100}},
    {'w', {0b00000, 0b00000, 0b10001, 0b10001, 0b10101, 0b10101, 0b01010}},
    {'x', {0b00000, 0b00000, 0b10001, 0b01010, 0b00100, 0b01010, 0b10001}},
    {'y', {0b00000, 0b00000, 0b10001, 0b10001, 0b10001, 0b10011, 0b01101, 0b00001, 0b01110}},
    {'z', {0b00000, 0b00000, 0b11111, 0b00010, 0b00100, 0b01000, 0b11111}},
};

constexpr int kGlyphW = kFontGlyphW, kGlyphH = kFontGlyphH, kGlyphRows = kFontGlyphRows, kAdvance = kFontAdvance;

const Glyph* find_glyph(char c) {
  for (const Glyph& g : kFont)
    if (g.c == c) return &g;
  return nullptr;
}

void fill_rect(RgbImage& img, int x0, int y0, int w, int h, glm::u8vec3 c) {
  for (int y = std::max(0, y0); y < std::min(img.height, y0 + h); ++y)
    for (int x = std::max(0, x0); x < std::min(img.width, x0 + w); ++x) img.set(x, y, c);
}

}  // namespace

int text_width(std::string_view text, int scale) {
  if (text.empty()) return 0;
  return (static_cast<int>(text.size()) * kAdvance - (kAdvance - kGlyphW)) * scale;
}

void draw_text(RgbImage& img, int x, int y, std::string_view text, glm::u8vec3 color, int scale) {
  for (char c : text) {
    if (const Glyph* g = find_glyph(c)) {
      for (int row = 0; row < kGlyphRows; ++row)
        for (int col = 0; col < kGlyphW; ++col)
          if (g->rows[row] & (1u << (kGlyphW - 1 - col)))
            fill_rect(img, x + col * scale, y + row * scale, scale, scale, color);
    }
    x += kAdvance * scale;
  }
}

void draw_note(RgbImage& img, std::string_view text) {
  if (img.width <= 0 || img.height <= 0) return;
  const int s = img.width >= 480 ? 2 : 1, pad = 4 * s, line_h = (kGlyphRows + 2) * s;
  const int room = std::max(1, (img.width - 2 * pad) / (kAdvance * s));  // characters per line
  std::vector<std::string> lines(1);
  std::size_t at = 0;
  while (at < text.size()) {
    std::size_t end = text.find(' ', at);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view word = text.substr(at, end - at);
    std::string& line = lines.back();
    if (!line.empty() && static_cast<int>(line.size() + 1 + word.size()) > room) lines.emplace_back();
    if (!lines.back().empty()) lines.back() += ' ';
    lines.back() += word;
    at = end + 1;
  }
  const int band = static_cast<int>(lines.size()) * line_h + 2 * pad;
  const int y0 = std::max(0, (img.height - band) / 2);
  fill_rect(img, 0, y0, img.width, std::min(band, img.height - y0), glm::u8vec3(24, 24, 24));
  for (std::size_t k = 0; k < lines.size(); ++k) {
    const int w = text_width(lines[k], s);
    draw_text(img, std::max(pad, (img.width - w) / 2), y0 + pad + static_cast<int>(k) * line_h, lines[k],
              glm::u8vec3(235, 235, 235), s);
  }
}

std::string format_tick(double v) {
  if (v == 0.0 || !std::isfinite(v)) return "0";
  const double a = std::abs(v);
  char buf[32];
  if (a < 1e-3) {
    std::snprintf(buf, sizeof buf, "%.0e", v);
  } else if (a < 999.5) {
    std::snprintf(buf, sizeof buf, "%.3g", v);
  } else if (a < 1e4) {
    std::snprintf(buf, sizeof buf, "%.0f", v);  // "2500" reads better than "2.5e+03"
  } else if (a < 999.5e3) {
    std::snprintf(buf, sizeof buf, "%.3gk", v / 1e3);
  } else {
    std::snprintf(buf, sizeof buf, "%.3gM", v / 1e6);
  }
  return buf;
}

std::vector<std::string> legend_labels(const std::vector<double>& ticks, bool above_top, bool below_bottom) {
  // One unit for the thousands of one legend: "7.5k" beside "10k", not "7500".
  bool kilo = false;
  for (const double v : ticks) kilo = kilo || (std::abs(v) >= 1e4 && std::abs(v) < 999.5e3);
  std::vector<std::string> labels;
  for (const double v : ticks) {
    if (kilo && std::abs(v) >= 999.5 && std::abs(v) < 1e4) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.3gk", v / 1e3);
      labels.emplace_back(buf);
    } else {
      labels.push_back(format_tick(v));
    }
  }
  if (above_top && !labels.empty()) labels.back() += '+';
  if (below_bottom && !labels.empty()) labels.front().insert(0, "<=");
  return labels;
}

std::vector<double> legend_ticks(double lo, double hi, bool whole) {
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return {lo};
  // The round step nearest a quarter of the range (by ratio).
  const double raw = (hi - lo) / 4.0;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (const double m : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    if (whole && m == 2.5) continue;  // 2.5 nodes is no count
    if (std::abs(std::log(m * mag / raw)) < std::abs(std::log(step / raw))) step = m * mag;
  }
  if (whole) step = std::max(1.0, std::round(step));
  std::vector<double> ticks{lo};
  for (double k = std::floor(lo / step) + 1.0;; k += 1.0) {
    const double v = k * step;
    if (v > hi - 0.3 * step) break;
    if (v > lo) ticks.push_back(v);
  }
  ticks.push_back(hi);
  return ticks;
}

// ---- colour mapping and legend ---------------------------------------------------

RgbImage colorize(const MetricImage& image, const ColorizeOptions& opts) {
  const int w = image.width, h = image.height;
  const float scale_max = heatmap_scale_max(image, opts.max);
  const LegendPlacement legend = image.metric == HeatMetric::shaded ? LegendPlacement::none : opts.legend;

  // Legend geometry, in multiples of the glyph scale so it grows with the image.
  const int s = std::max(w, h) >= 480 ? 2 : 1;
  const int pad = 4 * s, glyph_h = kGlyphH * s, bar = 10 * s, tick = 3 * s;
  const std::vector<double> ticks = legend_ticks(0.0, scale_max, metric_counts(image.metric));
  // A fixed top with values above it: its number says so ("20+").
  const bool above_top =
      opts.max > 0.0f && legend != LegendPlacement::none && metric_value_range(image).max > scale_max;
  const std::vector<std::string> labels = legend_labels(ticks, above_top);
  int widest = 0;
  for (const std::string& l : labels) widest = std::max(widest, text_width(l, s));
  // Where tick k sits along the bar: its value's fraction of the range.
  const auto at = [&](std::size_t k) { return scale_max > 0.0f ? ticks[k] / static_cast<double>(scale_max) : 0.0; };
  int extra_w = 0, extra_h = 0;
  if (legend == LegendPlacement::bottom) extra_h = pad + glyph_h + pad + bar + tick + s + glyph_h + pad;
  if (legend == LegendPlacement::right)
    extra_w = std::max(pad + bar + tick + 3 * s + widest + pad,
                       text_width(metric_short_label(image.metric, opts.structure), s) + 2 * pad);

  const glm::u8vec3 panel(24, 24, 24), ink(235, 235, 235);
  RgbImage out;  // every pixel written below: the heatmap's rows on all threads, then the legend's
  out.width = w + extra_w;
  out.height = h + extra_h;
  out.pixels.resize(static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height) * 3);
  fill_rect(out, 0, h, out.width, extra_h, panel);
  // Rows on all threads. A pixel's colour depends on its value alone, and
  // counter metrics take few distinct values, so each band of rows keeps the
  // colours of the last values it saw (a small table indexed by the value's
  // bits) and computes a colour only for a value not in it.
  parallel_for(static_cast<std::size_t>(h), 0, 8, [&](std::size_t y0, std::size_t y1, unsigned) {
    struct Seen {
      std::uint32_t bits = 0;
      bool used = false;
      glm::u8vec3 colour{0};
    };
    std::array<Seen, 512> seen{};
    for (std::size_t y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        const float v = image.at(x, static_cast<int>(y));
        const auto bits = std::bit_cast<std::uint32_t>(v);
        Seen& e = seen[(bits ^ (bits >> 9) ^ (bits >> 18)) % seen.size()];
        if (!e.used || e.bits != bits) e = Seen{bits, true, heatmap_color(image.metric, v, scale_max, opts)};
        out.set(x, static_cast<int>(y), e.colour);
      }
    for (std::size_t y = y0; y < y1; ++y)
      for (int x = w; x < out.width; ++x) out.set(x, static_cast<int>(y), panel);  // beside it: a right legend
  });

  if (legend == LegendPlacement::bottom) {
    const int y0 = h;
    // The longest title that fits: "fixed max" cut to "(fixed max" at 640 wide, "(fi" at 160.
    const std::string note = !opts.scale_note.empty() ? "  (" + opts.scale_note + ")"
                             : opts.max > 0.0f        ? std::string("  (fixed max)")
                                                      : std::string();
    const std::string label = metric_label(image.metric, opts.structure),
                      short_label = metric_short_label(image.metric, opts.structure);
    std::string title = opts.title_prefix + short_label;
    for (const std::string& t : {opts.title_prefix + label + note, opts.title_prefix + short_label + note})
      if (text_width(t, s) <= out.width - 2 * pad) {
        title = t;
        break;
      }
    draw_text(out, pad, y0 + pad, title, ink, s);
    const int margin = std::max(pad, widest / 2 + pad);
    const int xl = margin, xr = std::max(xl + 1, w - 1 - margin);
    const int bar_y = y0 + pad + glyph_h + pad;
    for (int x = xl; x <= xr; ++x) {
      const float t = static_cast<float>(x - xl) / static_cast<float>(xr - xl);
      fill_rect(out, x, bar_y, 1, bar, to_rgb8(colormap(opts.map, t)));
    }
    // Every tick marked; a number drawn where it keeps a glyph's gap from its neighbours: the ends
    // always, an inner one only when it touches neither ("10k10.9k" at 640 wide before).
    const auto label_x = [&](std::size_t k) {
      const int x = xl + static_cast<int>(std::lround(static_cast<double>(xr - xl) * at(k)));
      return std::clamp(x - text_width(labels[k], s) / 2, 0, std::max(0, out.width - text_width(labels[k], s)));
    };
    const std::size_t last = ticks.size() - 1;
    int drawn_end = -1;  // right edge of the last number drawn
    for (std::size_t k = 0; k < ticks.size(); ++k) {
      const int x = xl + static_cast<int>(std::lround(static_cast<double>(xr - xl) * at(k)));
      fill_rect(out, x - (s - 1) / 2, bar_y + bar, s, tick, ink);
      const int lx = label_x(k), lw = text_width(labels[k], s), gap = kAdvance * s;
      const bool inner = k > 0 && k < last;
      if (inner && (lx < drawn_end + gap || lx + lw + gap > label_x(last))) continue;
      draw_text(out, lx, bar_y + bar + tick + s, labels[k], ink, s);
      drawn_end = lx + lw;
    }
  } else if (legend == LegendPlacement::right) {
    const int x0 = w + pad;
    draw_text(out, x0, pad, metric_short_label(image.metric, opts.structure), ink, s);
    const int yt = pad + glyph_h + pad + glyph_h / 2;
    const int yb = std::max(yt + 1, h - 1 - pad - glyph_h / 2);
    for (int y = yt; y <= yb; ++y) {
      const float t = static_cast<float>(yb - y) / static_cast<float>(yb - yt);  // max at the top
      fill_rect(out, x0, y, bar, 1, to_rgb8(colormap(opts.map, t)));
    }
    for (std::size_t k = 0; k < ticks.size(); ++k) {
      const int y = yb - static_cast<int>(std::lround(static_cast<double>(yb - yt) * at(k)));
      fill_rect(out, x0 + bar, y - (s - 1) / 2, tick, s, ink);
      // A gap after the tick so that it does not read as a minus sign.
      draw_text(out, x0 + bar + tick + 3 * s, std::clamp(y - glyph_h / 2, 0, std::max(0, out.height - glyph_h)),
                labels[k], ink, s);
    }
  }
  return out;
}

// ---- PNG I/O ---------------------------------------------------------------------

std::string png_name_problem(const std::string& path) {
  if (lower_extension(path) == ".png") return {};
  if (bare_extension(path) == ".png") return path + ": a PNG file needs a name before .png";
  return path + ": a PNG file's name must end in .png";
}

namespace {

std::uint32_t png_crc(std::string_view bytes) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t n = 0; n < 256; ++n) {
      std::uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[n] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  for (unsigned char b : bytes) c = table[(c ^ b) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

void put_u32(std::string& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out += static_cast<char>((v >> s) & 0xFF);
}

std::uint32_t get_u32(const std::string& in, std::size_t at) {
  std::uint32_t v = 0;
  for (int k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(in[at + static_cast<std::size_t>(k)]);
  return v;
}

constexpr std::string_view kPngSignature("\x89PNG\r\n\x1a\n", 8);

}  // namespace

std::string encode_png(const RgbImage& img, const std::string& path, std::span<const PngText> text) {
  if (const std::string problem = png_name_problem(path); !problem.empty()) throw std::runtime_error(problem);
  if (img.width <= 0 || img.height <= 0) throw std::runtime_error(path + ": cannot write an empty image");
  std::string bytes;
  const int encoded = stbi_write_png_to_func(
      [](void* context, void* data, int size) {
        if (size > 0) static_cast<std::string*>(context)->append(static_cast<const char*>(data), std::size_t(size));
      },
      &bytes, img.width, img.height, 3, img.pixels.data(), img.width * 3);
  if (!encoded) throw std::runtime_error(path + ": the PNG could not be encoded");
  if (text.empty()) return bytes;
  // stb writes IEND last (12 bytes: length 0, type, CRC): the iTXt chunks go before it.
  const std::size_t iend = bytes.size() - 12;
  if (bytes.size() < kPngSignature.size() + 12 || bytes.compare(iend + 4, 4, "IEND") != 0)
    throw std::runtime_error(path + ": the PNG could not be encoded (no end chunk)");
  std::string chunks;
  for (const PngText& t : text) {
    if (t.keyword.empty() || t.keyword.size() > 79 || t.keyword.find('\0') != std::string::npos)
      throw std::invalid_argument("PNG text keyword must be 1-79 characters without NUL: '" + t.keyword + "'");
    // keyword NUL, compression flag 0, method 0, language "" NUL, translated keyword "" NUL, UTF-8 text.
    std::string body = "iTXt" + t.keyword;
    body += std::string("\0\0\0\0\0", 5);
    body +=
        valid_utf8(t.text.substr(0, t.text.find('\0')));  // iTXt is UTF-8: a Latin-1 file name's bytes become U+FFFD
    put_u32(chunks, static_cast<std::uint32_t>(body.size() - 4));
    chunks += body;
    put_u32(chunks, png_crc(body));
  }
  bytes.insert(iend, chunks);
  return bytes;
}

std::vector<PngText> png_text(const std::string& bytes) {
  std::vector<PngText> out;
  if (bytes.compare(0, kPngSignature.size(), kPngSignature) != 0) return out;
  for (std::size_t at = kPngSignature.size(); at + 12 <= bytes.size();) {
    const std::uint32_t length = get_u32(bytes, at);
    if (length > bytes.size() - at - 12) break;
    const std::string type = bytes.substr(at + 4, 4);
    if (type == "iTXt") {
      const std::string body = bytes.substr(at + 8, length);
      const std::size_t key_end = body.find('\0');
      // keyword NUL, flag, method, language NUL, translated keyword NUL, text: uncompressed only.
      if (key_end != std::string::npos && key_end + 2 < body.size() && body[key_end + 1] == 0) {
        const std::size_t lang_end = body.find('\0', key_end + 3);
        const std::size_t trans_end = lang_end == std::string::npos ? lang_end : body.find('\0', lang_end + 1);
        if (trans_end != std::string::npos) out.push_back({body.substr(0, key_end), body.substr(trans_end + 1)});
      }
    }
    if (type == "IEND") break;
    at += 12 + static_cast<std::size_t>(length);
  }
  return out;
}

void write_png(const std::string& path, const RgbImage& img, bool overwrite, std::span<const PngText> text) {
  // Encoded in memory, then written through a temporary beside the file
  // (write_output_file): a failed write never costs the file that was there.
  const std::string bytes = encode_png(img, path, text);
  const OutputWrite w = write_output_file(path, {bytes}, overwrite);
  if (w.exists) throw FileExistsError(path + ": exists (use --force to overwrite)");
  if (!w.ok()) throw std::runtime_error(path + ": " + w.problem);
}

RgbImage read_png(const std::string& path) {
  int w = 0, h = 0, n = 0;
  std::unique_ptr<stbi_uc, void (*)(void*)> data(stbi_load(path.c_str(), &w, &h, &n, 3), stbi_image_free);
  if (!data) throw std::runtime_error(path + ": cannot read image: " + stbi_failure_reason());
  RgbImage img;
  img.width = w;
  img.height = h;
  img.pixels.assign(data.get(), data.get() + static_cast<std::size_t>(w) * h * 3);
  return img;
}

}  // namespace accelviz
