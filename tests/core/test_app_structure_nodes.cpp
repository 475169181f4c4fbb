// Node tables for the box overlay and the ray replay: they mirror each
// structure's own arrays, selections pick what they say, and the ids a
// traversal reports map to boxes the ray really passes through.
#include <gtest/gtest.h>

#include <cmath>

#include "core/accel/factory.h"
#include "core/accel/tlas/tlas.h"
#include "core/query/camera.h"
#include "core/scene/load.h"
#include "ui/app/structure_nodes.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_structure_nodes {

using namespace accelviz;

namespace {

const Scene& teapot() {
  static const Scene s = load_scene("builtin:teapot?size=800");
  return s;
}

bool inside(const Aabb& outer, const Aabb& inner, float tol) {
  for (int a = 0; a < 3; ++a)
    if (inner.lo[a] < outer.lo[a] - tol || inner.hi[a] > outer.hi[a] + tol) return false;
  return true;
}

bool same_box(const Aabb& a, const Aabb& b) {
  return a.lo == b.lo && a.hi == b.hi;
}

}  // namespace

TEST(AppStructureNodes, TreesMirrorTheirNodeArrays) {
  for (const char* name : {"bvh", "kdtree", "octree", "voxels"}) {
    SCOPED_TRACE(name);
    const auto accel = build_accelerator(name, teapot().triangles, StructureOptions{});
    const StructureNodes t = StructureNodes::of(*accel);
    EXPECT_EQ(t.kind(), name);
    ASSERT_FALSE(t.empty());
    const BuildStats& b = accel->build_stats();
    if (std::string(name) != "voxels") {
      EXPECT_EQ(t.size(), b.node_count);
      EXPECT_EQ(t.max_depth(), b.max_depth);
    }
    // Leaves mode finds every leaf the build reports (voxels: full blocks).
    const auto leaves = t.select({BoxMode::leaves, 0, 0, 0}, 1u << 30);
    EXPECT_EQ(leaves.matched, b.leaf_count);
    double share = 0.0;
    std::uint64_t roots = 0;
    for (std::uint32_t i = 0; i < t.size(); ++i) {
      const StructureNode* n = t.node(i);
      ASSERT_NE(n, nullptr);
      share += n->sah_share;
      if (n->parent == 0xFFFFFFFFu) {
        ++roots;
        continue;
      }
      const StructureNode* p = t.node(n->parent);
      ASSERT_NE(p, nullptr);
      EXPECT_EQ(n->depth, p->depth + 1);
      EXPECT_TRUE(inside(p->bounds, n->bounds, 1e-5f)) << "node " << i << " pokes out of its parent";
    }
    EXPECT_EQ(roots, 1u);
    EXPECT_NEAR(share, 1.0, 1e-4);
  }
}

TEST(AppStructureNodes, SelectionsPickWhatTheySay) {
  const auto accel = build_accelerator("bvh", teapot().triangles, StructureOptions{});
  const auto& bvh = dynamic_cast<const Bvh&>(*accel);
  const StructureNodes t = StructureNodes::of(*accel);
  for (std::uint32_t i = 0; i < bvh.nodes().size(); ++i) EXPECT_TRUE(same_box(*t.box(i), bvh.nodes()[i].bounds));
  EXPECT_FALSE(t.box(static_cast<std::uint32_t>(bvh.nodes().size())).has_value());

  const auto d3 = t.select({BoxMode::depth, 3, 0, 0}, 1u << 30);
  ASSERT_FALSE(d3.boxes.empty());
  for (const NodeBox& b : d3.boxes) EXPECT_EQ(b.depth, 3u);
  std::uint64_t at3 = 0;
  for (std::uint32_t i = 0; i < t.size(); ++i) at3 += t.node(i)->depth == 3;
  EXPECT_EQ(d3.matched, at3);

  const auto range = t.select({BoxMode::depth_range, 2, 4, 0}, 1u << 30);
  for (const NodeBox& b : range.boxes) EXPECT_TRUE(b.depth >= 2 && b.depth <= 4);

  const auto all = t.select({BoxMode::subtree, 0, 0, 0}, 1u << 30);
  EXPECT_EQ(all.matched, t.size()) << "the root's subtree is everything";
  EXPECT_EQ(all.boxes.front().id, 0u) << "parent before children";
  const auto some = t.select({BoxMode::subtree, 0, 0, 5}, 1u << 30);
  for (const NodeBox& b : some.boxes) EXPECT_TRUE(inside(*t.box(5), b.bounds, 0.0f));

  // A cut list: `limit` boxes spread evenly over the whole selection (box
  // floor(k * matched / limit) of the uncut list), not its first ones.
  const auto leaves = t.select({BoxMode::leaves, 0, 0, 0}, 1u << 30);
  EXPECT_FALSE(leaves.truncated);
  for (const std::size_t limit : {std::size_t{1}, std::size_t{10}, leaves.boxes.size() - 1}) {
    SCOPED_TRACE(limit);
    const auto cut = t.select({BoxMode::leaves, 0, 0, 0}, limit);
    ASSERT_EQ(cut.boxes.size(), limit);
    EXPECT_TRUE(cut.truncated);
    EXPECT_EQ(cut.matched, leaves.boxes.size());
    for (std::size_t k = 0; k < limit; ++k)
      ASSERT_EQ(cut.boxes[k].id, leaves.boxes[k * leaves.boxes.size() / limit].id) << k;
  }
  const auto exact = t.select({BoxMode::leaves, 0, 0, 0}, leaves.boxes.size());
  EXPECT_FALSE(exact.truncated);
  EXPECT_EQ(exact.boxes.size(), leaves.boxes.size());
}

