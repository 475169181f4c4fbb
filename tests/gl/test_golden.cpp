// Golden images: whole frames of typical views compared with reviewed PNGs
// in tests/gl/golden/ (per channel within 3, at most 0.5% of pixels off).
// On a mismatch, <name>.actual.png and <name>.diff.png are written to the
// build's tests/gl/golden-out/. To accept an intended change:
//   ACCELVIZ_UPDATE_GOLDEN=1 ctest --test-dir <build> -R 'gl\.Golden\.'
// then look at the new PNGs before committing them.
#include <cstdlib>

#include "core/accel/brute_force.h"
#include "core/analysis/heatmap.h"
#include "core/query/camera.h"
#include "gl_fixture.h"
#include "load_png.h"
#include "ui/render/screenshot.h"

namespace accelviz::test {
namespace {

constexpr int kGoldenW = 160, kGoldenH = 120;
constexpr int kChannelTolerance = 3;
constexpr double kMaxOffFraction = 0.005;

bool updating_goldens() {
  const char* v = std::getenv("ACCELVIZ_UPDATE_GOLDEN");
  return v && std::string(v) == "1";
}

// Off pixels in red (brighter = larger difference) over a dim copy of the golden.
Rgba8Image diff_image(const Rgba8Image& want, const Rgba8Image& got) {
  Rgba8Image out(want.width, want.height);
  for (int y = 0; y < want.height; ++y) {
    for (int x = 0; x < want.width; ++x) {
      const int d = channel_diff(want.at(x, y), got.at(x, y));
      if (d > kChannelTolerance) {
        out.set(x, y, {static_cast<std::uint8_t>(std::min(255, 128 + 4 * d)), 0, 0, 255});
      } else {
        const glm::u8vec4 w = want.at(x, y);
        const auto grey = static_cast<std::uint8_t>((w.x + w.y + w.z) / 10);
        out.set(x, y, {grey, grey, grey, 255});
      }
    }
  }
  return out;
}

void expect_matches_golden(const Rgba8Image& got, const std::string& name) {
  const std::filesystem::path golden = std::filesystem::path(ACCELVIZ_GOLDEN_DIR) / (name + ".png");
  const std::filesystem::path out_dir = ACCELVIZ_GOLDEN_OUT;
  if (updating_goldens()) {
    const SaveResult r = write_screenshot_png(golden, got, /*overwrite=*/true);
    ASSERT_TRUE(r) << r.error;
    std::printf("updated %s\n", golden.c_str());
    return;
  }
  const Rgba8Image want = load_png(golden);
  if (want.empty()) {
    (void)write_screenshot_png(out_dir / (name + ".actual.png"), got, true);
    FAIL() << golden << " is missing; create it with ACCELVIZ_UPDATE_GOLDEN=1 (the frame is in " << out_dir << ")";
  }
  ASSERT_EQ(want.width, got.width) << name;
  ASSERT_EQ(want.height, got.height) << name;
  int off = 0, worst = 0;
  for (int y = 0; y < got.height; ++y) {
    for (int x = 0; x < got.width; ++x) {
      const int d = channel_diff(want.at(x, y), got.at(x, y));
      worst = std::max(worst, d);
      off += d > kChannelTolerance;
    }
  }
  const double fraction = static_cast<double>(off) / (static_cast<double>(got.width) * got.height);
  if (fraction > kMaxOffFraction) {
    (void)write_screenshot_png(out_dir / (name + ".actual.png"), got, true);
    (void)write_screenshot_png(out_dir / (name + ".diff.png"), diff_image(want, got), true);
  }
  EXPECT_LE(fraction, kMaxOffFraction) << name << ": " << off << " pixels differ by more than " << kChannelTolerance
                                       << " (worst " << worst << "); see " << (out_dir / (name + ".diff.png"))
                                       << ", or ACCELVIZ_UPDATE_GOLDEN=1 if the change is intended";
}

// Quad in the plane y = h, [x0,x1]×[z0,z1], facing up.
void add_quad_xz(std::vector<Triangle>& out, float x0, float z0, float x1, float z1, float h) {
  out.push_back({{x0, h, z0}, {x0, h, z1}, {x1, h, z1}});
  out.push_back({{x0, h, z0}, {x1, h, z1}, {x1, h, z0}});
}

// A small fixed scene: floor, two boxes and a leaning triangle, and a
// hand-made two-level box hierarchy over it (so the picture does not change
// when the BVH builder is tuned).
struct GoldenScene {
  std::vector<Triangle> triangles;
  std::vector<BvhNode> nodes;
  Camera camera;

