#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

#include "core/accel/brute_force.h"
#include "core/accel/bvh/bvh.h"
#include "core/accel/factory.h"
#include "core/analysis/heatmap.h"
#include "core/query/batch.h"
#include "core/query/camera.h"
#include "core/query/ray_sets.h"
#include "tests/support/temp_dir.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_heatmap {

using namespace accelviz;
namespace fs = std::filesystem;

namespace {

/// A few overlapping triangles at different depths, so that per-pixel box
/// tests, primitive tests and depths all vary across the image.
std::vector<Triangle> tiny_scene() {
  return {
      {{-2, -2, 0}, {2, -2, 0}, {0, 2, 0}},
      {{-1, -1, 1}, {1, -1, 1}, {0, 1, 1}},
      {{0.5f, 0.5f, -1}, {2.5f, 0.5f, -1}, {1.5f, 2.5f, -1}},
      {{-3, 1, 2}, {-1, 1, 2}, {-2, 3, 2}},
  };
}

Camera tiny_camera() {
  return look_at({0.3f, 0.2f, 8.0f}, {0.0f, 0.0f, 0.0f}, 0.9f);
}

}  // namespace

TEST(Heatmap, PixelValuesEqualWhatTheAcceleratorReports) {
  const std::vector<Triangle> tris = tiny_scene();
  const BruteForce accel(tris, BruteForceOptions{.bbox_early_out = true});
  const Camera cam = tiny_camera();
  for (HeatMetric metric : {HeatMetric::prims, HeatMetric::cost, HeatMetric::depth, HeatMetric::shaded}) {
    HeatmapOptions opts;
    opts.metric = metric;
    opts.width = 23;
    opts.height = 17;
    opts.threads = 2;
    opts.c_trav = 1.5f;
    opts.c_isect = 0.5f;
    HeatmapFigures fig;
    const MetricImage img = render_metric(accel, cam, opts, &fig);
    ASSERT_EQ(img.values.size(), 23u * 17u);
    EXPECT_EQ(fig.rays, 23u * 17u);
    std::uint64_t hits = 0;
    double max = 0.0, sum = 0.0;
    int counted = 0;
    for (int y = 0; y < opts.height; ++y) {
      for (int x = 0; x < opts.width; ++x) {
        const Ray ray = primary_ray(cam, x, y, opts.width, opts.height);
        RayStats st;
        const Hit h = accel.closest_hit(ray, opts.query, &st);
        hits += h.valid();
        const float v = img.at(x, y);
        switch (metric) {
          case HeatMetric::prims:
            EXPECT_EQ(v, static_cast<float>(st.prim_tests));
            break;
          case HeatMetric::cost:
            EXPECT_FLOAT_EQ(v, 1.5f * st.nodes_visited + 0.5f * st.prim_tests);
            break;
          case HeatMetric::depth:
            if (h.valid()) {
              EXPECT_EQ(v, h.t);
            } else {
              EXPECT_TRUE(std::isnan(v));
            }
            break;
          case HeatMetric::shaded:
            if (h.valid()) {
              EXPECT_NEAR(v, std::abs(glm::dot(h.ng, ray.direction)), 1e-6f);
            } else {
              EXPECT_TRUE(std::isnan(v));
            }
            break;
          default:
            break;
        }
        if (std::isfinite(v)) {
          max = std::max<double>(max, v);
          sum += v;
          ++counted;
        }
      }
    }
    EXPECT_EQ(fig.hits, hits);
    EXPECT_GT(hits, 0u);
    EXPECT_LT(hits, fig.rays);  // some pixels miss: the test covers both cases
    EXPECT_DOUBLE_EQ(fig.max, max);
    EXPECT_NEAR(fig.mean, sum / counted, 1e-9 * std::max(1.0, max));
    EXPECT_GT(fig.render_ms, 0.0);
  }
}

TEST(Heatmap, BruteForceWithBoxesCountsEveryBoxAsANodeVisit) {
  // brute-bbox is a flat tree of one-triangle leaves: every ray tests every box, and the cost metric
  // (c_trav · nodes + c_isect · prims) counts them; it read 0.46 per ray against the BVH's 3.1 before.
  const std::vector<Triangle> tris = tiny_scene();
  const BruteForce boxes(tris, BruteForceOptions{.bbox_early_out = true}), plain(tris);
  const Ray ray({0.0f, 0.0f, 8.0f}, {0.0f, 0.0f, -1.0f});
  RayStats a, b;
  boxes.closest_hit(ray, {}, &a);
  plain.closest_hit(ray, {}, &b);
  EXPECT_EQ(a.nodes_visited, tris.size());
  EXPECT_EQ(a.box_tests, tris.size());
  EXPECT_LT(a.prim_tests, tris.size());  // the boxes the ray misses skip their triangle
  EXPECT_EQ(b.nodes_visited, 0u);
  EXPECT_EQ(b.prim_tests, tris.size());
  RayStats any;
  boxes.any_hit(ray, {}, &any);
  EXPECT_EQ(any.nodes_visited, any.box_tests);
  EXPECT_GE(any.nodes_visited, 1u);
  // Its SAH: every box (C_trav = 1) plus each triangle with its box's share of the root's area.
  EXPECT_EQ(boxes.build_stats().node_count, tris.size());
  EXPECT_GT(boxes.build_stats().sah_cost, static_cast<double>(tris.size()));
  EXPECT_LT(boxes.build_stats().sah_cost, 2.0 * static_cast<double>(tris.size()));
  EXPECT_EQ(plain.build_stats().sah_cost, static_cast<double>(tris.size()));
}

