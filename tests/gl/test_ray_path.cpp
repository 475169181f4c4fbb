// A ray path traced from a known pixel is drawn through the pixels the
// camera math predicts: path, hit marker, normal, visited boxes and tested
// primitives.
#include "gl_fixture.h"

#include "core/accel/brute_force.h"
#include "core/accel/bvh/bvh.h"
#include "core/query/camera.h"
#include "ui/render/camera_view.h"

#include <cmath>

namespace accelviz::test {
namespace {

bool neighbourhood_has(const Rgba8Image& img, glm::vec2 p, glm::u8vec4 color, int radius = 1) {
  const int cx = static_cast<int>(std::floor(p.x)), cy = static_cast<int>(std::floor(p.y));
  for (int y = cy - radius; y <= cy + radius; ++y)
    for (int x = cx - radius; x <= cx + radius; ++x)
      if (x >= 0 && y >= 0 && x < img.width && y < img.height && channel_diff(img.at(x, y), color) <= 2) return true;
  return false;
}

bool inside(glm::vec2 p, int margin = 2) {
  return p.x >= margin && p.y >= margin && p.x < kWidth - margin && p.y < kHeight - margin;
}

glm::u8vec4 rgb(const glm::vec4& c) {
  return to_rgba8(glm::vec3(c));
}

class RayPathTest : public GlTest {
 protected:
  void SetUp() override {
    GlTest::SetUp();
    add_quad_xy(wall_, -3.0f, -3.0f, 3.0f, 3.0f, 0.0f);
    renderer_->set_triangles(wall_);
  }

  // The ray of pixel (40, 30) seen from camera A, traced against the wall.
  RayPath trace_known_pixel(Ray* ray_out = nullptr, Hit* hit_out = nullptr) {
    const Ray ray = primary_ray(camera_a_, kPixelX, kPixelY, kWidth, kHeight);
    const BruteForce brute(wall_);
    const Hit hit = brute.closest_hit(ray, QueryOptions{});
    EXPECT_TRUE(hit.valid());
    Aabb bounds;
    for (const Triangle& t : wall_) bounds.extend(t.bounds());
    if (ray_out) *ray_out = ray;
    if (hit_out) *hit_out = hit;
    return make_ray_path(ray, hit, bounds);
  }

