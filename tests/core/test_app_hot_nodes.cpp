// Hot nodes in the 3D view (ui/app/hot_nodes.h): box colours follow the
// visit counts of a real BVH over a real view (the hottest box gets the top
// of the colour map), labels carry id/depth/prims/visits, projection inverts
// primary_ray, a clicked hit names the leaf it was found in, and view
// rectangles map onto the insight record's pixels.
#include <gtest/gtest.h>

#include <algorithm>

#include "core/accel/factory.h"
#include "core/scene/load.h"
#include "ui/app/hot_nodes.h"
#include "ui/app/ray_inspection.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_hot_nodes {

using namespace accelviz;

namespace hot_nodes_test {

struct Fixture {
  Scene scene = load_scene("builtin:teapot?size=800");
  std::unique_ptr<Accelerator> accel = build_accelerator("bvh", scene.triangles, StructureOptions{});
  StructureNodes nodes = StructureNodes::of(*accel);
  Camera camera = look_at({6.0f, 4.0f, 8.0f}, {0.0f, 1.2f, 0.0f}, 0.7f);
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

TEST(AppHotNodes, BoxColoursFollowVisitsHottestGetsTheTopColour) {
  const auto& f = fixture();
  const VisitRecord rec = record_view_visits(*f.accel, f.camera, 40, 30, QueryOptions{}, 1);
  const std::vector<std::uint64_t> visits = node_visit_counts(rec, f.nodes.size());
  // Depth 3 of the tree: several boxes, some hot, some cold.
  const auto sel = f.nodes.select({BoxMode::depth, 3, 3, 0}, 1u << 20);
  ASSERT_GE(sel.boxes.size(), 4u);
  for (const ColorMap map : {ColorMap::viridis, ColorMap::inferno}) {
    const std::vector<glm::vec4> colors = visit_colors(sel.boxes, visits, map);
    ASSERT_EQ(colors.size(), sel.boxes.size());
    std::size_t hottest = 0, coldest = 0;
    for (std::size_t i = 0; i < sel.boxes.size(); ++i) {
      if (visits[sel.boxes[i].id] > visits[sel.boxes[hottest].id]) hottest = i;
      if (visits[sel.boxes[i].id] < visits[sel.boxes[coldest].id]) coldest = i;
    }
    ASSERT_GT(visits[sel.boxes[hottest].id], visits[sel.boxes[coldest].id]) << "the view must make a difference";
    EXPECT_EQ(max_visit_count(sel.boxes, visits), visits[sel.boxes[hottest].id]);
    EXPECT_LT(max_visit_count(sel.boxes, visits), visits[0]) << "the root, not drawn, is hotter";
    EXPECT_EQ(glm::vec3(colors[hottest]), colormap(map, 1.0f));
    EXPECT_NE(glm::vec3(colors[coldest]), colormap(map, 1.0f));
    // Every box's colour is the map at its ramp value, and the ramp orders as the visits do.
    for (std::size_t i = 0; i < sel.boxes.size(); ++i) {
      const float t = visit_ramp(visits[sel.boxes[i].id], visits[sel.boxes[hottest].id]);
      EXPECT_EQ(glm::vec3(colors[i]), colormap(map, t));
      for (std::size_t j = 0; j < sel.boxes.size(); ++j) {
        if (visits[sel.boxes[i].id] < visits[sel.boxes[j].id]) {
          EXPECT_LT(t, visit_ramp(visits[sel.boxes[j].id], visits[sel.boxes[hottest].id]));
        }
      }
    }
  }
  EXPECT_EQ(visit_ramp(0, 0), 0.0f);
  EXPECT_EQ(visit_ramp(0, 10), 0.0f);
  EXPECT_EQ(visit_ramp(10, 10), 1.0f);
}

TEST(AppHotNodes, LabelsNameSelectedAndHotNodes) {
  const auto& f = fixture();
  const VisitRecord rec = record_view_visits(*f.accel, f.camera, 32, 24, QueryOptions{}, 1);
  const std::vector<std::uint64_t> visits = node_visit_counts(rec, f.nodes.size());
  const std::vector<HotNode> hot = top_hot_nodes(visits, 10);
  ASSERT_GE(hot.size(), 5u);
  const std::uint32_t sel = hot[2].node;
  const std::vector<NodeLabel> labels = node_labels(f.nodes, visits, hot, 4, sel);
  ASSERT_EQ(labels.size(), 5u);  // the selected one + 4 others
  EXPECT_TRUE(labels[0].selected);
  EXPECT_EQ(labels[0].node, sel);
  for (const NodeLabel& l : labels) {
    const StructureNode* n = f.nodes.node(l.node);
    ASSERT_NE(n, nullptr);
    std::string want_prefix("#");
    want_prefix += std::to_string(l.node) + " d" + std::to_string(n->depth) + " p";
    EXPECT_EQ(l.text.rfind(want_prefix, 0), 0u) << l.text;
    EXPECT_NE(l.text.find(" v" + std::to_string(visits[l.node])), std::string::npos) << l.text;
    EXPECT_EQ(std::count_if(labels.begin(), labels.end(), [&](const NodeLabel& o) { return o.node == l.node; }), 1);
  }
  // The root's label counts every primitive.
  const std::vector<NodeLabel> root = node_labels(f.nodes, visits, {}, 0, 0u);
  ASSERT_EQ(root.size(), 1u);
  EXPECT_NE(root[0].text.find(" p" + std::to_string(f.scene.triangles.size()) + " "), std::string::npos)
      << root[0].text;
}

TEST(AppHotNodes, ProjectionInvertsPrimaryRays) {
  const auto& f = fixture();
  for (const auto& [x, y] : {std::pair{0, 0}, std::pair{17, 5}, std::pair{63, 47}}) {
    const Ray r = primary_ray(f.camera, x, y, 64, 48);
    const auto p = project_to_pixel(f.camera, r.origin + 7.0f * r.direction, 64, 48);
    ASSERT_TRUE(p);
    EXPECT_NEAR(p->x, x + 0.5f, 1e-3f);
    EXPECT_NEAR(p->y, y + 0.5f, 1e-3f);
  }
  EXPECT_FALSE(project_to_pixel(f.camera, f.camera.position - f.camera.forward, 64, 48));
}

/// `name` built over the fixture's scene, with its node table, as the app shows it.
BuiltStructure built_over_fixture(const char* name) {
  auto loaded = std::make_shared<LoadedScene>();
  loaded->scene = fixture().scene;
  BuiltStructure built;
  built.scene = loaded;
  built.accel = build_accelerator(name, loaded->scene.triangles, StructureOptions{});
  built.nodes = StructureNodes::of(*built.accel);
  return built;
}

TEST(AppHotNodes, AClickedHitNamesItsLeafAndPath) {
  const auto& f = fixture();
  const BuiltStructure built = built_over_fixture("bvh");
  const RayInspection insp = inspect_pixel(built, f.camera, 32, 24, 64, 48, QueryOptions{});
  ASSERT_TRUE(insp.hit.valid()) << "the middle pixel hits the teapot";
  const auto leaf = hit_leaf(insp.trace, insp.hit, built.nodes);
  ASSERT_TRUE(leaf);
  const StructureNode* n = built.nodes.node(*leaf);
  ASSERT_NE(n, nullptr);
  EXPECT_TRUE(n->leaf);
  const glm::vec3 p = insp.ray.origin + insp.hit.t * insp.ray.direction;
  const float tol = 1e-3f * glm::length(n->bounds.extent()) + 1e-4f;
  for (int a = 0; a < 3; ++a) {
    EXPECT_GE(p[a], n->bounds.lo[a] - tol);
    EXPECT_LE(p[a], n->bounds.hi[a] + tol);
  }
  const std::vector<std::uint32_t> path = path_to(built.nodes, *leaf);
  ASSERT_FALSE(path.empty());
  EXPECT_EQ(path.front(), 0u);
  EXPECT_EQ(path.back(), *leaf);
  EXPECT_EQ(path.size(), n->depth + 1);
  // A miss, and a trace without the hit's test, name no leaf.
  EXPECT_FALSE(hit_leaf(insp.trace, Hit{}, built.nodes));
  EXPECT_FALSE(hit_leaf(VisitTrace{}, insp.hit, built.nodes));
}

// A grid has cells, not nodes: the cell a click selects is the one the walk
// ended in, which holds the hit point (the hit's triangle may have been
// tested in an earlier cell it overlaps).
TEST(AppHotNodes, AClickedHitInAGridNamesTheCellHoldingIt) {
  const auto& f = fixture();
  const BuiltStructure built = built_over_fixture("grid");
  ASSERT_EQ(built.nodes.kind(), "grid");
  int hits = 0;
  for (int y = 8; y < 48; y += 8)
    for (int x = 8; x < 64; x += 8) {
      const RayInspection insp = inspect_pixel(built, f.camera, x, y, 64, 48, QueryOptions{});
      if (!insp.hit.valid()) {
        EXPECT_FALSE(hit_leaf(insp.trace, insp.hit, built.nodes));
        continue;
      }
      ++hits;
      const auto cell = hit_leaf(insp.trace, insp.hit, built.nodes);
      ASSERT_TRUE(cell) << x << "," << y;
      const auto box = built.nodes.box(*cell);
      ASSERT_TRUE(box);
      const glm::vec3 p = insp.ray.origin + insp.hit.t * insp.ray.direction;
      const float tol = 1e-4f * glm::length(box->extent()) + 1e-5f;
      for (int a = 0; a < 3; ++a) {
        EXPECT_GE(p[a], box->lo[a] - tol) << x << "," << y;
        EXPECT_LE(p[a], box->hi[a] + tol) << x << "," << y;
      }
    }
  EXPECT_GT(hits, 5);
}

TEST(AppHotNodes, ViewRectanglesMapOntoTheRecord) {
  const PixelRect all = view_rect_to_record(0, 0, 640, 480, 640, 480, 128, 96);
  EXPECT_EQ(all.x0, 0);
  EXPECT_EQ(all.y0, 0);
  EXPECT_EQ(all.x1, 128);
  EXPECT_EQ(all.y1, 96);
  const PixelRect r = view_rect_to_record(330, 250, 100, 10, 640, 480, 128, 96);  // corners in any order
  EXPECT_EQ(r.x0, 20);
  EXPECT_EQ(r.y0, 2);
  EXPECT_EQ(r.x1, 66);
  EXPECT_EQ(r.y1, 50);
  const PixelRect tiny = view_rect_to_record(10, 10, 11, 11, 640, 480, 128, 96);
  EXPECT_EQ(tiny.x1 - tiny.x0, 1);
  EXPECT_EQ(tiny.y1 - tiny.y0, 1);
  EXPECT_TRUE(view_rect_to_record(700, 500, 900, 900, 640, 480, 128, 96).empty());
}
}  // namespace hot_nodes_test

}  // namespace unity_test_app_hot_nodes