TEST(Heatmap, PercentileOfTheImagesValuesAboveZero) {
  MetricImage a, b;
  a.width = 5;
  a.height = 1;
  a.values = {1, 2, 3, 4, std::numeric_limits<float>::quiet_NaN()};  // misses do not count
  b.width = 6;
  b.height = 1;
  b.values = {5, 6, 7, 8, 9, 100};
  const MetricImage* one[] = {&a};
  const MetricImage* two[] = {&a, &b};
  EXPECT_EQ(metric_percentile(one, 100.0), 4.0f);
  EXPECT_EQ(metric_percentile(one, 50.0), 2.0f);  // nearest rank: ceil(0.5 * 4) = 2nd
  EXPECT_EQ(metric_percentile(two, 90.0), 9.0f);  // 10 values: the 9th; the outlier 100 is the 10th
  EXPECT_EQ(metric_percentile(two, 100.0), 100.0f);
  EXPECT_EQ(metric_percentile(two, 1.0), 1.0f);
  MetricImage none;
  none.values = {std::numeric_limits<float>::quiet_NaN(), 0.0f};
  const MetricImage* empty[] = {&none};
  EXPECT_EQ(metric_percentile(empty, 99.0), 0.0f);
  // Pixels that counted nothing are left out: the 50th percentile of a mostly empty image is not 0.
  MetricImage sparse;
  sparse.values = {0, 0, 0, 0, 0, 0, 3, 5, 7};
  const MetricImage* background[] = {&sparse};
  EXPECT_EQ(metric_percentile(background, 50.0), 5.0f);
  EXPECT_EQ(metric_percentile(background, 10.0), 3.0f);
}

TEST(Heatmap, PngHasTheColourTheMapGives) {
  const std::vector<Triangle> tris = tiny_scene();
  const BruteForce accel(tris, BruteForceOptions{.bbox_early_out = true});
  HeatmapOptions opts;
  opts.metric = HeatMetric::prims;
  opts.width = 40;
  opts.height = 30;
  const MetricImage img = render_metric(accel, tiny_camera(), opts);
  const test_support::TempDir tmp("heatmap");
  for (ColorMap map : {ColorMap::viridis, ColorMap::turbo}) {
    ColorizeOptions co;
    co.map = map;
    const RgbImage rgb = colorize(img, co);
    EXPECT_EQ(rgb.width, 40);
    EXPECT_GT(rgb.height, 30);  // legend below
    const std::string path = tmp.file(std::string(colormap_name(map)) + ".png");
    write_png(path, rgb);
    const RgbImage back = read_png(path);
    ASSERT_EQ(back.width, rgb.width);
    ASSERT_EQ(back.height, rgb.height);
    EXPECT_EQ(back.pixels, rgb.pixels);
    const float max = heatmap_scale_max(img, 0.0f);
    for (auto [x, y] : {std::pair{20, 15}, std::pair{0, 0}, std::pair{39, 29}, std::pair{10, 20}}) {
      const glm::u8vec3 expected = to_rgb8(colormap(map, img.at(x, y) / max));
      EXPECT_EQ(back.at(x, y), expected) << "pixel " << x << "," << y;
    }
  }
}

TEST(Heatmap, FixedMaxClampsAndBackgroundForMisses) {
  MetricImage img;
  img.width = 3;
  img.height = 1;
  img.metric = HeatMetric::depth;
  img.values = {1.0f, 4.0f, std::nanf("")};
  ColorizeOptions co;
  co.max = 2.0f;
  co.legend = LegendPlacement::none;
  const RgbImage rgb = colorize(img, co);
  ASSERT_EQ(rgb.height, 1);
  EXPECT_EQ(rgb.at(0, 0), to_rgb8(colormap(ColorMap::viridis, 0.5f)));
  EXPECT_EQ(rgb.at(1, 0), to_rgb8(colormap(ColorMap::viridis, 1.0f)));  // clamped
  EXPECT_EQ(rgb.at(2, 0), to_rgb8(co.background));
  EXPECT_FLOAT_EQ(heatmap_scale_max(img, 0.0f), 4.0f);
}

// A grid's "nodes visited" are the cells it steps through, the sparse voxels'
// the octants: the legend says so; other structures keep the metric's words.
// Metrics a structure cannot count by its nature say why.
TEST(Heatmap, LegendTitlesInTheStructuresWords) {
  EXPECT_EQ(metric_label(HeatMetric::nodes, "grid"), "cells visited per ray");
  EXPECT_EQ(metric_short_label(HeatMetric::nodes, "grid"), "cells");
  EXPECT_EQ(metric_label(HeatMetric::nodes, "voxels"), "octants visited per ray");
  EXPECT_EQ(metric_label(HeatMetric::nodes, "bvh"), "nodes visited per ray");
  EXPECT_EQ(metric_label(HeatMetric::nodes, ""), "nodes visited per ray");
  EXPECT_EQ(metric_label(HeatMetric::prims, "grid"), "primitive tests per ray");
  EXPECT_EQ(metric_short_label(HeatMetric::depth, "grid"), "distance");
  MetricImage img;
  img.width = 320;
  img.height = 48;
  img.values.assign(320 * 48, 3.0f);
  ColorizeOptions co;
  const RgbImage generic = colorize(img, co);
  co.structure = "bvh";
  EXPECT_EQ(colorize(img, co).pixels, generic.pixels);
  co.structure = "grid";
  EXPECT_NE(colorize(img, co).pixels, generic.pixels) << "the grid's legend title is its own";
  EXPECT_EQ(metric_not_counted(HeatMetric::prims, "voxels"), "the sparse voxels test no triangles (a hit is a voxel)");
  EXPECT_EQ(metric_not_counted(HeatMetric::instances, "bvh"), "only a two-level structure (tlas) enters instances");
  EXPECT_EQ(metric_not_counted(HeatMetric::instances, "tlas"), "");
  EXPECT_EQ(metric_not_counted(HeatMetric::nodes, "voxels"), "");
  EXPECT_EQ(metric_not_counted(HeatMetric::prims, "grid"), "");
}

