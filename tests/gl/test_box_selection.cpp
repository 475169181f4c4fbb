// Selecting BVH nodes to draw (pure functions, no GL).
#include "ui/render/box_selection.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

namespace accelviz {
namespace {

// A hand-made tree (depth in brackets):
//   0 [0] inner, children 1 and 2
//   1 [1] inner, children 3 and 4      2 [1] leaf
//   3 [2] leaf                         4 [2] inner, children 5 and 6
//   5 [3] leaf                         6 [3] leaf
std::vector<BvhNode> sample_tree() {
  auto box = [](float i) { return Aabb{{i, 0.0f, 0.0f}, {i + 1.0f, 1.0f, 1.0f}}; };
  std::vector<BvhNode> n(7);
  for (int i = 0; i < 7; ++i) n[i].bounds = box(static_cast<float>(i));
  n[0].index = 1, n[0].count = 0;
  n[1].index = 3, n[1].count = 0;
  n[2].index = 0, n[2].count = 2;
  n[3].index = 2, n[3].count = 1;
  n[4].index = 5, n[4].count = 0;
  n[5].index = 3, n[5].count = 1;
  n[6].index = 4, n[6].count = 3;
  return n;
}

std::vector<std::uint32_t> ids(const std::vector<SelectedBox>& boxes) {
  std::vector<std::uint32_t> out;
  for (const SelectedBox& b : boxes) out.push_back(b.node);
  return out;
}

TEST(BoxSelection, AllNodesAtOneDepth) {
  const auto tree = sample_tree();
  BoxSelection sel;
  sel.depth = 0;
  EXPECT_EQ(ids(select_bvh_boxes(tree, sel)), (std::vector<std::uint32_t>{0}));
  sel.depth = 1;
  EXPECT_EQ(ids(select_bvh_boxes(tree, sel)), (std::vector<std::uint32_t>{1, 2}));
  sel.depth = 2;
  EXPECT_EQ(ids(select_bvh_boxes(tree, sel)), (std::vector<std::uint32_t>{3, 4}));
  sel.depth = 3;
  EXPECT_EQ(ids(select_bvh_boxes(tree, sel)), (std::vector<std::uint32_t>{5, 6}));
  sel.depth = 4;
  EXPECT_TRUE(select_bvh_boxes(tree, sel).empty());
}

TEST(BoxSelection, DepthRangeIsInclusiveAndDepthFirst) {
  const auto tree = sample_tree();
  BoxSelection sel{BoxSelection::Mode::depth_range, 1, 2, 0};
  const auto boxes = select_bvh_boxes(tree, sel);
  EXPECT_EQ(ids(boxes), (std::vector<std::uint32_t>{1, 3, 4, 2}));
  for (const SelectedBox& b : boxes) EXPECT_EQ(b.bounds.lo.x, static_cast<float>(b.node));
}

TEST(BoxSelection, LeavesOnly) {
  const auto tree = sample_tree();
  const auto boxes = select_bvh_boxes(tree, {BoxSelection::Mode::leaves});
  EXPECT_EQ(ids(boxes), (std::vector<std::uint32_t>{3, 5, 6, 2}));
  for (const SelectedBox& b : boxes) EXPECT_TRUE(b.leaf);
  EXPECT_EQ(boxes[1].depth, 3u);
}

TEST(BoxSelection, SubtreeOfANode) {
  const auto tree = sample_tree();
  BoxSelection sel{BoxSelection::Mode::subtree, 0, 0, 4};
  const auto boxes = select_bvh_boxes(tree, sel);
  EXPECT_EQ(ids(boxes), (std::vector<std::uint32_t>{4, 5, 6}));
  EXPECT_EQ(boxes[0].depth, 2u);  // depths stay absolute
  sel.node = 2;
  EXPECT_EQ(ids(select_bvh_boxes(tree, sel)), (std::vector<std::uint32_t>{2}));
  sel.node = 0;
  EXPECT_EQ(select_bvh_boxes(tree, sel).size(), 7u);
  sel.node = 7;
  EXPECT_THROW(select_bvh_boxes(tree, sel), std::invalid_argument);
}

TEST(BoxSelection, EmptyArraySelectsNothing) {
  EXPECT_TRUE(select_bvh_boxes({}, {BoxSelection::Mode::leaves}).empty());
  EXPECT_EQ(bvh_max_depth({}), 0u);
}

TEST(BoxSelection, MaxDepth) {
  EXPECT_EQ(bvh_max_depth(sample_tree()), 3u);
}

TEST(BoxSelection, ChildOutOfRangeIsReported) {
  auto tree = sample_tree();
  tree[4].index = 6;  // children 6 and 7: 7 does not exist
  try {
    (void)select_bvh_boxes(tree, {BoxSelection::Mode::leaves});
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("node 4"), std::string::npos) << e.what();
  }
}

TEST(BoxSelection, CycleIsReportedNotLoopedForever) {
  auto tree = sample_tree();
  tree[4].index = 0;  // children 0 and 1: back to the root
  EXPECT_THROW((void)select_bvh_boxes(tree, {BoxSelection::Mode::leaves}), std::invalid_argument);
}

TEST(BoxSelection, WorksOnABuiltBvh) {
  // A real tree from the builder: every primitive lies in exactly one leaf,
  // and the leaves' depths agree with the build statistics.
  std::vector<Aabb> bounds;
  std::vector<glm::vec3> centroids;
  for (int i = 0; i < 100; ++i) {
    const glm::vec3 p(static_cast<float>(i % 10), static_cast<float>(i / 10), static_cast<float>((i * 7) % 5));
    bounds.push_back({p, p + glm::vec3(0.5f)});
    centroids.push_back(p + glm::vec3(0.25f));
  }
  const BvhTopology bvh = build_bvh(bounds, centroids);
  const auto leaves = select_bvh_boxes(bvh.nodes, {BoxSelection::Mode::leaves});
  std::uint32_t prims = 0, deepest = 0;
  for (const SelectedBox& b : leaves) {
    prims += bvh.nodes[b.node].count;
    deepest = std::max(deepest, b.depth);
  }
  EXPECT_EQ(prims, 100u);
  EXPECT_EQ(leaves.size(), bvh.stats.leaf_count);
  EXPECT_EQ(deepest, bvh.stats.max_depth);
  EXPECT_EQ(bvh_max_depth(bvh.nodes), bvh.stats.max_depth);
  // All nodes over the depth range [0, max] is every node.
  const auto all = select_bvh_boxes(bvh.nodes, {BoxSelection::Mode::depth_range, 0, deepest, 0});
  EXPECT_EQ(all.size(), bvh.nodes.size());
}

TEST(BoxColoring, QualitativeByDepthDistinguishesNeighbours) {
  const auto tree = sample_tree();
  const auto sel = select_bvh_boxes(tree, {BoxSelection::Mode::depth_range, 0, 3, 0});
  const auto colored = color_boxes(sel, {BoxColoring::Kind::depth_qualitative});
  ASSERT_EQ(colored.size(), sel.size());
  for (std::size_t i = 0; i < sel.size(); ++i) {
    EXPECT_EQ(glm::vec3(colored[i].color), qualitative_color(sel[i].depth));
    EXPECT_EQ(colored[i].box.lo, sel[i].bounds.lo);
  }
  for (std::uint32_t d = 0; d < 20; ++d) EXPECT_NE(qualitative_color(d), qualitative_color(d + 1));
}

TEST(BoxColoring, SequentialSpansTheColourMap) {
  const auto tree = sample_tree();
  const auto sel = select_bvh_boxes(tree, {BoxSelection::Mode::depth_range, 1, 3, 0});
  BoxColoring c{BoxColoring::Kind::depth_sequential, ColorMap::inferno};
  c.alpha = 0.5f;
  const auto colored = color_boxes(sel, c);
  for (std::size_t i = 0; i < sel.size(); ++i) {
    const float t = static_cast<float>(sel[i].depth - 1) / 2.0f;  // depths 1..3 → 0..1
    EXPECT_EQ(glm::vec3(colored[i].color), colormap(ColorMap::inferno, t));
    EXPECT_EQ(colored[i].color.w, 0.5f);
  }
}

TEST(BoxColoring, FadeRunsFromFirstToLast) {
  const std::vector<Aabb> boxes(5, Aabb{{0, 0, 0}, {1, 1, 1}});
  const glm::vec4 a(1, 0, 0, 1), b(0, 0, 1, 0.5f);
  const auto faded = fade_boxes(boxes, a, b);
  ASSERT_EQ(faded.size(), 5u);
  EXPECT_EQ(faded.front().color, a);
  EXPECT_EQ(faded.back().color, b);
  EXPECT_EQ(faded[2].color, glm::mix(a, b, 0.5f));
  EXPECT_EQ(fade_boxes(std::span<const Aabb>(boxes.data(), 1), a, b)[0].color, a);
}

}  // namespace
}  // namespace accelviz