TEST(AppStructureNodes, GridCellsAreTheGridsOwn) {
  const auto accel = build_accelerator("grid", teapot().triangles, StructureOptions{});
  const auto& grid = dynamic_cast<const Grid&>(*accel);
  const StructureNodes t = StructureNodes::of(*accel);
  EXPECT_EQ(t.kind(), "grid");
  const auto r = grid.resolution();
  EXPECT_EQ(t.size(), static_cast<std::uint64_t>(r[0]) * r[1] * r[2]);
  for (int z = 0; z < r[2]; z += 3)
    for (int y = 0; y < r[1]; y += 2)
      for (int x = 0; x < r[0]; ++x) {
        const std::uint32_t id = static_cast<std::uint32_t>(x + r[0] * (y + r[1] * z));
        EXPECT_TRUE(same_box(*t.box(id), grid.cell_box(x, y, z)));
      }
  const auto root = t.select({BoxMode::depth, 0, 0, 0}, 100);
  ASSERT_EQ(root.boxes.size(), 1u);
  EXPECT_TRUE(same_box(root.boxes[0].bounds, grid.bounds()));
  const auto cells = t.select({BoxMode::leaves, 0, 0, 0}, 1u << 30);
  EXPECT_EQ(cells.matched,
            static_cast<std::uint64_t>(grid.build_stats().node_count - grid.build_stats().extra.at("empty_cells")));
  // Depths: 0 the bounds, 1 the cells, none deeper (a range past 1 held every
  // cell, and depth 3 nothing, while its maximum depth is 1).
  EXPECT_EQ(t.max_depth(), 1u);
  EXPECT_EQ(grid.build_stats().max_depth, t.max_depth());  // the Stats panel's figure (it said 0)
  const auto matched = [&](NodeSelection s) { return t.select(s, 1u << 30).matched; };
  EXPECT_EQ(matched({BoxMode::depth, 1, 1, 0}), cells.matched);
  EXPECT_EQ(matched({BoxMode::depth_range, 0, 1, 0}), cells.matched + 1);
  EXPECT_EQ(matched({BoxMode::depth_range, 1, 5, 0}), cells.matched);
  EXPECT_EQ(matched({BoxMode::depth_range, 0, 0, 0}), 1u);
  EXPECT_EQ(matched({BoxMode::depth_range, 3, 5, 0}), 0u);
  EXPECT_EQ(matched({BoxMode::depth, 3, 3, 0}), 0u);
}

// prims_below (the node labels' and the View panel's "primitives below", computed once per build; the
// labels walked the whole tree per frame) equals the leaves' sum over each node's subtree, the voxel
// octree's too, whose root is its last node.
TEST(AppStructureNodes, PrimitivesBelowSumTheSubtreesLeaves) {
  for (const char* name : {"bvh", "kdtree", "octree", "voxels"}) {
    SCOPED_TRACE(name);
    const auto accel = build_accelerator(name, teapot().triangles, StructureOptions{});
    const StructureNodes t = StructureNodes::of(*accel);
    ASSERT_GT(t.size(), 1u);
    const auto below = [&](std::uint32_t id, const auto& self) -> std::uint64_t {
      const StructureNode& n = *t.node(id);
      if (n.leaf) return n.prims;
      std::uint64_t sum = 0;
      for (const std::uint32_t c : t.children(id)) sum += self(c, self);
      return sum;
    };
    std::size_t roots = 0;
    for (std::uint32_t id = 0; id < t.size(); ++id) {
      EXPECT_EQ(t.node(id)->prims_below, below(id, below)) << id;
      if (t.node(id)->parent == 0xFFFFFFFFu && !t.node(id)->leaf) {
        ++roots;
        if (std::string(name) != "voxels") {  // voxels reference no triangles
          EXPECT_GE(t.node(id)->prims_below, teapot().triangles.size()) << "the root holds every triangle";
        }
      }
    }
    EXPECT_GE(roots, 1u);
  }
}

