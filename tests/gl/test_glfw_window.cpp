// The window side of the context seam, in a private Xvfb server: the same
// renderer draws the same frame in a GLFW window as headless, and what the
// window shows is exactly what read_pixels returns.
#include "gl_fixture.h"
#include "tests/support/xvfb_server.h"
#include "ui/gl/glfw_context.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <cstring>

namespace accelviz::test {
namespace {

[[maybe_unused]] ::testing::Environment* const x_server =
    ::testing::AddGlobalTestEnvironment(new test_support::PrivateXServer(ACCELVIZ_XVFB, "640x480x24"));

// A frame with mesh, wireframe, boxes and a translucent quad.
RenderView sample_scene(Renderer& r) {
  std::vector<Triangle> tris;
  add_box(tris, {-0.8f, -0.6f, -0.5f}, {0.6f, 0.7f, 0.4f});
  add_quad_xy(tris, -2.0f, -2.0f, 2.0f, 2.0f, -0.6f);
  r.set_triangles(tris);
  const std::vector<ColoredBox> boxes = {{{{-1.0f, -0.8f, -0.6f}, {0.8f, 0.9f, 0.6f}}, {1.0f, 0.8f, 0.1f, 1.0f}}};
  r.set_boxes(boxes);
  const TranslucentQuad q = split_plane_quad(boxes[0].box, 0, 0.1f, {0.3f, 0.6f, 1.0f, 0.3f}, {0.3f, 0.6f, 1.0f, 1.0f});
  r.set_quads(std::span(&q, 1));
  RenderView view;
  view.camera = look_from({2.0f, 1.5f, 3.5f}, {0.0f, 0.0f, 0.0f});
  view.show_wireframe = true;
  return view;
}

// The window's back buffer, rows flipped to top-down.
Rgba8Image read_window(int w, int h) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  std::vector<std::uint8_t> bottom_up(static_cast<std::size_t>(w) * h * 4);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
  check_gl_errors("window readback");
  Rgba8Image img(w, h);
  for (int y = 0; y < h; ++y) std::memcpy(&img.pixels[y * w * 4], &bottom_up[(h - 1 - y) * w * 4], w * 4);
  return img;
}

TEST(GlfwWindow, GivesAnOpenGl45CoreContext) {
  GlfwContext window({.width = kWidth, .height = kHeight, .title = "accelviz test", .visible = true, .vsync = false});
  EXPECT_GE(window.info().major * 10 + window.info().minor, 45) << window.info().version;
  EXPECT_TRUE(window.info().core_profile);
  EXPECT_EQ(window.kind(), "glfw");
  EXPECT_EQ(window.width(), kWidth);
  EXPECT_EQ(window.height(), kHeight);
  EXPECT_NE(window.window(), nullptr);
  EXPECT_FALSE(window.should_close());
}

TEST(GlfwWindow, PresentShowsExactlyTheFrameReadBack) {
  GlfwContext window({.width = kWidth, .height = kHeight, .visible = true, .vsync = false});
  Renderer renderer;
  const RenderView view = sample_scene(renderer);
  renderer.render(view, window.width(), window.height());
  const Rgba8Image frame = renderer.read_pixels();
  renderer.present(window.width(), window.height());
  const Rgba8Image shown = read_window(window.width(), window.height());
  window.swap_buffers();
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      ASSERT_EQ(glm::uvec3(shown.at(x, y)), glm::uvec3(frame.at(x, y))) << "pixel " << x << "," << y;
}

TEST(GlfwWindow, WindowAndHeadlessDrawTheSameFrame) {
  // Both contexts in one process: make_current reloads the GL entry points
  // when switching between GLFW's libGL and OSMesa.
  GlfwContext window({.width = kWidth, .height = kHeight, .visible = false, .vsync = false});
  Renderer in_window;
  const RenderView view = sample_scene(in_window);
  in_window.render(view, kWidth, kHeight);
  const Rgba8Image a = in_window.read_pixels();

  OsMesaContext headless(kWidth, kHeight);
  {
    Renderer offscreen;
    sample_scene(offscreen);
    offscreen.render(view, kWidth, kHeight);
    const Rgba8Image b = offscreen.read_pixels();
    int off = 0;
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) off += channel_diff(a.at(x, y), b.at(x, y)) > 3;
    EXPECT_LE(off, kWidth * kHeight / 200) << off << " pixels differ between window and OSMesa";
  }
  // Back to the window: its renderer still works with the reloaded table.
  window.make_current();
  in_window.render(view, kWidth, kHeight);
  EXPECT_TRUE(in_window.read_pixels().pixels == a.pixels);
}

}  // namespace
}  // namespace accelviz::test
