// Screenshots hold exactly the frame (legend included), round-trip through
// PNG, and never overwrite a file unless asked.
#include <fstream>

#include "gl_fixture.h"
#include "load_png.h"
#include "ui/render/screenshot.h"

namespace accelviz::test {
namespace {

using test_support::read_file;

class Screenshot : public GlTest {
 protected:
  // A frame with every kind of content: shaded mesh, boxes, heatmap and its legend.
  Rgba8Image busy_frame() {
    std::vector<Triangle> tris;
    add_box(tris, {-0.8f, -0.6f, -0.5f}, {0.6f, 0.7f, 0.4f});
    renderer_->set_triangles(tris);
    const std::vector<ColoredBox> boxes = {{{{-1.0f, -0.8f, -0.6f}, {0.8f, 0.9f, 0.6f}}, {1.0f, 0.8f, 0.1f, 1.0f}}};
    renderer_->set_boxes(boxes);
    MetricImage heat;
    heat.width = kWidth;
    heat.height = kHeight;
    heat.values.resize(kWidth * kHeight);
    for (int i = 0; i < kWidth * kHeight; ++i) heat.values[i] = static_cast<float>(i % kWidth);
    renderer_->set_heatmap(heat);
    RenderView view;
    view.camera = look_from({2.0f, 1.5f, 3.5f}, {0.0f, 0.0f, 0.0f});
    view.heatmap.mode = HeatmapMode::blend;
    view.heatmap.opacity = 0.3f;
    EXPECT_TRUE(renderer_->legend_layout(view, kWidth, kHeight).visible);
    return draw(view);
  }
};

TEST_F(Screenshot, PngRoundTripKeepsEveryPixel) {
  const Rgba8Image frame = busy_frame();
  TempDir dir("screenshot");
  const auto path = dir.path() / "frame.png";
  const SaveResult saved = write_screenshot_png(path, frame);
  ASSERT_TRUE(saved) << saved.error;
  const Rgba8Image back = load_png(path);
  ASSERT_EQ(back.width, kWidth);
  ASSERT_EQ(back.height, kHeight);
  EXPECT_TRUE(back.pixels == frame.pixels) << "PNG differs from the frame read back";
  // Row 0 of the file is the top of the picture: the legend panel is at the top right.
  const LegendLayout legend =
      renderer_->legend_layout(RenderView{.heatmap = {.mode = HeatmapMode::blend}}, kWidth, kHeight);
  ASSERT_TRUE(legend.visible);
  EXPECT_LT(legend.panel.y0, kHeight / 4);
  EXPECT_EQ(back.at(legend.bar.x0 + 2, legend.bar.y0), frame.at(legend.bar.x0 + 2, legend.bar.y0));
}

TEST_F(Screenshot, ReadbackIsTopRowFirst) {
  // Upper half red, lower half blue, made by a heatmap with a two-entry-like LUT.
  std::vector<glm::vec3> lut(256);
  for (int i = 0; i < 256; ++i) lut[i] = i < 128 ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0);
  renderer_->set_colormap_lut(lut);
  MetricImage heat;
  heat.width = 4;
  heat.height = 4;
  heat.values = {1, 1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0};  // first rows (top) = 1
  renderer_->set_heatmap(heat);
  RenderView view;
  view.heatmap.mode = HeatmapMode::full_screen;
  view.heatmap.show_legend = false;
  const Rgba8Image img = draw(view, 8, 8);
  EXPECT_EQ(img.at(3, 0), glm::u8vec4(255, 0, 0, 255));
  EXPECT_EQ(img.at(3, 7), glm::u8vec4(0, 0, 255, 255));
}

TEST_F(Screenshot, RefusesToOverwriteUnlessAsked) {
  const Rgba8Image frame = busy_frame();
  TempDir dir("screenshot");
  const auto path = dir.path() / "frame.png";
  { std::ofstream(path) << "precious"; }
  const SaveResult refused = write_screenshot_png(path, frame);
  EXPECT_FALSE(refused);
  EXPECT_EQ(refused.error, path.string() + ": exists (not overwritten)");
  EXPECT_EQ(read_file(path), "precious");

  const SaveResult forced = write_screenshot_png(path, frame, /*overwrite=*/true);
  ASSERT_TRUE(forced) << forced.error;
  EXPECT_TRUE(load_png(path).pixels == frame.pixels);
}

TEST_F(Screenshot, ReportsUnwritablePaths) {
  const Rgba8Image frame = busy_frame();
  const SaveResult r = write_screenshot_png("/nonexistent-dir/accelviz/frame.png", frame);
  EXPECT_FALSE(r);
  EXPECT_EQ(r.error.rfind("/nonexistent-dir/accelviz/frame.png: ", 0), 0u) << r.error;
  EXPECT_FALSE(write_screenshot_png("/tmp/never.png", Rgba8Image{}));
  // Through core's writer: a name that is not .png is refused, nothing written.
  TempDir dir("screenshot");
  const auto jpg = dir.path() / "frame.jpg";
  const SaveResult named = write_screenshot_png(jpg, frame);
  EXPECT_FALSE(named);
  EXPECT_EQ(named.error, jpg.string() + ": a PNG file's name must end in .png");
  EXPECT_FALSE(std::filesystem::exists(jpg));
}

TEST(ScreenshotPath, NextFreeNameNeverCollides) {
  TempDir dir("screenshot");
  const auto first = next_screenshot_path(dir.path());
  EXPECT_EQ(first.filename(), "accelviz-001.png");
  std::ofstream(first) << "x";
  EXPECT_EQ(next_screenshot_path(dir.path()).filename(), "accelviz-002.png");
  EXPECT_EQ(next_screenshot_path(dir.path(), "bvh").filename(), "bvh-001.png");
}

}  // namespace
}  // namespace accelviz::test
