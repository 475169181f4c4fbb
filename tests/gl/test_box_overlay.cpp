// Box overlays land on the pixels the camera math predicts.
#include "gl_fixture.h"

#include "ui/render/camera_view.h"

#include <array>
#include <cmath>

namespace accelviz::test {
namespace {

const glm::vec3 kBlack(0.0f);
const glm::vec4 kLine(1.0f, 0.5f, 0.0f, 1.0f);

std::array<glm::vec3, 8> corners(const Aabb& b) {
  std::array<glm::vec3, 8> c;
  for (int i = 0; i < 8; ++i) {
    c[i] = {(i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z};
  }
  return c;
}

// The 12 edges as pairs of corner indices: corners differing in one bit.
std::vector<std::pair<int, int>> edges() {
  std::vector<std::pair<int, int>> e;
  for (int a = 0; a < 8; ++a)
    for (int bit : {1, 2, 4})
      if (!(a & bit)) e.push_back({a, a | bit});
  return e;
}

float distance_to_segment(glm::vec2 p, glm::vec2 a, glm::vec2 b) {
  const glm::vec2 ab = b - a;
  const float t = std::clamp(glm::dot(p - a, ab) / std::max(glm::dot(ab, ab), 1e-12f), 0.0f, 1.0f);
  return glm::length(p - (a + t * ab));
}

bool neighbourhood_has(const Rgba8Image& img, glm::vec2 p, glm::u8vec4 color, int radius = 1) {
  const int cx = static_cast<int>(std::floor(p.x)), cy = static_cast<int>(std::floor(p.y));
  for (int y = cy - radius; y <= cy + radius; ++y)
    for (int x = cx - radius; x <= cx + radius; ++x)
      if (x >= 0 && y >= 0 && x < img.width && y < img.height && channel_diff(img.at(x, y), color) <= 2) return true;
  return false;
}

class BoxOverlay : public GlTest {
 protected:
  RenderView boxes_only_view(const Camera& cam) {
    RenderView view;
    view.camera = cam;
    view.background = kBlack;
    view.z_near = 0.1f;
    view.z_far = 50.0f;
    return view;
  }

  // Renders one box and checks every pixel: near a projected edge it may be
  // line-coloured (and along each edge some pixel is), elsewhere background.
  void check_box(const Camera& cam, const Aabb& box) {
    const ColoredBox cb{box, kLine};
    renderer_->set_boxes(std::span(&cb, 1));
    const RenderView view = boxes_only_view(cam);
    const Rgba8Image img = draw(view);
    const CameraMatrices m = renderer_->matrices(view, kWidth, kHeight);

    std::array<glm::vec2, 8> px;
    const auto c = corners(box);
    for (int i = 0; i < 8; ++i) {
      const auto p = project_to_pixel(m, c[i]);
      ASSERT_TRUE(p.has_value());
      px[i] = *p;
    }
    const glm::u8vec4 line = to_rgba8(glm::vec3(kLine));
    const glm::u8vec4 background = to_rgba8(kBlack);

    // Along every edge, on the predicted pixels.
    for (auto [a, b] : edges()) {
      for (float t = 0.05f; t <= 0.951f; t += 0.05f) {
        const glm::vec2 p = glm::mix(px[a], px[b], t);
        if (p.x < 1 || p.y < 1 || p.x > kWidth - 1 || p.y > kHeight - 1) continue;
        EXPECT_TRUE(neighbourhood_has(img, p, line))
            << "no line pixel near (" << p.x << "," << p.y << ") on edge " << a << "-" << b;
      }
    }
    // Every pixel away from the edges, inside or outside the box's outline, is background.
    int line_pixels = 0;
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const glm::vec2 centre(x + 0.5f, y + 0.5f);
        float d = 1e9f;
        for (auto [a, b] : edges()) d = std::min(d, distance_to_segment(centre, px[a], px[b]));
        const glm::u8vec4 got = img.at(x, y);
        if (d > 1.5f) {
          EXPECT_EQ(got, background) << "pixel " << x << "," << y << " is " << describe(got) << ", " << d
                                     << " px from the nearest edge";
        } else if (channel_diff(got, line) <= 2) {
          ++line_pixels;
        }
      }
    }
    EXPECT_GT(line_pixels, 50);
  }
};

TEST_F(BoxOverlay, FrontViewBoxLandsOnProjectedPixels) {
  // Head-on: the front and back faces project to nested rectangles.
  check_box(Camera{}, Aabb{{-1.0f, -0.7f, -0.5f}, {1.2f, 0.9f, 0.6f}});
}

TEST_F(BoxOverlay, ObliqueViewBoxLandsOnProjectedPixels) {
  check_box(look_from({3.0f, 2.2f, 4.0f}, {0.1f, 0.0f, -0.2f}), Aabb{{-1.0f, -0.8f, -0.5f}, {1.2f, 0.9f, 0.6f}});
}

TEST_F(BoxOverlay, CornerPixelsAreLineColoured) {
  const Camera cam = look_from({2.0f, 1.5f, 5.0f}, {0.0f, 0.0f, 0.0f});
  const Aabb box{{-0.6f, -0.5f, -0.4f}, {0.7f, 0.4f, 0.5f}};
  const ColoredBox cb{box, kLine};
  renderer_->set_boxes(std::span(&cb, 1));
  const RenderView view = boxes_only_view(cam);
  const Rgba8Image img = draw(view);
  const CameraMatrices m = renderer_->matrices(view, kWidth, kHeight);
  for (const glm::vec3& c : corners(box)) {
    const glm::vec2 p = *project_to_pixel(m, c);
    EXPECT_TRUE(neighbourhood_has(img, p, to_rgba8(glm::vec3(kLine)))) << p.x << "," << p.y;
  }
}

TEST_F(BoxOverlay, PerBoxColoursAndDepthTestAgainstTheMesh) {
  // A wall at z = 0 hides a box behind it unless boxes are drawn through the mesh.
  std::vector<Triangle> wall;
  add_quad_xy(wall, -3.0f, -3.0f, 3.0f, 3.0f, 0.0f);
  renderer_->set_triangles(wall);
  const glm::vec4 front_color(0.0f, 1.0f, 0.0f, 1.0f), back_color(1.0f, 0.0f, 1.0f, 1.0f);
  const std::vector<ColoredBox> boxes = {
      {{{-1.5f, -0.5f, 0.5f}, {-0.5f, 0.5f, 1.0f}}, front_color},  // in front of the wall
      {{{0.5f, -0.5f, -1.0f}, {1.5f, 0.5f, -0.5f}}, back_color},   // behind it
  };
  renderer_->set_boxes(boxes);
  RenderView view;
  view.camera = Camera{};
  view.background = kBlack;
  auto count = [](const Rgba8Image& img, const glm::vec4& c) {
    int n = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) n += channel_diff(img.at(x, y), to_rgba8(glm::vec3(c))) <= 2;
    return n;
  };
  const Rgba8Image occluded = draw(view);
  EXPECT_GT(count(occluded, front_color), 40);
  EXPECT_EQ(count(occluded, back_color), 0);
  view.boxes_through_mesh = true;
  const Rgba8Image through = draw(view);
  EXPECT_GT(count(through, back_color), 40);
  view.show_boxes = false;
  const Rgba8Image hidden = draw(view);
  EXPECT_EQ(count(hidden, front_color), 0);
}

