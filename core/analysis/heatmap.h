#pragma once
// Per-pixel metric images ("heatmaps"): one primary ray per pixel, traced on
// all threads with per-ray statistics, turned into a value per pixel, then
// into an RGB image through a colour map with a legend bar, written as PNG.
// The CPU twin of the GUI's heatmap view, and what `accelviz render` writes.
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/accel/accel.h"
#include "core/analysis/colormap.h"
#include "core/scene/scene.h"

namespace accelviz {

enum class HeatMetric {
  nodes,      ///< RayStats::nodes_visited
  prims,      ///< RayStats::prim_tests
  cost,       ///< c_trav · nodes_visited + c_isect · prim_tests (the SAH's cost model, per ray)
  shaded,     ///< headlight shading |N·L| of the closest hit, grey background: a picture of the scene
  depth,      ///< distance to the closest hit; misses have no value
  instances,  ///< RayStats::instances_visited: instances whose BLAS the ray entered (two-level; 0 elsewhere)
};

std::string_view metric_name(HeatMetric m);   ///< "nodes", "prims", ...
std::string_view metric_label(HeatMetric m);  ///< legend title, e.g. "nodes visited per ray"
/// A narrow legend's title: the name, but "distance" for `depth` (the hit's
/// t, not a tree depth).
std::string_view metric_short_label(HeatMetric m);
/// The same on `structure`, in its own words where the metric counts what it
/// calls otherwise: a grid's nodes visited are cells ("cells visited per
/// ray", "cells"), the sparse voxels' are octants; "" or any other structure:
/// the metric's own words.
std::string metric_label(HeatMetric m, std::string_view structure);
std::string metric_short_label(HeatMetric m, std::string_view structure);
/// Why `structure` leaves the counter metric `m` at 0 on every ray by its
/// nature ("" when it counts it): the sparse voxels test no triangles (a hit
/// is a voxel), only the two-level structure enters instances.
std::string metric_not_counted(HeatMetric m, std::string_view structure);
std::optional<HeatMetric> parse_metric(std::string_view name);
/// Whether the metric needs per-ray counters (a slower, instrumented pass).
bool metric_needs_stats(HeatMetric m);

/// Callers fill it with designated initializers, naming every field they set;
/// c_trav and c_isect are the structure's SAH costs where it has them (the
/// CLI's render, render --compare and raster blend, the GUI's view, compare
/// and scenario jobs).
struct HeatmapOptions {
  HeatMetric metric = HeatMetric::nodes;
  int width = 800;  ///< image size in pixels (the legend is added outside it)
  int height = 600;
  unsigned threads = 0;       ///< 0: all hardware threads
  QueryOptions query;         ///< triangle test, ordered traversal
  float c_trav = 1.0f;        ///< cost metric: cost of a node visit
  float c_isect = 1.0f;       ///< cost metric: cost of a primitive test
  ProgressCallback progress;  ///< optional; false cancels (render_metric then throws BuildCancelled)
};

/// Whether `a` and `b` trace the same image: metric, size, query options and
/// cost weights all equal. `threads` and `progress` are left out on purpose:
/// they change neither the rays nor the values (and a std::function has no
/// ==, so HeatmapOptions cannot have a defaulted operator==).
inline bool same_heatmap_image(const HeatmapOptions& a, const HeatmapOptions& b) {
  return a.metric == b.metric && a.width == b.width && a.height == b.height && a.query == b.query &&
         a.c_trav == b.c_trav && a.c_isect == b.c_isect;
}

/// One float per pixel, row-major from the top-left. NaN means "no value"
/// (a miss, for depth and shaded), drawn as background.
struct MetricImage {
  int width = 0;
  int height = 0;
  HeatMetric metric = HeatMetric::nodes;
  std::vector<float> values;

