// Instance overlap (core/accel/tlas/tlas_overlap.h) and the flatten what-if
// (core/accel/tlas/flatten_what_if.h) on hand-made two- and three-instance scenes.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/accel/tlas/flatten_what_if.h"
#include "core/accel/tlas/tlas.h"
#include "core/accel/tlas/tlas_overlap.h"
#include "core/query/camera.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_tlas_overlap {

using namespace accelviz;

TEST(InstanceOverlap, TwoOverlappingAndOneApartHandComputed) {
  // A = [0,2]^3, B = [1,3]x[0,2]x[0,2]: A∩B = [1,2]x[0,2]x[0,2], area 2(1*2+2*2+2*1) = 16, volume 4.
  // C = [10,11]^3 is apart. Union box [0,11]^3: area 726, volume 1331.
  const std::vector<Aabb> boxes = {Aabb{{10, 10, 10}, {11, 11, 11}}, Aabb{{1, 0, 0}, {3, 2, 2}},
                                   Aabb{{0, 0, 0}, {2, 2, 2}}};
  const InstanceOverlap o = instance_overlap(boxes);
  EXPECT_EQ(o.instances, 3u);
  EXPECT_EQ(o.overlapping_pairs, 1u);
  EXPECT_DOUBLE_EQ(o.area_sum, 16.0);
  EXPECT_DOUBLE_EQ(o.volume_sum, 4.0);
  EXPECT_DOUBLE_EQ(o.root_area, 726.0);
  EXPECT_DOUBLE_EQ(o.root_volume, 1331.0);
  EXPECT_DOUBLE_EQ(o.area_ratio, 16.0 / 726.0);
  EXPECT_DOUBLE_EQ(o.volume_ratio, 4.0 / 1331.0);
}

TEST(InstanceOverlap, DisjointCornerTouchingAndEmptyBoxesAddNothing) {
  const std::vector<Aabb> boxes = {Aabb{{0, 0, 0}, {1, 1, 1}}, Aabb{{1, 1, 1}, {2, 2, 2}},  // corner only
                                   Aabb{{5, 0, 0}, {6, 1, 1}}, Aabb{}};
  const InstanceOverlap o = instance_overlap(boxes);
  EXPECT_EQ(o.instances, 3u);
  EXPECT_EQ(o.overlapping_pairs, 0u);
  EXPECT_EQ(o.area_ratio, 0.0);
  EXPECT_EQ(instance_overlap(std::vector<Aabb>{}).instances, 0u);
}

TEST(InstanceOverlap, ThreeNestedCopiesCountEveryPair) {
  // Three identical unit boxes: 3 pairs, each the whole box (area 6, volume 1); union = the box.
  const std::vector<Aabb> boxes(3, Aabb{{0, 0, 0}, {1, 1, 1}});
  const InstanceOverlap o = instance_overlap(boxes);
  EXPECT_EQ(o.overlapping_pairs, 3u);
  EXPECT_DOUBLE_EQ(o.area_ratio, 3.0);
  EXPECT_DOUBLE_EQ(o.volume_ratio, 3.0);
}

TEST(InstanceOverlap, TheTlasReportsItsInstancesOverlapAtBuild) {
  // Two instances of one triangle, the second shifted half-way along x: their boxes overlap.
  Scene s;
  Mesh m;
  m.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 1}};
  m.indices = {{0, 1, 2}};
  s.meshes.push_back(m);
  s.nodes.resize(2);
  Instance a, b;
  a.mesh = b.mesh = 0;
  a.node = 0;
  b.node = 1;
  b.transform[3] = glm::vec4(1.0f, 0.0f, 0.0f, 1.0f);
  s.instances = {a, b};
  s.flatten();
  const Tlas t(s);
  const double ratio = t.build_stats().extra.at("instance_overlap_area");
  // Boxes [0,2]x[0,2]x[0,1] and [1,3]x[0,2]x[0,1] (padded 1e-5): overlap area 2(2+2+1) = 10 over the
  // union [0,3]x[0,2]x[0,1], area 2(6+2+3) = 22.
  EXPECT_NEAR(ratio, 10.0 / 22.0, 1e-3);
  EXPECT_EQ(t.build_stats().extra.at("instance_overlap_pairs"), 1.0);
}