  GoldenScene() {
    add_quad_xz(triangles, -2.0f, -1.5f, 2.0f, 1.5f, 0.0f);
    add_box(triangles, {-1.3f, 0.0f, -0.9f}, {-0.3f, 1.1f, 0.1f});
    add_box(triangles, {0.3f, 0.0f, -0.3f}, {1.3f, 0.6f, 0.7f});
    triangles.push_back({{-0.2f, 0.0f, 0.9f}, {0.6f, 0.0f, 1.1f}, {0.1f, 1.2f, 0.7f}});
    auto bounds_of = [&](std::size_t first, std::size_t count) {
      Aabb b;
      for (std::size_t i = first; i < first + count; ++i) b.extend(triangles[i].bounds());
      return b;
    };
    // 0 root → (1 floor leaf, 2 objects) ; 2 → (3 boxes, 4 triangle leaf) ; 3 → (5 box A, 6 box B)
    nodes.resize(7);
    nodes[0] = {bounds_of(0, triangles.size()), 1, 0};
    nodes[1] = {bounds_of(0, 2), 0, 2};
    nodes[2] = {bounds_of(2, 25), 3, 0};
    nodes[3] = {bounds_of(2, 24), 5, 0};
    nodes[4] = {bounds_of(26, 1), 26, 1};
    nodes[5] = {bounds_of(2, 12), 2, 12};
    nodes[6] = {bounds_of(14, 12), 14, 12};
    camera = look_at({3.2f, 2.6f, 3.8f}, {0.0f, 0.35f, 0.0f}, 0.75f);
  }
};

class Golden : public GlTest {
 protected:
  GoldenScene scene_;
};

TEST_F(Golden, MeshWithBvhBoxes) {
  renderer_->set_triangles(scene_.triangles);
  const auto selected = select_bvh_boxes(scene_.nodes, {BoxSelection::Mode::depth_range, 0, 3, 0});
  renderer_->set_boxes(color_boxes(selected, {BoxColoring::Kind::depth_qualitative}));
  RenderView view;
  view.camera = scene_.camera;
  view.show_wireframe = true;
  expect_matches_golden(draw(view, kGoldenW, kGoldenH), "mesh_boxes");
}

TEST_F(Golden, DepthHeatmapBlendedOverTheMesh) {
  // The CPU tracer's per-pixel depth, drawn over the GL mesh: if the two
  // camera conventions disagreed, the colours would slide off the objects.
  renderer_->set_triangles(scene_.triangles);
  const BruteForce brute(scene_.triangles);
  HeatmapOptions opts;
  opts.metric = HeatMetric::depth;
  opts.width = kGoldenW;
  opts.height = kGoldenH;
  opts.threads = 1;
  renderer_->set_heatmap(render_metric(brute, scene_.camera, opts));
  renderer_->set_colormap(ColorMap::turbo);
  RenderView view;
  view.camera = scene_.camera;
  view.heatmap.mode = HeatmapMode::blend;
  view.heatmap.opacity = 0.65f;
  expect_matches_golden(draw(view, kGoldenW, kGoldenH), "heatmap_blend");
}

TEST_F(Golden, RayInspectorWithSplitPlane) {
  renderer_->set_triangles(scene_.triangles);
  const Ray ray({-2.5f, 1.6f, 2.2f}, glm::normalize(glm::vec3(0.9f, -0.55f, -0.9f)));
  const BruteForce brute(scene_.triangles);
  const Hit hit = brute.closest_hit(ray, QueryOptions{});
  ASSERT_TRUE(hit.valid());
  RayPath path = make_ray_path(ray, hit, scene_.nodes[0].bounds);
  path.visited = {scene_.nodes[0].bounds, scene_.nodes[2].bounds, scene_.nodes[3].bounds, scene_.nodes[5].bounds};
  path.highlighted = {hit.prim};
  renderer_->set_ray_path(path);
  const TranslucentQuad plane =
      split_plane_quad(scene_.nodes[0].bounds, 0, 0.0f, {0.3f, 0.6f, 1.0f, 0.25f}, {0.3f, 0.6f, 1.0f, 0.8f});
  renderer_->set_quads(std::span(&plane, 1));
  RenderView view;
  view.camera = scene_.camera;
  expect_matches_golden(draw(view, kGoldenW, kGoldenH), "ray_inspector");
}

}  // namespace
}  // namespace accelviz::test