TEST(Heatmap, LegendPlacements) {
  MetricImage img;
  img.width = 64;
  img.height = 48;
  img.values.assign(64 * 48, 3.0f);
  ColorizeOptions co;
  co.legend = LegendPlacement::right;
  const RgbImage right = colorize(img, co);
  EXPECT_EQ(right.height, 48);
  EXPECT_GT(right.width, 64);
  co.legend = LegendPlacement::bottom;
  const RgbImage bottom = colorize(img, co);
  EXPECT_EQ(bottom.width, 64);
  EXPECT_GT(bottom.height, 48);
  // The bottom legend's gradient spans the map: its left end is the map's 0.
  bool found_low = false;
  for (int y = 48; y < bottom.height && !found_low; ++y)
    for (int x = 0; x < 64 && !found_low; ++x)
      found_low = bottom.at(x, y) == to_rgb8(colormap(ColorMap::viridis, 0.0f));
  EXPECT_TRUE(found_low);
  img.metric = HeatMetric::shaded;
  EXPECT_EQ(colorize(img, co).height, 48);  // no legend for the shaded picture
}

TEST(Heatmap, WritePngTakesOnlyPngNames) {
  const RgbImage img(4, 4, {10, 20, 30});
  const test_support::TempDir tmp("heatmap");
  for (const char* name : {"heat.jpg", "heat", "heat.png.txt", "heat.pn"}) {
    const std::string path = tmp.file(name);
    EXPECT_EQ(png_name_problem(path), path + ": a PNG file's name must end in .png");
    try {
      write_png(path, img);
      ADD_FAILURE() << "wrote " << path;
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), path + ": a PNG file's name must end in .png");
    }
    EXPECT_FALSE(fs::exists(path)) << path;
  }
  for (const char* name : {"upper.PNG", "mixed.Png", "two.dots.png"}) {
    const std::string path = tmp.file(name);
    EXPECT_EQ(png_name_problem(path), "");
    write_png(path, img);
    EXPECT_EQ(read_png(path).width, 4) << path;
  }
}

TEST(Heatmap, WritePngRefusesToOverwrite) {
  const test_support::TempDir tmp("heatmap");
  const std::string path = tmp.file("exists.png");
  const RgbImage img(4, 4, {10, 20, 30});
  write_png(path, img);
  try {
    write_png(path, RgbImage(2, 2));
    ADD_FAILURE() << "overwrote";
  } catch (const FileExistsError& e) {  // its own type: the GUI words it its own way
    EXPECT_EQ(std::string(e.what()), path + ": exists (use --force to overwrite)");
  }
  EXPECT_EQ(read_png(path).width, 4);
  write_png(path, RgbImage(2, 2), /*overwrite=*/true);
  EXPECT_EQ(read_png(path).width, 2);
  fs::remove(path);
  EXPECT_THROW(read_png(path), std::runtime_error);
}

// The caption and the program ride in the file as iTXt chunks: a viewer shows them, the
// pixels stay the same, and the chunks' lengths and CRCs are right (stb reads the file back).
TEST(Heatmap, PngCarriesItsTextBesideThePixels) {
  const test_support::TempDir tmp("heatmap");
  RgbImage img(5, 3, {10, 20, 30});
  img.pixels[7] = 200;
  const std::string plain = encode_png(img, "a.png");
  EXPECT_TRUE(png_text(plain).empty());
  const std::vector<PngText> text{{"Description", "accelviz render 'builtin:teapot?size=2000' -s bvh \xc3\xa9"},
                                  {"Software", "accelviz 0.1.0 (commit abc, Release build)"},
                                  {"Comment", ""}};
  const std::string with = encode_png(img, "a.png", text);
  EXPECT_GT(with.size(), plain.size());
  const std::vector<PngText> back = png_text(with);
  ASSERT_EQ(back.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back[i].keyword, text[i].keyword);
    EXPECT_EQ(back[i].text, text[i].text);
  }
  EXPECT_EQ(with.substr(with.size() - 12, 8), plain.substr(plain.size() - 12, 8));  // IEND still last
  const std::string path = tmp.file("t.png");
  write_png(path, img, false, text);
  const RgbImage read = read_png(path);
  EXPECT_EQ(read.pixels, img.pixels);
  EXPECT_TRUE(png_text("not a png").empty());
  EXPECT_TRUE(png_text(with.substr(0, with.size() / 2)).size() <= 3u);  // cut short: no read past the end
  EXPECT_THROW(encode_png(img, "a.png", std::vector<PngText>{{"", "x"}}), std::invalid_argument);
  // iTXt is UTF-8: a Latin-1 byte of a file name becomes U+FFFD, valid sequences stay.
  const std::vector<PngText> latin1{{"Description", "lat\xe9.glb \xc3\xa9"}};
  EXPECT_EQ(png_text(encode_png(img, "a.png", latin1))[0].text, "lat\xef\xbf\xbd.glb \xc3\xa9");
}