  static constexpr int kPixelX = 40, kPixelY = 30;
  std::vector<Triangle> wall_;
  Camera camera_a_{};  // (0, 0, 5) looking down -z
  Camera camera_b_ = look_from({4.0f, 2.5f, 7.5f}, {-0.3f, 0.2f, 2.0f}, 1.0f);
};

TEST_F(RayPathTest, PathFromAKnownPixelIsDrawnThroughTheExpectedPixels) {
  Ray ray;
  Hit hit;
  RayPath path = trace_known_pixel(&ray, &hit);
  renderer_->set_ray_path(path);
  RenderView view;
  view.camera = camera_b_;
  view.background = {0.0f, 0.0f, 0.0f};
  const Rgba8Image img = draw(view);
  const CameraMatrices m = renderer_->matrices(view, kWidth, kHeight);

  // The segment from camera A to the hit point, as camera B sees it.
  const glm::vec2 a = *project_to_pixel(m, ray.origin);
  const glm::vec2 b = *project_to_pixel(m, ray.at(hit.t));
  int checked = 0;
  for (float t = 0.05f; t < 0.9f; t += 0.05f) {
    const glm::vec2 p = glm::mix(a, b, t);
    if (!inside(p)) continue;
    ++checked;
    EXPECT_TRUE(neighbourhood_has(img, p, rgb(path.style.path))) << "no path pixel near " << p.x << "," << p.y;
  }
  EXPECT_GT(checked, 8);

  // The hit marker is a 7-pixel square centred on the projected hit point.
  ASSERT_TRUE(inside(b, 4));
  EXPECT_LE(channel_diff(pixel_at(img, b), rgb(path.style.hit_marker)), 2) << describe(pixel_at(img, b));
  EXPECT_LE(channel_diff(pixel_at(img, b + glm::vec2(2.0f, -2.0f)), rgb(path.style.hit_marker)), 2);

  // The normal (+z, facing the ray) leaves the marker.
  EXPECT_EQ(path.hit_normal, glm::vec3(0.0f, 0.0f, 1.0f));
  for (float t : {0.7f, 0.85f, 1.0f}) {
    const glm::vec2 p = *project_to_pixel(m, path.hit_point + t * path.normal_length * path.hit_normal);
    EXPECT_TRUE(neighbourhood_has(img, p, rgb(path.style.normal))) << "no normal pixel near " << p.x << "," << p.y;
  }
}

TEST_F(RayPathTest, SeenFromItsOwnCameraThePathIsThePixel) {
  const RayPath path = trace_known_pixel();
  renderer_->set_ray_path(path);
  RenderView view;
  view.camera = camera_a_;
  const Rgba8Image img = draw(view);
  EXPECT_LE(channel_diff(img.at(kPixelX, kPixelY), rgb(path.style.hit_marker)), 2);
  // Far from it, the shaded wall.
  EXPECT_GT(channel_diff(img.at(kPixelX + 30, kPixelY + 30), rgb(path.style.hit_marker)), 50);
}

TEST_F(RayPathTest, VisitedBoxesFadeInOrderAndTestedPrimitivesAreHighlighted) {
  RayPath path = trace_known_pixel();
  path.visited = {Aabb{{-2.0f, -2.0f, -0.5f}, {-0.2f, 2.0f, 0.5f}}, Aabb{{0.4f, -1.0f, -0.5f}, {2.5f, 1.0f, 0.5f}}};
  path.highlighted = {0};  // the wall's first triangle: below its diagonal (x0,y0)-(x1,y1)
  renderer_->set_ray_path(path);
  RenderView view;
  view.camera = camera_a_;
  view.background = {0.0f, 0.0f, 0.0f};
  const Rgba8Image img = draw(view);
  const CameraMatrices m = renderer_->matrices(view, kWidth, kHeight);

  // First box in the first colour, last box in the last colour (front faces' vertical edges).
  EXPECT_TRUE(neighbourhood_has(img, *project_to_pixel(m, {-2.0f, 0.3f, 0.5f}), rgb(path.style.first_visit)));
  EXPECT_TRUE(neighbourhood_has(img, *project_to_pixel(m, {2.5f, 0.3f, 0.5f}), rgb(path.style.last_visit)));
  EXPECT_FALSE(neighbourhood_has(img, *project_to_pixel(m, {2.5f, 0.3f, 0.5f}), rgb(path.style.first_visit)));

  // Triangle 0 ((-3,-3), (3,-3), (3,3)) is highlighted; triangle 1 is not.
  // (The frame shows about |x| < 2.8, |y| < 2.1 of the wall.)
  const glm::vec2 in_tri0 = *project_to_pixel(m, {1.5f, -1.5f, 0.0f});
  const glm::vec2 in_tri1 = *project_to_pixel(m, {-1.5f, 1.2f, 0.0f});
  EXPECT_LE(channel_diff(pixel_at(img, in_tri0), rgb(path.style.highlight)), 2);
  EXPECT_GT(channel_diff(pixel_at(img, in_tri1), rgb(path.style.highlight)), 50);

  // Hiding the layer removes all of it.
  view.show_ray_path = false;
  const Rgba8Image hidden = draw(view);
  EXPECT_GT(channel_diff(pixel_at(hidden, in_tri0), rgb(path.style.highlight)), 50);
  EXPECT_GT(channel_diff(hidden.at(kPixelX, kPixelY), rgb(path.style.hit_marker)), 50);
}

TEST(MakeRayPath, MissEndsWhereTheRayLeavesTheScene) {
  const Aabb bounds{{-1.0f, -1.0f, -1.0f}, {1.0f, 1.0f, 1.0f}};
  const Ray ray({0.0f, 0.0f, 5.0f}, {0.0f, 0.0f, -1.0f});
  const RayPath path = make_ray_path(ray, Hit{}, bounds);
  EXPECT_FALSE(path.hit);
  ASSERT_EQ(path.polyline.size(), 2u);
  EXPECT_EQ(path.polyline[0], ray.origin);
  EXPECT_NEAR(path.polyline[1].z, -1.0f, 1e-5f);
  // Missing the box too: it still gets a visible length past the scene.
  const Ray away({3.0f, 3.0f, 3.0f}, {1.0f, 0.0f, 0.0f});
  const RayPath far = make_ray_path(away, Hit{}, bounds);
  EXPECT_GT(glm::length(far.polyline[1] - far.polyline[0]), glm::length(bounds.extent()));
}

TEST(MakeRayPath, NormalFacesTheIncomingRay) {
  Hit hit;
  hit.prim = 0;
  hit.t = 2.0f;
  hit.ng = {0.0f, 0.0f, -1.0f};  // the back side, as seen by a ray going -z
  const RayPath path = make_ray_path(Ray({0.0f, 0.0f, 2.0f}, {0.0f, 0.0f, -1.0f}), hit, Aabb{{-1, -1, -1}, {1, 1, 1}});
  EXPECT_TRUE(path.hit);
  EXPECT_EQ(path.hit_point, glm::vec3(0.0f));
  EXPECT_EQ(path.hit_normal, glm::vec3(0.0f, 0.0f, 1.0f));
}

TEST(MakeRayPath, TraceGivesVisitedBoxesAndTestedPrimitives) {
  std::vector<BvhNode> nodes(3);
  nodes[0].bounds = {{0, 0, 0}, {4, 1, 1}};
  nodes[1].bounds = {{0, 0, 0}, {1, 1, 1}};
  nodes[2].bounds = {{3, 0, 0}, {4, 1, 1}};
  VisitTrace trace;
  using K = VisitStep::Kind;
  trace.steps = {{K::node_entered, 0, 0, 1}, {K::node_missed, 1, 0, 0}, {K::node_entered, 2, 0, 1},
                 {K::prim_miss, 7, 0, 0},    {K::prim_hit, 3, 0, 0},    {K::prim_hit, 7, 0, 0}};
  const std::vector<Aabb> boxes = entered_boxes(trace, nodes);
  ASSERT_EQ(boxes.size(), 2u);
  EXPECT_EQ(boxes[1].lo.x, 3.0f);
  EXPECT_EQ(tested_primitives(trace), (std::vector<std::uint32_t>{7, 3}));
}

TEST(MakeRayPath, InspectorPipelineOnARealBvh) {
  // End to end as the ray inspector does it: trace through a BVH, turn the
  // trace into boxes and primitives. The hit primitive is among the tested.
  std::vector<Triangle> tris;
  for (int i = 0; i < 20; ++i) add_quad_xy(tris, i * 0.5f, 0.0f, i * 0.5f + 0.4f, 1.0f, -0.1f * i);
  const Bvh bvh(tris);
  const Ray ray({2.2f, 0.5f, 5.0f}, {0.0f, 0.0f, -1.0f});
  VisitTrace trace;
  const Hit hit = bvh.closest_hit(ray, QueryOptions{}, nullptr, &trace);
  ASSERT_TRUE(hit.valid());
  const std::vector<Aabb> boxes = entered_boxes(trace, bvh.nodes());
  ASSERT_FALSE(boxes.empty());
  EXPECT_EQ(boxes.front().lo, bvh.nodes()[0].bounds.lo);  // the root comes first
  for (const Aabb& b : boxes) {
    SlabInterval s{};
    EXPECT_TRUE(intersect_slab(b, ray, s));  // every entered box is on the ray
  }
  const auto prims = tested_primitives(trace);
  EXPECT_NE(std::find(prims.begin(), prims.end(), hit.prim), prims.end());
}

}  // namespace
}  // namespace accelviz::test