namespace tlas_what_if_test {

// Three instances of a unit quad (two triangles) side by side along x, the third mirrored.
Scene three_quads() {
  Scene s;
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  m.indices = {{0, 1, 2}, {0, 2, 3}};
  s.meshes.push_back(m);
  for (int i = 0; i < 3; ++i) {
    Node n;
    n.mesh = 0;
    s.nodes.push_back(n);
    s.roots.push_back(i);
    Instance inst;
    inst.node = static_cast<std::uint32_t>(i);
    inst.transform[3] = glm::vec4(1.5f * static_cast<float>(i), 0.0f, 0.0f, 1.0f);
    if (i == 2) inst.transform[0][0] = -1.0f;  // mirrored: spans x in [2, 3]
    s.instances.push_back(inst);
  }
  s.flatten();
  return s;
}

}  // namespace tlas_what_if_test

TEST(FlattenWhatIf, MergingTwoOfThreeInstancesKeepsTheWorldGeometry) {
  const Scene s = tlas_what_if_test::three_quads();
  const std::vector<std::uint32_t> sel = {0, 2};
  const FlattenedScene flattened = flatten_instances(s, sel);
  const Scene& flat = flattened.scene;
  EXPECT_EQ(flattened.merged_triangles, 4u);
  ASSERT_EQ(flat.instances.size(), 2u);  // instance 1 kept, then the merged one
  EXPECT_EQ(flat.instances[0].transform, s.instances[1].transform);
  EXPECT_EQ(flat.meshes[flat.instances[1].mesh].indices.size(), 4u);
  EXPECT_EQ(flat.triangles.size(), s.triangles.size());
  EXPECT_TRUE(flat.has_instancing() == false);

  const Camera cam = look_at({1.5f, 0.5f, 4.0f}, {1.5f, 0.5f, 0.0f}, 1.0f);
  const FlattenWhatIf w = flatten_what_if(s, sel, cam, 24, 8);
  EXPECT_EQ(w.merged_instances, 2u);
  EXPECT_EQ(w.merged_triangles, 4u);
  EXPECT_EQ(w.two_level.instances, 3u);
  EXPECT_EQ(w.flattened.instances, 2u);
  EXPECT_EQ(w.two_level.blas, 1u);
  EXPECT_EQ(w.flattened.blas, 2u);
  EXPECT_EQ(w.two_level.rays, 24u * 8u);
  // Same world geometry: the same pixels hit.
  EXPECT_EQ(w.flattened.hits, w.two_level.hits);
  EXPECT_GT(w.two_level.hits, 0u);
  EXPECT_GT(w.two_level.sah_cost, 0.0);
  EXPECT_GT(w.flattened.sah_cost, 0.0);
  EXPECT_GT(w.two_level.mean_instances, 0.0);
  EXPECT_GT(w.two_level.trace_ms, 0.0);
  EXPECT_GT(w.flattened.trace_ms, 0.0);
  // Two instances merged: fewer instance entries per ray.
  EXPECT_LT(w.flattened.mean_instances, w.two_level.mean_instances);

  // Hit by hit, the flattened two-level structure answers like the original.
  const Tlas a(s), b(flat);
  for (int x = 0; x < 24; ++x) {
    const Ray r = primary_ray(cam, x, 4, 24, 8);
    const Hit ha = a.closest_hit(r, {}), hb = b.closest_hit(r, {});
    EXPECT_EQ(ha.valid(), hb.valid()) << x;
    if (ha.valid() && hb.valid()) {
      EXPECT_NEAR(ha.t, hb.t, 1e-5f) << x;
    }
  }
}

TEST(FlattenWhatIf, ProgressRisesToOneAndFalseCancels) {
  const Scene s = tlas_what_if_test::three_quads();
  const std::vector<std::uint32_t> sel = {1};
  const Camera cam = look_at({1.5f, 0.5f, 4.0f}, {1.5f, 0.5f, 0.0f}, 1.0f);
  std::vector<double> seen;
  flatten_what_if(s, sel, cam, 8, 6, {}, [&](double f) {
    seen.push_back(f);
    return true;
  });
  ASSERT_GT(seen.size(), 12u);  // a row of each trace at least
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_DOUBLE_EQ(seen.back(), 1.0);
  EXPECT_GE(seen.front(), 0.0);
  int calls = 0;
  EXPECT_THROW(flatten_what_if(s, sel, cam, 8, 6, {}, [&](double) { return ++calls < 5; }), BuildCancelled);
  EXPECT_GE(calls, 5);
}

TEST(FlattenWhatIf, BadSelectionsAreRefused) {
  const Scene s = tlas_what_if_test::three_quads();
  for (const std::vector<std::uint32_t>& bad : {std::vector<std::uint32_t>{3}, std::vector<std::uint32_t>{1, 1}}) {
    try {
      flatten_instances(s, bad);
      ADD_FAILURE() << "accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("flatten:"), std::string::npos) << e.what();
    }
  }
}

}  // namespace unity_test_tlas_overlap