TEST(Heatmap, TickFormatting) {
  EXPECT_EQ(format_tick(0.0), "0");
  EXPECT_EQ(format_tick(12.0), "12");
  EXPECT_EQ(format_tick(0.25), "0.25");
  EXPECT_EQ(format_tick(2500.0), "2500");
  EXPECT_EQ(format_tick(15300.0), "15.3k");
  EXPECT_EQ(format_tick(2.3e6), "2.3M");
  EXPECT_EQ(format_tick(1e-5), "1e-05");
  // Legend ticks: whole numbers for counts (nodes 0..89 read 22.2 and 44.5),
  // round steps otherwise, both ends always, none crowding the top.
  using V = std::vector<double>;
  EXPECT_EQ(legend_ticks(0, 89, true), (V{0, 20, 40, 60, 80, 89}));
  EXPECT_EQ(legend_ticks(0, 200, true), (V{0, 50, 100, 150, 200}));
  EXPECT_EQ(legend_ticks(0, 3, true), (V{0, 1, 2, 3}));
  EXPECT_EQ(legend_ticks(0, 1, true), (V{0, 1}));
  EXPECT_EQ(legend_ticks(0, 7.18, false), (V{0, 2, 4, 6, 7.18}));
  EXPECT_EQ(legend_ticks(0, 1, false), (V{0, 0.25, 0.5, 0.75, 1}));
  EXPECT_EQ(legend_ticks(0, 41, true), (V{0, 10, 20, 30, 41})) << "40 is within half a step of 41";
  EXPECT_EQ(legend_ticks(10, 90, true), (V{10, 20, 40, 60, 80, 90}));
  EXPECT_EQ(legend_ticks(5, 5, true), (V{5}));
  for (const double v : legend_ticks(0, 1234567, true)) EXPECT_EQ(v, std::floor(v));
  // Values above a locked or fixed top: its number says so.
  using S = std::vector<std::string>;
  EXPECT_EQ(legend_labels(V{0, 10, 20}, false), (S{"0", "10", "20"}));
  EXPECT_EQ(legend_labels(V{0, 10, 20}, true), (S{"0", "10", "20+"}));
  EXPECT_EQ(legend_labels(V{}, true), S{});
  // Values below a locked range's low end: its bottom number says so.
  EXPECT_EQ(legend_labels(V{5, 10, 20}, false, true), (S{"<=5", "10", "20"}));
  EXPECT_EQ(legend_labels(V{5, 10, 20}, true, true), (S{"<=5", "10", "20+"}));
  EXPECT_EQ(legend_labels(V{5}, true, true), S{"<=5+"});
  // One unit for the thousands of a legend.
  EXPECT_EQ(legend_labels(V{0, 2500, 5000, 7500, 10000, 10886}, false), (S{"0", "2.5k", "5k", "7.5k", "10k", "10.9k"}));
  EXPECT_EQ(legend_labels(V{0, 2500, 5000}, false), (S{"0", "2500", "5000"}));
}

TEST(Heatmap, ValueRangeSkipsMissingValues) {
  MetricImage img;
  img.width = 4;
  img.height = 1;
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  img.values = {nan, 3.5f, 0.25f, inf};
  const ValueRange r = metric_value_range(img);
  EXPECT_EQ(r.min, 0.25f);
  EXPECT_EQ(r.max, 3.5f);
  img.values = {nan, nan, nan, nan};  // nothing: 0 .. 0, and the automatic top is 1
  EXPECT_EQ(metric_value_range(img).min, 0.0f);
  EXPECT_EQ(metric_value_range(img).max, 0.0f);
  EXPECT_EQ(heatmap_scale_max(img, 0.0f), 1.0f);
  // Large images go through blocks on all threads: the extremes anywhere.
  img.width = 300;
  img.height = 200;
  img.values.assign(60000, 5.0f);
  img.values[17] = 2.0f;
  img.values[59999] = 9.0f;
  EXPECT_EQ(metric_value_range(img).min, 2.0f);
  EXPECT_EQ(metric_value_range(img).max, 9.0f);
}