TEST_F(BoxOverlay, BvhDepthSelectionDrawsThoseNodes) {
  // Two leaves side by side under a root: selecting depth 1 draws exactly
  // the two child boxes, in their depth colour, and not the root.
  std::vector<BvhNode> nodes(3);
  nodes[0] = {{{-1.6f, -0.6f, -0.5f}, {1.6f, 0.6f, 0.5f}}, 1, 0};
  nodes[1] = {{{-1.4f, -0.5f, -0.4f}, {-0.2f, 0.5f, 0.4f}}, 0, 1};
  nodes[2] = {{{0.2f, -0.5f, -0.4f}, {1.4f, 0.5f, 0.4f}}, 1, 1};
  const auto selected = select_bvh_boxes(nodes, {BoxSelection::Mode::depth, 1});
  const auto colored = color_boxes(selected, {BoxColoring::Kind::depth_qualitative});
  renderer_->set_boxes(colored);
  const RenderView view = boxes_only_view(Camera{});
  const Rgba8Image img = draw(view);
  const CameraMatrices m = renderer_->matrices(view, kWidth, kHeight);
  const glm::u8vec4 depth1 = to_rgba8(qualitative_color(1));
  // Left edge of child 1 (front face, mid height), right edge of child 2.
  EXPECT_TRUE(neighbourhood_has(img, *project_to_pixel(m, {-1.4f, 0.0f, 0.4f}), depth1));
  EXPECT_TRUE(neighbourhood_has(img, *project_to_pixel(m, {1.4f, 0.0f, 0.4f}), depth1));
  // The root's outline is not drawn.
  EXPECT_FALSE(neighbourhood_has(img, *project_to_pixel(m, {-1.6f, 0.0f, 0.5f}), depth1, 0));
  EXPECT_EQ(pixel_at(img, *project_to_pixel(m, {-1.6f, 0.0f, 0.5f})), to_rgba8(kBlack));
}

}  // namespace
}  // namespace accelviz::test