  float at(int x, int y) const { return values[static_cast<std::size_t>(y) * width + x]; }
};

struct HeatmapFigures {
  std::uint64_t rays = 0;
  std::uint64_t hits = 0;
  double mean = 0.0;        ///< mean over pixels with a value
  double max = 0.0;         ///< maximum over pixels with a value
  double render_ms = 0.0;   ///< wall time of the tracing pass (instrumented when the metric needs stats)
  double rays_per_s = 0.0;  ///< rays / render time
};

/// The value a pixel gets from its ray, hit and counters.
float metric_value(HeatMetric m, const Ray& ray, const Hit& hit, const RayStats& stats, float c_trav, float c_isect);

/// The metric image (and `figures`, when given) of traced primary rays:
/// per pixel metric_value of its ray, hit and statistics (`stats` may be
/// empty when the metric needs none, `rays` when it is not the shaded one:
/// the only metric that reads the ray), the mean and maximum over finite
/// values, and rays/s from `trace_ms`. Shared by the CPU and GPU paths.
MetricImage metric_image_from_hits(std::span<const Ray> rays, std::span<const Hit> hits,
                                   std::span<const RayStats> stats, const HeatmapOptions& opts, double trace_ms,
                                   HeatmapFigures* figures);

/// What fills one block of a metric image: pixels [i0, i1) get their values
/// in values[0, i1 - i0); returns how many of them hit something. Called on
/// all threads at once, for disjoint blocks.
using MetricBlockFill = std::function<std::uint64_t(std::size_t i0, std::size_t i1, float* values)>;

/// Pixels per block of metric_image_by_blocks (the last block may be shorter).
inline constexpr std::size_t kMetricBlock = 4096;

/// The metric image of `n` pixels made in blocks of kMetricBlock on
/// opts.threads threads (dynamic balancing), each filled by `fill`, into
/// `into` (its storage reused: the same size allocates nothing), with
/// `figures` (when given): rays, hits, the mean and maximum over finite
/// values (each block's sum, maximum and counts combined in block order, so
/// they do not depend on the threads), render_ms `trace_ms`. opts gives the
/// size and metric; opts.progress, when set, hears the fraction of blocks
/// done (as for_each_chunk reports it), and false stops the blocks not yet
/// started: then returns false and the image is incomplete.
bool metric_image_by_blocks(std::size_t n, const HeatmapOptions& opts, double trace_ms, HeatmapFigures* figures,
                            const MetricBlockFill& fill, MetricImage& into);

/// Sets render_ms and rays_per_s (figures.rays per render_ms) of `figures`.
void set_render_time(HeatmapFigures& figures, double render_ms);

/// Traces one primary ray per pixel and returns the metric image: block by
/// block on opts.threads threads, each block's rays made, traced (counted
/// when the metric needs statistics) and turned into values in turn, without
/// image-sized arrays of rays, hits or counters. figures->render_ms is the
/// wall time of that pass. Throws BuildCancelled when opts.progress cancels.
MetricImage render_metric(const Accelerator& accel, const Camera& camera, const HeatmapOptions& opts,
                          HeatmapFigures* figures = nullptr);

// ---- images ------------------------------------------------------------------

/// 8-bit RGB, row-major from the top-left, 3 bytes per pixel.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;

  RgbImage() = default;
  RgbImage(int w, int h, glm::u8vec3 fill = {0, 0, 0});
  glm::u8vec3 at(int x, int y) const;
  void set(int x, int y, glm::u8vec3 c);
};

/// [0, 1] colour to 8 bits, rounding to nearest.
glm::u8vec3 to_rgb8(const glm::vec3& c);

enum class LegendPlacement { none, bottom, right };
std::optional<LegendPlacement> parse_legend_placement(std::string_view name);

struct ColorizeOptions {
  ColorMap map = ColorMap::viridis;
  float max = 0.0f;  ///< top of the scale; <= 0: the image's own maximum
  LegendPlacement legend = LegendPlacement::bottom;
  glm::vec3 background{0.3f, 0.3f, 0.3f};  ///< pixels without a value (and the shaded metric's misses)
  /// The bottom legend's title: title_prefix, the metric's label, then
  /// "(fixed max)" for a fixed top or "(scale_note)" when given; shortened
  /// (the short label, then no note) until it fits the image's width.
  std::string title_prefix;  ///< e.g. "A: " for one side of an A/B pair
  std::string scale_note;    ///< e.g. "scale shared with B"
  std::string structure;     ///< the structure traced: the title in its words (metric_label); "" generic
};

/// The smallest and largest finite value of `image` (both 0 when it has none).
struct ValueRange {
  float min = 0.0f, max = 0.0f;
};
ValueRange metric_value_range(const MetricImage& image);

/// The value below which `percent` % of the images' finite values above 0 lie
/// (the nearest rank; 0 when they have none): a colour scale's top that a few
/// outliers (a silhouette's grazing rays) do not set, `render --max p99`. The
/// pixels that counted nothing (rays that missed the scene's box) are left out
/// with the misses: half a soup's image was background, so `p50` came out 0,
/// which is no top, and the scale fell back to the maximum under a legend that
/// said "50th percentile".
float metric_percentile(std::span<const MetricImage* const> images, double percent);

/// Top of the colour scale for `image`: `fixed_max` when > 0, else the image's
/// maximum; never 0 (an all-zero image uses 1) so the scale stays defined.
float heatmap_scale_max(const MetricImage& image, float fixed_max);
/// The same from the image's value range (metric_value_range).
float heatmap_scale_max(const ValueRange& values, float fixed_max);