// A fixed top below the image's largest value: the legend's top number reads
// "10+". Against the same picture clamped to 10 (the same colours, no value
// above the top) only the legend's top number differs.
TEST(Heatmap, FixedMaxBelowTheValuesMarksTheTopNumber) {
  MetricImage img;
  img.width = 64;
  img.height = 48;
  img.metric = HeatMetric::nodes;
  for (int i = 0; i < 64 * 48; ++i) img.values.push_back(static_cast<float>(i % 21));  // 0..20
  MetricImage clamped = img;
  for (float& v : clamped.values) v = std::min(v, 10.0f);
  for (const LegendPlacement where : {LegendPlacement::right, LegendPlacement::bottom}) {
    ColorizeOptions o;
    o.max = 10.0f;
    o.legend = where;
    const RgbImage a = colorize(img, o), b = colorize(clamped, o);
    // The picture is the same (values above the top take its colour)...
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) ASSERT_EQ(a.at(x, y), b.at(x, y)) << x << "," << y;
    // ...the legend is not: a wider right legend (the '+'), or ink where the clamped one has none.
    int differ = a.width != b.width || a.height != b.height ? 1000 : 0;
    if (differ == 0)
      for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) differ += a.at(x, y) != b.at(x, y);
    EXPECT_GT(differ, 3) << "no '+' drawn";
  }
  // A fixed top at the largest value leaves nothing above it: the picture and
  // the right legend (whose title does not name the fixed top) equal the
  // automatic scale's.
  ColorizeOptions fixed, automatic;
  fixed.legend = automatic.legend = LegendPlacement::right;
  fixed.max = 20.0f;
  EXPECT_TRUE(colorize(img, fixed).pixels == colorize(img, automatic).pixels);
}

TEST(Heatmap, BitmapTextDrawsKnownGlyphsOnly) {
  RgbImage img(40, 10, {0, 0, 0});
  draw_text(img, 0, 0, "1", {255, 255, 255}, 1);
  // '1': the stem is column 2, rows 0-6; the base row spans columns 1-3.
  EXPECT_EQ(img.at(2, 0), glm::u8vec3(255));
  EXPECT_EQ(img.at(1, 6), glm::u8vec3(255));
  EXPECT_EQ(img.at(0, 0), glm::u8vec3(0));
  RgbImage blank(40, 10, {0, 0, 0});
  draw_text(blank, 0, 0, "  \t\x7f", {255, 255, 255}, 1);
  EXPECT_EQ(blank.pixels, RgbImage(40, 10, {0, 0, 0}).pixels);
  EXPECT_EQ(text_width("12", 2), 22);
  // Capitals, the signs captions use, and descenders below the 7 rows.
  const auto lit = [](const char* text) {
    RgbImage img(8, 12, {0, 0, 0});
    draw_text(img, 0, 0, text, {255, 255, 255}, 1);
    int n = 0, below = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x)
        if (img.at(x, y).x == 255) {
          ++n;
          below += y >= 7;
        }
    return std::pair{n, below};
  };
  for (const char* c : {"A", "B", "H", "S", "V", "Z", ";", "'", "%", "_", "?", "!", "[", "<", "#", "&"})
    EXPECT_GT(lit(c).first, 0) << c << " draws nothing";
  for (const char* c : {"g", "j", "p", "q", "y", ";", ","}) EXPECT_GT(lit(c).second, 0) << c << " has no descender";
  for (const char* c : {"a", "o", "x", "B", "9"}) EXPECT_EQ(lit(c).second, 0) << c << " runs below the baseline";
}

// ---- the batch tracer under the heatmap (core/query/batch) ----

TEST(Batch, ResultsDoNotDependOnTheThreadCount) {
  const std::vector<Triangle> tris = tiny_scene();
  const BruteForce accel(tris, BruteForceOptions{.bbox_early_out = true});
  const std::vector<Ray> rays = primary_rays(tiny_camera(), 37, 29);
  std::vector<Hit> h1(rays.size()), h3(rays.size());
  std::vector<RayStats> s1(rays.size()), s3(rays.size());
  std::vector<std::uint8_t> o1(rays.size()), o3(rays.size());
  ASSERT_TRUE(trace_closest(accel, rays, h1, {}, 1u, s1));
  ASSERT_TRUE(trace_closest(accel, rays, h3, {}, BatchOptions{.threads = 3, .chunk = 7}, s3));
  ASSERT_TRUE(trace_any(accel, rays, o1, {}, 1u));
  ASSERT_TRUE(trace_any(accel, rays, o3, {}, BatchOptions{.threads = 3, .chunk = 5}));
  for (std::size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(h1[i].prim, h3[i].prim);
    EXPECT_EQ(h1[i].t, h3[i].t);
    EXPECT_EQ(s1[i].prim_tests, s3[i].prim_tests);
    EXPECT_EQ(o1[i], o3[i]);
    EXPECT_EQ(o1[i] != 0, h1[i].valid());
  }
}

TEST(Batch, StatsAreResetPerRay) {
  const std::vector<Triangle> tris = tiny_scene();
  const BruteForce accel(tris);
  const std::vector<Ray> rays = primary_rays(tiny_camera(), 4, 4);
  std::vector<Hit> hits(rays.size());
  std::vector<RayStats> stats(rays.size());
  trace_closest(accel, rays, hits, {}, 2u, stats);
  trace_closest(accel, rays, hits, {}, 2u, stats);  // a second pass must not accumulate
  for (const RayStats& s : stats) EXPECT_EQ(s.prim_tests, tris.size());
}

