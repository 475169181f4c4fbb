// Instance overlap (core/accel/tlas/tlas_overlap.h) and the flatten what-if
// (core/accel/tlas/flatten_what_if.h) on hand-made two- and three-instance scenes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
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

// Many boxes (long ones whose x-extents reach past hundreds of others, so
// the sweep's candidate chunks fill and wrap; flat ones that only touch;
// repeats) against every pair tested directly.
TEST(InstanceOverlap, ManyBoxesAgreeWithEveryPairTestedDirectly) {
  std::uint64_t state = 12345;
  const auto next = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<float>((state >> 40) & 0xFFFF) / 65535.0f;
  };
  std::vector<Aabb> boxes;
  for (int i = 0; i < 1500; ++i) {
    const glm::vec3 lo{next() * 100.0f, next() * 20.0f, next() * 20.0f};
    glm::vec3 size{next() * 3.0f, next() * 3.0f, next() * 3.0f};
    if (i % 50 == 0) size.x = 60.0f;  // long in x: hundreds of candidates each
    if (i % 7 == 0) size.y = 0.0f;    // flat: overlaps have no volume, and touch-only pairs count nothing
    boxes.push_back(Aabb{lo, lo + size});
  }
  boxes.push_back(boxes[3]);  // a repeat
  boxes.push_back(Aabb{});    // empty: skipped
  const auto area = [](const Aabb& b) {
    const glm::dvec3 e = glm::dvec3(b.hi) - glm::dvec3(b.lo);
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
  };
  std::uint64_t pairs = 0;
  double area_sum = 0.0, volume_sum = 0.0;
  for (std::size_t i = 0; i + 1 < boxes.size(); ++i)
    for (std::size_t j = i + 1; j < boxes.size(); ++j) {
      if (boxes[i].is_empty() || boxes[j].is_empty()) continue;
      const Aabb c = Aabb::intersection(boxes[i], boxes[j]);
      if (c.is_empty() || !(area(c) > 0.0)) continue;
      ++pairs;
      area_sum += area(c);
      const glm::dvec3 e = glm::dvec3(c.hi) - glm::dvec3(c.lo);
      volume_sum += e.x * e.y * e.z;
    }
  const InstanceOverlap o = instance_overlap(boxes);
  EXPECT_EQ(o.instances, boxes.size() - 1);
  ASSERT_GT(pairs, 500u) << "the boxes must overlap a lot for the test to mean something";
  EXPECT_EQ(o.overlapping_pairs, pairs);
  EXPECT_NEAR(o.area_sum, area_sum, 1e-9 * area_sum);
  EXPECT_NEAR(o.volume_sum, volume_sum, 1e-9 * volume_sum);
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
  // More triangles than one flattened mesh may hold (its vertex indices are 32-bit; the merge wrapped
  // them past 1.43e9 triangles): refused in one line before anything is copied.
  Scene big;
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.indices.assign(std::size_t{1} << 20, glm::uvec3(0, 1, 2));
  big.meshes.push_back(std::move(m));
  std::vector<std::uint32_t> all;
  for (std::uint32_t i = 0; i < 257; ++i) {
    Instance inst;
    inst.mesh = 0;
    big.instances.push_back(inst);
    all.push_back(i);
  }
  try {
    flatten_instances(big, all);
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "flatten: the selected instances hold 269484032 triangles, more than the 268435456 (2^28) one "
              "flattened mesh may hold");
  }
}

}  // namespace unity_test_tlas_overlap
