// Heatmaps show each pixel's value in the colour the colour map gives, and
// the legend's gradient runs through the same map.
#include "gl_fixture.h"

#include "core/analysis/colormap.h"
#include "core/analysis/heatmap.h"

#include <cmath>
#include <limits>

namespace accelviz::test {
namespace {

constexpr int kTolerance = 2;

// A metric image with a different value in every pixel: a ramp along x,
// a slower one along y, so a mix-up of rows or columns shows.
MetricImage ramp_image(int w, int h, float scale = 1.0f) {
  MetricImage img;
  img.width = w;
  img.height = h;
  img.metric = HeatMetric::nodes;
  img.values.resize(static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.values[static_cast<std::size_t>(y) * w + x] = scale * (x + 0.37f * y);
  return img;
}

float image_max(const MetricImage& img) {
  float m = 0.0f;
  for (float v : img.values)
    if (std::isfinite(v)) m = std::max(m, v);
  return m;
}

class Heatmap : public GlTest {
 protected:
  RenderView full_screen_view() {
    RenderView view;
    view.heatmap.mode = HeatmapMode::full_screen;
    view.heatmap.show_legend = false;
    view.background = {0.0f, 0.0f, 0.0f};
    return view;
  }
};

TEST_F(Heatmap, EveryPixelShowsItsValueThroughTheColourMap) {
  for (ColorMap map : {ColorMap::viridis, ColorMap::inferno, ColorMap::turbo}) {
    const MetricImage values = ramp_image(kWidth, kHeight);
    renderer_->set_heatmap(values);
    renderer_->set_colormap(map);
    const Rgba8Image img = draw(full_screen_view());
    const float top = image_max(values);
    int worst = 0;
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const glm::u8vec4 want = to_rgba8(colormap(map, values.at(x, y) / top));
        const int d = channel_diff(img.at(x, y), want);
        worst = std::max(worst, d);
        ASSERT_LE(d, kTolerance) << colormap_name(map) << " pixel " << x << "," << y << " value " << values.at(x, y)
                                 << ": got " << describe(img.at(x, y)) << ", want " << describe(want);
      }
    }
    RecordProperty(std::string("worst_") + std::string(colormap_name(map)), worst);
  }
}

TEST_F(Heatmap, KnownPixelMatchesCpuHeatmapColour) {
  // The same pixel through core's CPU heatmap (what `accelviz render` writes).
  const MetricImage values = ramp_image(kWidth, kHeight, 3.0f);
  renderer_->set_heatmap(values);
  const Rgba8Image img = draw(full_screen_view());
  ColorizeOptions cpu;
  const float scale = heatmap_scale_max(values, 0.0f);
  for (auto [x, y] : {std::pair{0, 0}, {17, 5}, {64, 48}, {127, 95}, {100, 3}}) {
    const glm::u8vec3 want = heatmap_color(values.metric, values.at(x, y), scale, cpu);
    EXPECT_LE(channel_diff(img.at(x, y), glm::u8vec4(want, 255)), kTolerance)
        << x << "," << y << ": " << describe(img.at(x, y));
  }
}

TEST_F(Heatmap, FixedRangeClampsAndNanShowsTheBackground) {
  MetricImage values = ramp_image(kWidth, kHeight);
  values.values[static_cast<std::size_t>(10) * kWidth + 20] = std::numeric_limits<float>::quiet_NaN();
  renderer_->set_heatmap(values);
  RenderView view = full_screen_view();
  view.background = {0.2f, 0.4f, 0.6f};
  view.heatmap.auto_scale = false;
  view.heatmap.range_min = 10.0f;
  view.heatmap.range_max = 50.0f;
  const Rgba8Image img = draw(view);
  auto want = [&](float v) { return to_rgba8(colormap(ColorMap::viridis, (v - 10.0f) / 40.0f)); };
  EXPECT_LE(channel_diff(img.at(2, 0), want(10.0f)), kTolerance);     // below the range: first colour
  EXPECT_LE(channel_diff(img.at(120, 50), want(50.0f)), kTolerance);  // above: last colour
  EXPECT_LE(channel_diff(img.at(30, 0), want(30.0f)), kTolerance);    // inside
  EXPECT_EQ(img.at(20, 10), to_rgba8(view.background));               // no value
}

TEST_F(Heatmap, AllZeroImageUsesTheFirstColour) {
  MetricImage values = ramp_image(8, 8, 0.0f);
  renderer_->set_heatmap(values);
  const Rgba8Image img = draw(full_screen_view(), 8, 8);
  EXPECT_LE(channel_diff(img.at(4, 4), to_rgba8(colormap(ColorMap::viridis, 0.0f))), kTolerance);
}

TEST_F(Heatmap, BlendMixesOverTheMeshWithTheOpacity) {
  std::vector<Triangle> wall;
  add_quad_xy(wall, -10.0f, -10.0f, 10.0f, 10.0f, 0.0f);
  renderer_->set_triangles(wall);
  const MetricImage values = ramp_image(kWidth, kHeight);
  renderer_->set_heatmap(values);
  RenderView view;
  view.camera = Camera{};  // head-on: the wall fills the frame, facing the headlight
  view.mesh_color = {0.8f, 0.8f, 0.8f};
  view.heatmap.mode = HeatmapMode::off;
  const Rgba8Image mesh = draw(view);
  view.heatmap.mode = HeatmapMode::blend;
  view.heatmap.opacity = 0.25f;
  view.heatmap.show_legend = false;
  const Rgba8Image blended = draw(view);
  const float top = image_max(values);
  for (auto [x, y] : {std::pair{5, 5}, {64, 48}, {120, 90}}) {
    const glm::vec3 under = glm::vec3(mesh.at(x, y)) / 255.0f;
    const glm::vec3 heat = colormap(ColorMap::viridis, values.at(x, y) / top);
    const glm::u8vec4 want = to_rgba8(glm::mix(under, heat, 0.25f));
    EXPECT_LE(channel_diff(blended.at(x, y), want), kTolerance) << x << "," << y;
    EXPECT_EQ(blended.at(x, y).w, 255);  // the frame stays opaque
  }
}

TEST_F(Heatmap, LegendGradientAndNumbersFollowTheRange) {
  const MetricImage values = ramp_image(kWidth, kHeight);
  renderer_->set_heatmap(values);
  renderer_->set_colormap(ColorMap::inferno);
  RenderView view = full_screen_view();
  view.heatmap.show_legend = true;
  view.heatmap.auto_scale = false;
  view.heatmap.range_min = 0.0f;
  view.heatmap.range_max = 200.0f;
  const LegendLayout legend = renderer_->legend_layout(view, kWidth, kHeight);
  ASSERT_TRUE(legend.visible);
  // Title, then one number per tick from low to high, in core's format.
  ASSERT_EQ(legend.labels.size(), 6u);
  EXPECT_EQ(legend.labels[0].text, "nodes");
  EXPECT_EQ(legend.labels[1].text, format_tick(0.0));
  EXPECT_EQ(legend.labels[3].text, format_tick(100.0));
  EXPECT_EQ(legend.labels[5].text, format_tick(200.0));  // the ramp's values are all below 200
  {
    // A locked top below the ramp's largest value (162.15): its number says so.
    RenderView narrow = view;
    narrow.heatmap.range_max = 100.0f;
    ASSERT_GT(image_max(values), 100.0f);
    EXPECT_EQ(renderer_->legend_layout(narrow, kWidth, kHeight).labels.back().text, format_tick(100.0) + "+");
    EXPECT_EQ(renderer_->legend_layout(narrow, kWidth, kHeight).labels[1].text, format_tick(0.0));
    // A locked bottom above the ramp's smallest value: its number says so too.
    narrow.heatmap.range_min = 10.0f;
    ASSERT_LT(metric_value_range(values).min, 10.0f);
    EXPECT_EQ(renderer_->legend_layout(narrow, kWidth, kHeight).labels[1].text, "<=" + format_tick(10.0));
    narrow.heatmap.auto_scale = true;  // the image's own range: never a sign
    const LegendLayout own = renderer_->legend_layout(narrow, kWidth, kHeight);
    EXPECT_NE(own.labels.back().text.back(), '+') << own.labels.back().text;
    EXPECT_FALSE(own.labels[1].text.starts_with("<=")) << own.labels[1].text;
  }

  const Rgba8Image img = draw(view);
  const auto& bar = legend.bar;
  const int x = (bar.x0 + bar.x1) / 2;
  for (int y = bar.y0; y < bar.y1; y += 3) {
    // uv.y runs from 1 on the top edge to 0 on the bottom edge.
    const float t = (static_cast<float>(bar.y1) - (y + 0.5f)) / static_cast<float>(bar.y1 - bar.y0);
    const glm::u8vec4 want = to_rgba8(colormap(ColorMap::inferno, t));
    EXPECT_LE(channel_diff(img.at(x, y), want), 3) << "bar row " << y << ": " << describe(img.at(x, y));
  }
  // The panel (dark grey, 85% opaque) is over the heatmap...
  {
    const int px = legend.panel.x1 - 2, py = legend.panel.y1 - 2;
    const glm::vec3 under = colormap(ColorMap::inferno, std::min(values.at(px, py) / 200.0f, 1.0f));
    const glm::u8vec4 want = to_rgba8(glm::mix(under, glm::vec3(24.0f / 255.0f), 0.85f));
    EXPECT_LE(channel_diff(img.at(px, py), want), kTolerance) << describe(img.at(px, py));
  }
  // ...and there is ink in each label's box.
  const glm::u8vec4 ink(235, 235, 235, 255);
  for (const LegendLayout::Label& label : legend.labels) {
    int inked = 0;
    for (int yy = label.y; yy < label.y + 7 * legend.scale; ++yy)
      for (int xx = label.x; xx < label.x + text_width(label.text, legend.scale); ++xx)
        inked += channel_diff(img.at(xx, yy), ink) <= 2;
    EXPECT_GT(inked, 3) << "label '" << label.text << "'";
  }
  // Without the legend, those pixels show the heatmap.
  view.heatmap.show_legend = false;
  const Rgba8Image plain = draw(view);
  const glm::u8vec4 under = to_rgba8(colormap(ColorMap::inferno, std::min(values.at(x, bar.y0 + 2) / 200.0f, 1.0f)));
  EXPECT_LE(channel_diff(plain.at(x, bar.y0 + 2), under), kTolerance);
}

TEST_F(Heatmap, LegendScalesUpForLargeImages) {
  renderer_->set_heatmap(ramp_image(64, 64));
  RenderView view = full_screen_view();
  view.heatmap.show_legend = true;
  EXPECT_EQ(renderer_->legend_layout(view, 640, 480).scale, 2);
  EXPECT_EQ(renderer_->legend_layout(view, 320, 240).scale, 1);
  EXPECT_FALSE(renderer_->legend_layout(view, 40, 30).visible);  // no room: none
}

TEST_F(Heatmap, RejectsWrongLutSizeAndImageShape) {
  std::vector<glm::vec3> lut(100, glm::vec3(1.0f));
  EXPECT_THROW(renderer_->set_colormap_lut(lut), std::invalid_argument);
  MetricImage bad = ramp_image(4, 4);
  bad.values.pop_back();
  EXPECT_THROW(renderer_->set_heatmap(bad), std::invalid_argument);
}

TEST_F(Heatmap, CustomLutIsUsed) {
  std::vector<glm::vec3> lut(256);
  for (int i = 0; i < 256; ++i) lut[i] = {i / 255.0f, 0.0f, 1.0f - i / 255.0f};
  renderer_->set_colormap_lut(lut);
  const MetricImage values = ramp_image(kWidth, kHeight);
  renderer_->set_heatmap(values);
  const Rgba8Image img = draw(full_screen_view());
  const float t = values.at(64, 48) / image_max(values);
  EXPECT_LE(channel_diff(img.at(64, 48), to_rgba8({t, 0.0f, 1.0f - t})), kTolerance);
}

}  // namespace
}  // namespace accelviz::test