// A BVH's counted heatmaps take Bvh's closest_hits (several rays in
// turns per chunk): each pixel still shows what the instrumented walk of a
// trace counts for its ray, on one thread and on two, and a cancel still
// throws.
TEST(Heatmap, BvhCountedPixelsEqualTheTracedWalk) {
  std::vector<Triangle> tris = tiny_scene();
  for (int i = 0; i < 40; ++i) {  // enough triangles for a tree of a few levels
    const float x = -3.0f + 0.15f * static_cast<float>(i), z = 0.05f * static_cast<float>(i % 7);
    tris.push_back({{x, -2.5f, z}, {x + 0.4f, -2.5f, z}, {x + 0.2f, 2.5f, z + 0.3f}});
  }
  BvhOptions bo;
  bo.compute_epo = false;
  const Bvh bvh(tris, bo);
  const Camera cam = tiny_camera();
  for (HeatMetric metric : {HeatMetric::nodes, HeatMetric::prims})
    for (unsigned threads : {1u, 2u}) {
      HeatmapOptions opts;
      opts.metric = metric;
      opts.width = 41;
      opts.height = 29;
      opts.threads = threads;
      HeatmapFigures fig;
      const MetricImage img = render_metric(bvh, cam, opts, &fig);
      std::uint64_t hits = 0;
      for (int y = 0; y < opts.height; ++y)
        for (int x = 0; x < opts.width; ++x) {
          RayStats st;
          VisitTrace trace;
          hits += bvh.closest_hit(primary_ray(cam, x, y, opts.width, opts.height), opts.query, &st, &trace).valid();
          EXPECT_EQ(img.at(x, y), static_cast<float>(metric == HeatMetric::nodes ? st.nodes_visited : st.prim_tests));
        }
      EXPECT_EQ(fig.hits, hits);
      EXPECT_GT(hits, 0u);
      EXPECT_LT(hits, fig.rays);
    }
  HeatmapOptions ho;
  ho.width = 32;
  ho.height = 32;
  ho.progress = [](double) { return false; };
  EXPECT_THROW(render_metric(bvh, cam, ho), BuildCancelled);
}

TEST(Batch, ProgressCanCancel) {
  const std::vector<Triangle> tris = tiny_scene();
  const BruteForce accel(tris);
  const std::vector<Ray> rays = primary_rays(tiny_camera(), 64, 64);
  std::vector<Hit> hits(rays.size());
  for (unsigned threads : {1u, 2u}) {
    int calls = 0;
    BatchOptions batch{.threads = threads, .chunk = 64};
    batch.progress = [&](double fraction) {
      EXPECT_GE(fraction, 0.0);
      EXPECT_LE(fraction, 1.0);
      return ++calls < 3;  // cancel at the third report
    };
    EXPECT_FALSE(trace_closest(accel, rays, hits, {}, batch));
    EXPECT_GE(calls, 3);
    int full = 0;
    batch.progress = [&](double fraction) {
      ++full;
      return fraction >= 0.0;
    };
    EXPECT_TRUE(trace_closest(accel, rays, hits, {}, batch));
    EXPECT_GT(full, 0);
  }
  HeatmapOptions ho;
  ho.width = 32;
  ho.height = 32;
  ho.progress = [](double) { return false; };
  EXPECT_THROW(render_metric(accel, tiny_camera(), ho), BuildCancelled);
}

TEST(Batch, TheLastReportIsNeverSkipped) {
  // The first report is slow: the other worker finishes every other chunk
  // meanwhile and finds the callback busy. Its intermediate reports may be
  // skipped, its last (1.0) must wait and come, so a caller always hears the
  // end (the heatmap's cancel test relied on it on a loaded machine).
  for (int round = 0; round < 3; ++round) {
    std::mutex m;
    std::vector<double> seen;
    BatchOptions batch{.threads = 2, .chunk = 1};
    batch.progress = [&](double fraction) {
      bool first;
      {
        std::lock_guard lock(m);
        first = seen.empty();
        seen.push_back(fraction);
      }
      if (first) std::this_thread::sleep_for(std::chrono::milliseconds(50));
      return true;
    };
    EXPECT_TRUE(for_each_chunk(8, batch, [](std::size_t, std::size_t) {}));
    ASSERT_FALSE(seen.empty());
    EXPECT_EQ(seen.back(), 1.0) << "round " << round;
  }
}

TEST(Batch, SizeMismatchThrows) {
  const std::vector<Triangle> tris = tiny_scene();
  const BruteForce accel(tris);
  const std::vector<Ray> rays(10, Ray({0, 0, 5}, {0, 0, -1}));
  std::vector<Hit> hits(9);
  EXPECT_THROW(trace_closest(accel, rays, hits, {}, 1u), std::invalid_argument);
  hits.resize(10);
  std::vector<RayStats> stats(3);
  EXPECT_THROW(trace_closest(accel, rays, hits, {}, 1u, stats), std::invalid_argument);
}