/// Colour of one metric value under the options (what a pixel of the heatmap
/// area gets); background for NaN; the shaded metric is drawn in grey.
glm::u8vec3 heatmap_color(HeatMetric metric, float value, float scale_max, const ColorizeOptions& opts);

/// The metric image mapped through the colour map, values clamped to
/// [0, scale max], with a legend bar (gradient, ticks, numbers, metric name)
/// below or to the right of the W×H picture. The shaded metric gets no legend.
RgbImage colorize(const MetricImage& image, const ColorizeOptions& opts);

/// Tiny built-in 5×7 bitmap font (digits, letters, punctuation; descenders
/// take two rows below the 7), drawn at an integer scale; unknown characters
/// draw as blanks. Its geometry in font pixels: kFontGlyphW columns,
/// kFontGlyphH rows above the baseline, kFontGlyphRows in all, kFontAdvance
/// from one character to the next.
inline constexpr int kFontGlyphW = 5, kFontGlyphH = 7, kFontGlyphRows = 9, kFontAdvance = 6;
int text_width(std::string_view text, int scale);
void draw_text(RgbImage& img, int x, int y, std::string_view text, glm::u8vec3 color, int scale);

/// A note across the middle of an image, in light text on a dark band, the
/// words wrapped to the image's width: what an image cannot show ("n/a:
/// embree counts nothing per ray" over its all-zero counter image).
void draw_note(RgbImage& img, std::string_view text);

/// A legend number: "0", "12", "0.25", "1.5k", "2.3M", "1e-05".
std::string format_tick(double v);

/// The values a legend over [lo, hi] marks: lo, hi, and between them the
/// multiples of a round step (1, 2 or 5 times a power of ten) that make about
/// four intervals, leaving out one within 0.3 of a step of hi (their labels
/// would touch). With `whole` (counts per ray) the step is a whole number, so
/// no tick reads 22.2 nodes. Ascending; {lo} alone when hi <= lo.
std::vector<double> legend_ticks(double lo, double hi, bool whole);

/// The numbers a legend writes at `ticks` (format_tick), the top one with a
/// "+" when `above_top`: the image has values above the scale's top, drawn
/// in its top colour (a locked or fixed scale); the bottom one with "<="
/// before it when `below_bottom`: values below a locked range's low end, drawn
/// in its bottom colour. A single tick takes both marks.
std::vector<std::string> legend_labels(const std::vector<double>& ticks, bool above_top, bool below_bottom = false);

/// Whether the metric counts whole things per ray (nodes, primitive tests,
/// instances), so that its legend marks whole numbers.
bool metric_counts(HeatMetric m);

/// "" when `path` names a PNG file (its name ends in .png, in any case), else
/// "<path>: a PNG file's name must end in .png". write_png refuses other
/// names (a heatmap saved as "heat.jpg" would be a PNG under a JPEG's name);
/// the CLI and the GUI's scripts check the name before any long work.
std::string png_name_problem(const std::string& path);

/// write_png's refusal of an existing file: callers that speak of it their
/// own way (the GUI: "exists (not overwritten)") catch this type.
class FileExistsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Text a PNG carries beside its pixels, as an uncompressed iTXt chunk
/// (UTF-8): the full caption and the program that drew it, which image
/// viewers and `exiftool` show, and which a caption cut on a small picture
/// no longer says. Keyword: 1-79 Latin-1 letters ("Description", "Software").
struct PngText {
  std::string keyword;
  std::string text;
};

/// Writes a PNG (stb_image_write). Refuses, with FileExistsError "<file>:
/// exists (use --force to overwrite)", when the file exists and `overwrite`
/// is false (the existence check and the creation are one step); a name not
/// ending in .png is png_name_problem's message; other failures are "<file>:
/// <reason>". Throws std::runtime_error.
/// `text`: stored in the file beside the pixels (PngText).
void write_png(const std::string& path, const RgbImage& img, bool overwrite = false,
               std::span<const PngText> text = {});

/// The PNG file's bytes of `img`, for a file named `path` (for a set of files
/// written all or nothing: write_output_files, OutputFolder), with `text` in
/// iTXt chunks before the end. Throws std::runtime_error as write_png does for
/// a name not ending in .png, an empty image or a failed encoding.
std::string encode_png(const RgbImage& img, const std::string& path, std::span<const PngText> text = {});

/// The iTXt chunks (uncompressed) of a PNG file's bytes; empty for none or
/// bytes that are no PNG.
std::vector<PngText> png_text(const std::string& bytes);

/// Reads any image stb_image understands as 8-bit RGB. Throws std::runtime_error "<file>: <reason>".
RgbImage read_png(const std::string& path);

}  // namespace accelviz