// The View panel's line for a node id: what the id names in the structure
// shown (inner node, leaf, grid cell), and an id past the end said as such.
TEST(AppStructureNodes, DescribeSaysWhatAnIdNamesHere) {
  const auto accel = build_accelerator("bvh", teapot().triangles, StructureOptions{});
  const StructureNodes t = StructureNodes::of(*accel);
  EXPECT_EQ(t.describe(0),
            "node 0: depth 0, 2 children, " + std::to_string(teapot().triangles.size()) + " primitives below")
      << "a BVH references each triangle once";
  std::uint32_t leaf = 0;
  while (!t.node(leaf)->leaf) ++leaf;
  const StructureNode& l = *t.node(leaf);
  EXPECT_EQ(t.describe(leaf), "node " + std::to_string(leaf) + ": a leaf at depth " + std::to_string(l.depth) + ", " +
                                  std::to_string(l.prims) + (l.prims == 1 ? " primitive" : " primitives"));
  const auto n = static_cast<std::uint32_t>(t.size());
  EXPECT_EQ(t.describe(n), "no node " + std::to_string(n) + ": this bvh has nodes 0-" + std::to_string(n - 1));

  const auto g = build_accelerator("grid", teapot().triangles, StructureOptions{});
  const auto& grid = dynamic_cast<const Grid&>(*g);
  const StructureNodes cells = StructureNodes::of(*g);
  const auto r = grid.resolution();
  const std::uint32_t id = static_cast<std::uint32_t>(1 + r[0] * (2 + r[1] * 1));
  const std::uint32_t held = grid.cell_start()[id + 1] - grid.cell_start()[id];
  EXPECT_EQ(cells.describe(id), "cell " + std::to_string(id) + " (x 1, y 2, z 1): " + std::to_string(held) +
                                    (held == 1 ? " primitive" : " primitives"));
  EXPECT_EQ(cells.describe(static_cast<std::uint32_t>(cells.size())).rfind("no cell ", 0), 0u);

  const auto brute = build_accelerator("brute", teapot().triangles, StructureOptions{});
  EXPECT_EQ(StructureNodes::of(*brute).describe(3), "no node 3: this structure has no nodes to show");
}

TEST(AppStructureNodes, EnteredNodesContainTheRaySegmentTheyReport) {
  const Scene& s = teapot();
  const Camera cam = camera_from_spec("", s, 1.0f);
  for (const char* name : {"bvh", "kdtree", "octree", "grid", "voxels"}) {
    SCOPED_TRACE(name);
    const auto accel = build_accelerator(name, s.triangles, StructureOptions{});
    const StructureNodes t = StructureNodes::of(*accel);
    std::size_t checked = 0;
    for (int y = 2; y < 32; y += 5)
      for (int x = 2; x < 32; x += 5) {
        const Ray ray = primary_ray(cam, x, y, 32, 32);
        VisitTrace trace;
        RayStats stats;
        accel->closest_hit(ray, {}, &stats, &trace);
        for (const VisitStep& st : trace.steps) {
          if (st.kind != VisitStep::Kind::node_entered) continue;
          const auto box = t.box(st.id);
          ASSERT_TRUE(box.has_value()) << "id " << st.id;
          const float tm = 0.5f * (std::max(st.t_entry, ray.tmin) + st.t_exit);
          if (!std::isfinite(tm)) continue;
          const glm::vec3 p = ray.at(tm);
          const float tol = 1e-3f * glm::length(box->extent()) + 1e-4f;
          EXPECT_TRUE(inside(*box, Aabb::of_point(p), tol)) << "node " << st.id << " at t " << tm;
          ++checked;
        }
      }
    EXPECT_GT(checked, 0u);
  }
}

TEST(AppStructureNodes, StructuresWithoutNodesHaveNone) {
  const auto accel = build_accelerator("brute", teapot().triangles, StructureOptions{});
  const StructureNodes t = StructureNodes::of(*accel);
  EXPECT_TRUE(t.empty());
  EXPECT_EQ(t.kind(), "");
  EXPECT_TRUE(t.select({BoxMode::depth, 0, 0, 0}, 10).boxes.empty());
  EXPECT_FALSE(t.box(0).has_value());
}

// Two-level: the TLAS nodes, then one leaf per instance (its world box)
// under the TLAS leaf that holds it.
TEST(StructureNodes, TwoLevelShowsTlasNodesAndOneLeafPerInstance) {
  const Scene s = make_builtin("forest?size=5000&seed=2");
  StructureOptions so;
  so.scene = &s;
  const auto accel = build_accelerator("tlas", s.triangles, so);
  const auto& tlas = dynamic_cast<const Tlas&>(*accel);
  const StructureNodes t = StructureNodes::of(*accel);
  EXPECT_EQ(t.kind(), "tlas");
  ASSERT_EQ(t.size(), tlas.tlas_nodes().size() + s.instances.size());
  std::size_t leaves = 0;
  for (std::uint32_t i = 0; i < t.size(); ++i) {
    const StructureNode* n = t.node(i);
    ASSERT_NE(n, nullptr);
    if (!n->leaf) continue;
    ++leaves;
    EXPECT_GE(i, tlas.tlas_nodes().size()) << "TLAS leaves become parents of their instances";
    ASSERT_LT(n->parent, tlas.tlas_nodes().size());
    EXPECT_TRUE(t.node(n->parent)->bounds.contains(n->bounds));
    EXPECT_GT(n->prims, 0u);
  }
  EXPECT_EQ(leaves, s.instances.size());
}
}  // namespace unity_test_app_structure_nodes