// closest_hits (one call per span; what trace_closest hands each chunk) gives
// every structure's closest_hit per ray: the same hits and, with statistics,
// the same counters, added to what the span held; sizes are checked.
TEST(Batch, ClosestHitsOfASpanEqualClosestHitPerRay) {
  std::vector<Triangle> tris = tiny_scene();
  for (int i = 0; i < 40; ++i) {
    const float x = -3.0f + 0.15f * static_cast<float>(i), z = 0.05f * static_cast<float>(i % 7);
    tris.push_back({{x, -2.5f, z}, {x + 0.4f, -2.5f, z}, {x + 0.2f, 2.5f, z + 0.3f}});
  }
  const std::vector<Ray> rays = primary_rays(tiny_camera(), 23, 17);
  for (const std::string& name : structure_names()) {
    SCOPED_TRACE(name);
    const auto accel = build_accelerator(name, tris, StructureOptions{});
    std::vector<Hit> fast(rays.size()), counted(rays.size());
    std::vector<RayStats> stats(rays.size());
    for (RayStats& st : stats) st.prim_tests = 5;
    accel->closest_hits(rays, fast, {});
    accel->closest_hits(rays, counted, {}, stats);
    std::size_t hits = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      RayStats one;
      const Hit h = accel->closest_hit(rays[i], {}, &one);
      EXPECT_EQ(fast[i].prim, h.prim);
      EXPECT_EQ(fast[i].t, h.t);
      EXPECT_EQ(counted[i].prim, h.prim);
      EXPECT_EQ(counted[i].t, h.t);
      EXPECT_EQ(stats[i].prim_tests, one.prim_tests + 5);
      EXPECT_EQ(stats[i].nodes_visited, one.nodes_visited);
      hits += h.valid();
    }
    EXPECT_GT(hits, 0u);
    EXPECT_LT(hits, rays.size());
    std::vector<Hit> short_hits(rays.size() - 1);
    std::vector<RayStats> short_stats(2);
    EXPECT_THROW(accel->closest_hits(rays, short_hits, {}), std::invalid_argument);
    EXPECT_THROW(accel->closest_hits(rays, fast, {}, short_stats), std::invalid_argument);
  }
}

TEST(Heatmap, RenderedBlockByBlockEveryPixelIsItsOwnRaysValueOnAnyThreads) {
  // render_metric traces each block of 4096 pixels 64 rays at a time, making
  // each ray from its pixel index: 131x67 = 8,777 pixels are two whole blocks
  // and a partial one, rows not a multiple of 64 wide, a last run of 9 rays.
  // Every pixel's value is metric_value of its own ray, hit and counters
  // (Bvh::closest_hit one ray at a time), the figures are those of one pass,
  // on 1, 2 and 3 threads; a cancel mid-image throws.
  const Scene scene = [] {
    Scene s;
    s.triangles = tiny_scene();
    for (int k = 0; k < 40; ++k) {
      const float x = -3.0f + 0.15f * static_cast<float>(k), z = -0.5f * static_cast<float>(k % 5);
      s.triangles.push_back({{x, -2.5f, z}, {x + 0.4f, -2.5f, z}, {x + 0.2f, 2.5f, z + 0.3f}});
    }
    return s;
  }();
  const Bvh bvh(scene.triangles);
  const Camera cam = tiny_camera();
  const int w = 131, h = 67;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  for (HeatMetric metric : {HeatMetric::nodes, HeatMetric::cost, HeatMetric::depth, HeatMetric::shaded}) {
    HeatmapOptions opts{.metric = metric, .width = w, .height = h, .c_trav = 1.25f, .c_isect = 0.75f};
    std::vector<float> expect(n);
    std::uint64_t hit_count = 0, counted = 0;
    double sum = 0.0, max = 0.0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const Ray ray = primary_ray(cam, x, y, w, h);
        RayStats st;
        const Hit hit = bvh.closest_hit(ray, opts.query, &st);
        const float v = metric_value(metric, ray, hit, st, opts.c_trav, opts.c_isect);
        expect[static_cast<std::size_t>(y) * w + x] = v;
        hit_count += hit.valid();
        if (std::isfinite(v)) {
          sum += v;
          max = std::max<double>(max, v);
          ++counted;
        }
      }
    ASSERT_GT(hit_count, n / 10);
    ASSERT_LT(hit_count, n);
    double mean_one_thread = 0.0;
    for (unsigned threads : {1u, 2u, 3u}) {
      opts.threads = threads;
      HeatmapFigures fig;
      const MetricImage img = render_metric(bvh, cam, opts, &fig);
      ASSERT_EQ(img.values.size(), n);
      for (std::size_t i = 0; i < n; ++i)
        ASSERT_EQ(std::bit_cast<std::uint32_t>(img.values[i]), std::bit_cast<std::uint32_t>(expect[i]))
            << metric_name(metric) << " pixel " << i << " on " << threads << " threads";
      EXPECT_EQ(fig.rays, n);
      EXPECT_EQ(fig.hits, hit_count);
      EXPECT_DOUBLE_EQ(fig.max, max);
      EXPECT_NEAR(fig.mean, sum / static_cast<double>(counted), 1e-12 * std::max(1.0, max));
      if (threads == 1) mean_one_thread = fig.mean;
      EXPECT_EQ(fig.mean, mean_one_thread);  // combined in block order whatever the threads
      EXPECT_GT(fig.render_ms, 0.0);
      EXPECT_DOUBLE_EQ(fig.rays_per_s, static_cast<double>(n) / (fig.render_ms * 1e-3));
    }
  }
  int reports = 0;
  HeatmapOptions cancelled{.width = w, .height = h, .threads = 2};
  cancelled.progress = [&](double fraction) {
    EXPECT_GT(fraction, 0.0);
    EXPECT_LE(fraction, 1.0);
    return ++reports < 2;
  };
  EXPECT_THROW(render_metric(bvh, cam, cancelled), BuildCancelled);
  EXPECT_GE(reports, 2);
}

