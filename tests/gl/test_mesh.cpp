// The mesh pass: headlight flat shading by geometric normal, the wireframe
// overlay, and the depth-only mesh under a full-screen heatmap.
#include <cmath>
#include <stdexcept>
#include <vector>

#include "core/query/camera.h"
#include "gl_fixture.h"
#include "ui/render/camera_view.h"

namespace accelviz::test {
namespace mesh_test {

constexpr int kTolerance = 2;

// Shading the mesh shader computes for a point p on a face with normal n
// seen from eye: colour · (0.25 + 0.75·|n·(eye - p)/|eye - p||).
glm::vec3 headlight(const glm::vec3& color, const glm::vec3& n, const glm::vec3& p, const glm::vec3& eye) {
  return color * (0.25f + 0.75f * std::abs(glm::dot(glm::normalize(n), glm::normalize(eye - p))));
}

// Where the primary ray of pixel (x, y) meets the plane dot(n, p) = d.
glm::vec3 pixel_on_plane(const Camera& cam, int x, int y, const glm::vec3& n, float d) {
  const Ray r = primary_ray(cam, x, y, kWidth, kHeight);
  const float t = (d - glm::dot(n, r.origin)) / glm::dot(n, r.direction);
  return r.at(t);
}

class MeshPassTest : public GlTest {};

TEST_F(MeshPassTest, HeadlightFlatShadingFollowsTheGeometricNormal) {
  // A wall tilted 50 degrees about the y axis: its brightness changes across
  // the image only through the direction to the eye.
  const float a = 50.0f * 3.14159265f / 180.0f;
  const glm::vec3 n(std::sin(a), 0.0f, std::cos(a));
  const glm::vec3 u(std::cos(a), 0.0f, -std::sin(a)), v(0.0f, 1.0f, 0.0f);
  const glm::vec3 c0 = -3.0f * u - 3.0f * v, c1 = 3.0f * u - 3.0f * v, c2 = 3.0f * u + 3.0f * v,
                  c3 = -3.0f * u + 3.0f * v;
  const std::vector<Triangle> wall = {{c0, c1, c2}, {c0, c2, c3}};
  renderer_->set_triangles(wall);
  RenderView view;
  view.camera = Camera{};
  view.mesh_color = {0.9f, 0.6f, 0.3f};
  const Rgba8Image img = draw(view);
  int checked = 0;
  for (auto [x, y] : {std::pair{10, 10}, {64, 48}, {100, 60}, {30, 70}, {80, 20}}) {
    const glm::vec3 p = pixel_on_plane(view.camera, x, y, n, 0.0f);
    if (std::abs(glm::dot(p, u)) > 2.9f || std::abs(p.y) > 2.9f) continue;  // off the wall
    ++checked;
    const glm::u8vec4 want = to_rgba8(headlight(view.mesh_color, n, p, view.camera.position));
    EXPECT_LE(channel_diff(img.at(x, y), want), kTolerance)
        << x << "," << y << ": " << describe(img.at(x, y)) << " want " << describe(want);
  }
  EXPECT_GE(checked, 4);
}

TEST_F(MeshPassTest, BackFacesAreShadedLikeFrontFaces) {
  // The same wall wound the other way round: identical picture.
  std::vector<Triangle> front, back;
  add_quad_xy(front, -3.0f, -3.0f, 3.0f, 3.0f, 0.0f);
  for (const Triangle& t : front) back.push_back({t.v0, t.v2, t.v1});
  RenderView view;
  view.camera = look_from({1.0f, 2.0f, 4.0f}, {0.0f, 0.0f, 0.0f});
  renderer_->set_triangles(front);
  const Rgba8Image a = draw(view);
  renderer_->set_triangles(back);
  const Rgba8Image b = draw(view);
  EXPECT_TRUE(a.pixels == b.pixels);
}

TEST_F(MeshPassTest, WireframeDrawsTheTriangleEdges) {
  std::vector<Triangle> wall;
  add_quad_xy(wall, -1.5f, -1.0f, 1.5f, 1.0f, 0.0f);  // diagonal from (-1.5,-1) to (1.5,1)
  renderer_->set_triangles(wall);
  RenderView view;
  view.camera = Camera{};
  view.show_wireframe = true;
  view.wireframe_color = {1.0f, 0.0f, 0.0f, 1.0f};
  const Rgba8Image img = draw(view);
  const CameraMatrices m = renderer_->matrices(view, kWidth, kHeight);
  const glm::u8vec4 red(255, 0, 0, 255);
  auto near_red = [&](const glm::vec3& world) {
    const glm::vec2 p = *project_to_pixel(m, world);
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (pixel_at(img, p + glm::vec2(dx, dy)) == red) return true;
    return false;
  };
  EXPECT_TRUE(near_red({0.0f, 0.0f, 0.0f}));  // the shared diagonal
  EXPECT_TRUE(near_red({0.75f, 0.5f, 0.0f}));
  EXPECT_TRUE(near_red({1.5f, 0.0f, 0.0f}));   // the right border
  EXPECT_TRUE(near_red({0.0f, -1.0f, 0.0f}));  // the bottom border
  // Inside a triangle, away from the edges: shaded, not red.
  const glm::vec2 inside = *project_to_pixel(m, {0.8f, -0.5f, 0.0f});
  EXPECT_GT(channel_diff(pixel_at(img, inside), red), 100);
  view.show_wireframe = false;
  EXPECT_FALSE(draw(view).pixels == img.pixels);
}

// Per-instance colours of a two-level view (Renderer::set_triangle_colors):
// each triangle shaded in its own colour, the same headlight as the flat colour.
TEST_F(MeshPassTest, PerTriangleColoursShadeEachTriangleInItsOwnColour) {
  std::vector<Triangle> wall;
  add_quad_xy(wall, -3.0f, -3.0f, 0.0f, 3.0f, 0.0f);  // left half: triangles 0, 1
  add_quad_xy(wall, 0.0f, -3.0f, 3.0f, 3.0f, 0.0f);   // right half: triangles 2, 3
  renderer_->set_triangles(wall);
  const glm::vec3 left(0.9f, 0.2f, 0.1f), right(0.1f, 0.3f, 0.9f);
  renderer_->set_triangle_colors(std::vector<glm::vec3>{left, left, right, right});
  RenderView view;
  view.camera = Camera{};
  view.mesh_color = {0.5f, 0.5f, 0.5f};
  const glm::vec3 n(0.0f, 0.0f, 1.0f);
  const auto want_at = [&](int x, int y, const glm::vec3& c) {
    return to_rgba8(headlight(c, n, pixel_on_plane(view.camera, x, y, n, 0.0f), view.camera.position));
  };
  Rgba8Image img = draw(view);
  EXPECT_LE(channel_diff(img.at(40, 48), want_at(40, 48, left)), kTolerance) << describe(img.at(40, 48));
  EXPECT_LE(channel_diff(img.at(88, 48), want_at(88, 48, right)), kTolerance) << describe(img.at(88, 48));
  // A colour count that is not the triangle count is refused; the colours stay.
  EXPECT_THROW(renderer_->set_triangle_colors(std::vector<glm::vec3>{left}), std::invalid_argument);
  // Cleared: the flat mesh colour again; new triangles drop the colours too.
  renderer_->set_triangle_colors({});
  img = draw(view);
  EXPECT_LE(channel_diff(img.at(40, 48), want_at(40, 48, view.mesh_color)), kTolerance) << describe(img.at(40, 48));
  renderer_->set_triangle_colors(std::vector<glm::vec3>{left, left, right, right});
  renderer_->set_triangles(wall);
  img = draw(view);
  EXPECT_LE(channel_diff(img.at(88, 48), want_at(88, 48, view.mesh_color)), kTolerance) << describe(img.at(88, 48));
}

TEST_F(MeshPassTest, FullScreenHeatmapKeepsTheMeshDepthForOverlays) {
  std::vector<Triangle> wall;
  add_quad_xy(wall, -3.0f, -3.0f, 3.0f, 3.0f, 0.0f);
  renderer_->set_triangles(wall);
  const glm::vec4 behind_color(1.0f, 0.0f, 1.0f, 1.0f);
  const std::vector<ColoredBox> boxes = {{{{-1.0f, -1.0f, -1.5f}, {1.0f, 1.0f, -0.5f}}, behind_color}};
  renderer_->set_boxes(boxes);
  MetricImage heat;
  heat.width = 4;
  heat.height = 4;
  heat.values.assign(16, 0.5f);
  renderer_->set_heatmap(heat);
  RenderView view;
  view.camera = Camera{};
  view.heatmap.mode = HeatmapMode::full_screen;
  view.heatmap.show_legend = false;
  const Rgba8Image img = draw(view);
  int magenta = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) magenta += channel_diff(img.at(x, y), to_rgba8(glm::vec3(behind_color))) <= 2;
  EXPECT_EQ(magenta, 0) << "the box behind the wall shows through the heatmap";
  // The heatmap itself covers the frame.
  EXPECT_LE(channel_diff(img.at(64, 48), to_rgba8(colormap(ColorMap::viridis, 0.5f / 0.5f))), kTolerance);
}

TEST_F(MeshPassTest, MultisampledFrameResolvesWithSmoothEdges) {
  std::vector<Triangle> tri = {{{-1.0f, -1.0f, 0.0f}, {1.2f, -0.7f, 0.0f}, {-0.2f, 1.1f, 0.0f}}};
  renderer_->set_triangles(tri);
  RenderView view;
  view.camera = Camera{};
  view.background = {0.0f, 0.0f, 0.0f};
  view.mesh_color = {1.0f, 1.0f, 1.0f};
  const Rgba8Image aliased = draw(view);
  view.msaa_samples = 4;
  const Rgba8Image smooth = draw(view);
  ASSERT_EQ(smooth.width, kWidth);
  ASSERT_EQ(smooth.height, kHeight);
  // Without MSAA a pixel is either background or the full shade; with it,
  // edge pixels take values in between.
  auto partial = [](const Rgba8Image& img) {
    const int full = img.at(kWidth / 2, kHeight / 2).x;
    int n = 0;
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) n += img.at(x, y).x > 8 && img.at(x, y).x < full - 8;
    return n;
  };
  EXPECT_EQ(partial(aliased), 0);
  EXPECT_GT(partial(smooth), 20);
}

}  // namespace mesh_test
}  // namespace accelviz::test