TEST(Heatmap, FiguresOfManyBlocksAreTheOnePassOnesOnAnyThreads) {
  // 30,000 pixels: several of metric_image_from_hits' blocks of 4096, with
  // hits, misses and counters that vary; the image and figures equal a plain
  // pass over the pixels, on one thread and on three.
  const int w = 200, h = 150;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  std::vector<Hit> hits(n);
  std::vector<RayStats> stats(n);
  for (std::size_t i = 0; i < n; ++i) {
    stats[i].nodes_visited = static_cast<std::uint32_t>((i * 2654435761u) % 97);
    stats[i].prim_tests = static_cast<std::uint32_t>(i % 13);
    if (i % 7 != 0) {
      hits[i].prim = static_cast<std::uint32_t>(i);
      hits[i].t = 1.0f + static_cast<float>(i % 1000) * 0.37f;
    }
  }
  const std::vector<Ray> rays = primary_rays(tiny_camera(), w, h);
  for (HeatMetric metric : {HeatMetric::nodes, HeatMetric::depth, HeatMetric::cost}) {
    double sum = 0.0, max = 0.0;
    std::uint64_t counted = 0, hit_count = 0;
    std::vector<float> expect(n);
    HeatmapOptions opts;
    opts.metric = metric;
    opts.width = w;
    opts.height = h;
    opts.c_trav = 1.25f;
    opts.c_isect = 0.75f;
    for (std::size_t i = 0; i < n; ++i) {
      expect[i] = metric_value(metric, rays[i], hits[i], stats[i], opts.c_trav, opts.c_isect);
      hit_count += hits[i].valid();
      if (std::isfinite(expect[i])) {
        sum += expect[i];
        max = std::max<double>(max, expect[i]);
        ++counted;
      }
    }
    for (unsigned threads : {1u, 3u}) {
      opts.threads = threads;
      HeatmapFigures fig;
      // The ray is read by the shaded metric alone: without rays the others give the same.
      const MetricImage img = metric_image_from_hits({}, hits, stats, opts, 2.0, &fig);
      const MetricImage with_rays = metric_image_from_hits(rays, hits, stats, opts, 2.0, nullptr);
      ASSERT_EQ(img.values.size(), n);
      for (std::size_t i = 0; i < n; ++i) {
        ASSERT_EQ(std::bit_cast<std::uint32_t>(img.values[i]), std::bit_cast<std::uint32_t>(expect[i])) << i;
        ASSERT_EQ(std::bit_cast<std::uint32_t>(with_rays.values[i]), std::bit_cast<std::uint32_t>(expect[i])) << i;
      }
      EXPECT_EQ(fig.rays, n);
      EXPECT_EQ(fig.hits, hit_count);
      EXPECT_DOUBLE_EQ(fig.max, max);
      EXPECT_NEAR(fig.mean, sum / static_cast<double>(counted), 1e-12 * max);
      EXPECT_DOUBLE_EQ(fig.rays_per_s, static_cast<double>(n) / 2e-3);
    }
  }
  HeatmapOptions shaded;
  shaded.metric = HeatMetric::shaded;
  shaded.width = w;
  shaded.height = h;
  EXPECT_THROW(metric_image_from_hits({}, hits, stats, shaded, 1.0, nullptr), std::invalid_argument);
  EXPECT_THROW(metric_image_from_hits(std::span<const Ray>(rays).first(5), hits, stats, HeatmapOptions{}, 1.0, nullptr),
               std::invalid_argument);
}

TEST(Heatmap, EveryPixelHasItsValuesColourWhateverTheValuesBefore) {
  // colorize keeps the colours of values it has seen in a small table per band
  // of rows: with many distinct values (table collisions), repeats, NaNs and
  // infinities, every pixel must still have heatmap_color of its own value.
  const int w = 301, h = 203;
  MetricImage img;
  img.width = w;
  img.height = h;
  img.metric = HeatMetric::depth;
  img.values.resize(static_cast<std::size_t>(w) * h);
  std::uint32_t state = 12345;
  for (float& v : img.values) {
    state = state * 1664525u + 1013904223u;
    const std::uint32_t r = state >> 8;
    v = r % 11 == 0   ? std::numeric_limits<float>::quiet_NaN()
        : r % 13 == 0 ? std::numeric_limits<float>::infinity()
        : r % 3 == 0  ? static_cast<float>(r % 40)                     // few values, repeated
                      : static_cast<float>(r % 100000) * 0.001953125f;  // many
  }
  for (LegendPlacement legend : {LegendPlacement::bottom, LegendPlacement::right, LegendPlacement::none}) {
    ColorizeOptions opts;
    opts.legend = legend;
    const RgbImage rgb = colorize(img, opts);
    const float scale_max = heatmap_scale_max(img, opts.max);
    float serial_max = 0.0f;
    for (float v : img.values)
      if (std::isfinite(v)) serial_max = std::max(serial_max, v);
    EXPECT_EQ(scale_max, serial_max);
    ASSERT_GE(rgb.width, w);
    ASSERT_GE(rgb.height, h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        ASSERT_EQ(rgb.at(x, y), heatmap_color(img.metric, img.at(x, y), scale_max, opts)) << x << "," << y;
    // Beside and below the heatmap: the legend's panel colour or its ink, never unwritten black.
    for (int y = 0; y < rgb.height; ++y)
      for (int x = (y < h ? w : 0); x < rgb.width; ++x) ASSERT_NE(rgb.at(x, y), glm::u8vec3(0, 0, 0)) << x << "," << y;
  }
}
}  // namespace unity_test_heatmap
