// Sparse voxel occupancy (core/accel/voxels): named cases, the occupancy
// against an independent dense voxelization, surface samples inside occupied
// voxels, collapsing and memory, and the ray march against the dense DDA
// reference (dense_voxel_march) on over 100,000 seeded rays.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "core/accel/voxels/dense_voxels.h"
#include "core/accel/voxels/voxels.h"
#include "tests/core/spatial_test_scenes.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_voxels {

using namespace accelviz;
using namespace accelviz::test_scenes;

namespace {

using Scene = std::vector<Triangle>;

Scene varied_soup(std::uint64_t seed, int n, float max_size) {
  Rng rng{seed};
  Scene s;
  for (int i = 0; i < n; ++i) {
    const glm::vec3 c = rng.in_box(glm::vec3(-1), glm::vec3(1));
    const float size = max_size * rng.range(0.05f, 1.0f);
    s.push_back({c + size * rng.unit(), c + size * rng.unit(), c + size * rng.unit()});
  }
  return s;
}

// A closed sphere-like surface (octahedron subdivided and pushed out) plus
// a floor: curved surfaces in every orientation.
Scene sphere_and_floor() {
  Scene s;
  const int n = 24;
  const auto p = [&](int i, int j) {
    const float th = 3.14159265f * static_cast<float>(i) / n, ph = 6.2831853f * static_cast<float>(j) / n;
    return glm::vec3(0.2f, 0.1f, -0.1f) +
           0.7f * glm::vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) quad(s, p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
  quad(s, {-1, -0.8f, -1}, {1, -0.8f, -1}, {1, -0.8f, 1}, {-1, -0.8f, 1});
  return s;
}

Scene flat_wall() {
  Scene s;
  quad(s, {-1, -1, 0.3f}, {1, -1, 0.3f}, {1, 1, 0.3f}, {-1, 1, 0.3f});
  return s;
}

std::vector<Ray> make_rays(const VoxelDomain& d, std::uint64_t seed, int n) {
  Rng rng{seed};
  const Aabb box = d.box();
  const glm::vec3 c = box.center();
  const float r = 0.5f * glm::length(box.extent());
  std::vector<Ray> rays;
  for (int i = 0; i < n; ++i) {
    const int kind = rng.below(8);
    glm::vec3 o, dir;
    if (kind <= 2) {  // inside, random direction
      o = rng.in_box(box.lo, box.hi);
      dir = rng.unit();
    } else if (kind <= 5) {  // outside, aimed at the domain
      o = c + 2.0f * r * rng.unit();
      dir = rng.in_box(box.lo, box.hi) - o;
    } else {  // axis-aligned, ±0 components, from inside or outside
      for (int k = 0; k < 3; ++k) dir[k] = rng.next() < 0.5 ? 0.0f : -0.0f;
      const int a = rng.below(3);
      dir[a] = rng.next() < 0.5 ? 1.0f : -1.0f;
      if (kind == 7) dir[(a + 1) % 3] = rng.next() < 0.5 ? 0.5f : -0.5f;
      o = rng.in_box(box.lo, box.hi);
      if (rng.next() < 0.5) o -= 3.0f * r * dir;
    }
    Ray ray(o, dir);
    if (rng.next() < 0.25) {
      ray.tmax = rng.range(0.1f, 2.0f) * r / glm::length(dir);
      if (rng.next() < 0.5) ray.tmin = ray.tmax * rng.range(0.0f, 0.6f);
    }
    rays.push_back(ray);
  }
  return rays;
}

// The march against the dense reference: same validity, t within 1e-5
// relative, same normal, same voxel. Returns the number of mismatches.
int compare_with_dense(const Scene& scene, int level, std::uint64_t seed, int nrays) {
  const Voxels vox(scene, VoxelOptions{level});
  const DenseVoxelGrid dense = vox.to_dense();
  int bad = 0;
  const QueryOptions qo;
  int i = 0;
  for (const Ray& ray : make_rays(vox.domain(), seed, nrays)) {
    const Hit ref = dense_voxel_march(dense, ray);
    RayStats st;
    const Hit h = ++i % 3 == 0 ? vox.closest_hit(ray, qo, &st) : vox.closest_hit(ray, qo);
    const bool any = vox.any_hit(ray, qo);
    bool ok = h.valid() == ref.valid() && any == ref.valid();
    if (ok && ref.valid())
      ok = std::fabs(h.t - ref.t) <= 1e-5f * std::max(1.0f, std::fabs(ref.t)) && h.ng == ref.ng && h.prim == ref.prim;
    if (!ok && ++bad <= 5)
      ADD_FAILURE() << "level " << level << " o=(" << ray.origin.x << "," << ray.origin.y << "," << ray.origin.z
                    << ") d=(" << ray.direction.x << "," << ray.direction.y << "," << ray.direction.z << ") t=["
                    << ray.tmin << "," << ray.tmax << "]: sparse prim " << static_cast<int>(h.prim) << " t " << h.t
                    << " n=(" << h.ng.x << "," << h.ng.y << "," << h.ng.z << "), dense prim "
                    << static_cast<int>(ref.prim) << " t " << ref.t << " n=(" << ref.ng.x << "," << ref.ng.y << ","
                    << ref.ng.z << ")";
  }
  return bad;
}

}  // namespace

TEST(Voxels, OptionsAreValidated) {
  const Scene s = flat_wall();
  EXPECT_THROW(Voxels(s, VoxelOptions{-1}), std::invalid_argument);
  EXPECT_THROW(Voxels(s, VoxelOptions{11}), std::invalid_argument);
  try {
    Voxels v(s, VoxelOptions{12});
    FAIL() << "level 12 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("level"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(Voxels(s, VoxelOptions{0}));
}

TEST(Voxels, EmptyInputMisses) {
  const Scene none;
  const Voxels v(none);
  EXPECT_EQ(v.root(), Voxels::Root::empty);
  EXPECT_EQ(v.occupied_count(), 0u);
  EXPECT_EQ(v.build_stats().node_count, 0u);
  const Ray r({0, 0, -5}, {0, 0, 1});
  EXPECT_FALSE(v.closest_hit(r, {}).valid());
  EXPECT_FALSE(v.any_hit(r, {}));
}

TEST(Voxels, NameAndStats) {
  const Voxels v(sphere_and_floor(), VoxelOptions{8});
  EXPECT_EQ(v.name(), "voxels");
  const BuildStats& st = v.build_stats();
  EXPECT_EQ(st.max_depth, 8u);
  EXPECT_EQ(st.extra.at("resolution"), 256.0);
  EXPECT_EQ(st.extra.at("dense_bytes"), 256.0 * 256 * 256 / 8);
  EXPECT_EQ(st.extra.at("occupied_voxels"), static_cast<double>(v.occupied_count()));
  EXPECT_EQ(st.memory_bytes, st.node_count * sizeof(VoxelNode));
  // At 256^3 a surface takes a fraction of the dense bits (at low levels
  // the 8-byte nodes can outweigh one bit per voxel: no such claim there).
  EXPECT_LT(st.memory_bytes, st.extra.at("dense_bytes") / 2) << "a surface must take less than the dense grid";
}

TEST(Voxels, OccupancyEqualsIndependentDenseVoxelization) {
  for (int level : {0, 1, 3, 5, 7}) {
    for (const Scene& s : {varied_soup(1, 300, 0.3f), sphere_and_floor(), flat_wall()}) {
      const Voxels v(s, VoxelOptions{level});
      const DenseVoxelGrid sparse = v.to_dense();
      const DenseVoxelGrid ref = voxelize_dense(s, v.domain());
      EXPECT_EQ(sparse.bits, ref.bits) << "level " << level;
      EXPECT_EQ(sparse.count(), v.occupied_count());
      // occupied() agrees with the expansion.
      Rng rng{static_cast<std::uint64_t>(level) + 5};
      const std::uint32_t r = v.domain().resolution;
      for (int k = 0; k < 2000; ++k) {
        const std::uint32_t x = rng.below(static_cast<int>(r)), y = rng.below(static_cast<int>(r)),
                            z = rng.below(static_cast<int>(r));
        ASSERT_EQ(v.occupied(x, y, z), ref.get(x, y, z));
      }
    }
  }
}

TEST(Voxels, EverySurfaceSampleLiesInAnOccupiedVoxel) {
  for (int level : {2, 5, 8}) {
    const Scene s = sphere_and_floor();
    const Voxels v(s, VoxelOptions{level});
    int samples = 0;
    for (const Triangle& t : s) {
      const int n = 12;
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n - i; ++j) {
          const float u = static_cast<float>(i) / n, w = static_cast<float>(j) / n;
          // Rounding of the interpolation may step out of the triangle's
          // bounds (and so out of the domain) by an ulp: clamp back.
          const Aabb b = t.bounds();
          const glm::vec3 p = glm::clamp((1 - u - w) * t.v0 + u * t.v1 + w * t.v2, b.lo, b.hi);
          ++samples;
          ASSERT_TRUE(v.occupied_at(p)) << "level " << level << " p=(" << p.x << "," << p.y << "," << p.z << ")";
        }
    }
    EXPECT_GT(samples, 50000);
  }
}

TEST(Voxels, FullBlocksCollapse) {
  // A thick random soup at level 2: every voxel ends up occupied, so the
  // whole domain collapses into a full root with no nodes at all.
  const Scene s = varied_soup(3, 4000, 0.4f);
  const Voxels v(s, VoxelOptions{2});
  ASSERT_EQ(v.occupied_count(), 64u);
  EXPECT_EQ(v.root(), Voxels::Root::full);
  EXPECT_EQ(v.build_stats().node_count, 0u);
  const Ray r(glm::vec3(0, 0, -10), {0, 0, 1});
  const Hit h = v.closest_hit(r, {});
  ASSERT_TRUE(h.valid());
  EXPECT_FLOAT_EQ(h.t, v.domain().plane(2, 0) + 10.0f);
  EXPECT_EQ(h.ng, glm::vec3(0, 0, -1));
  // At level 4 some 2x2x2 blocks are full but not everything.
  const Voxels v4(s, VoxelOptions{4});
  EXPECT_GT(v4.build_stats().extra.at("full_blocks"), 0.0);
  EXPECT_EQ(v4.to_dense().bits, voxelize_dense(s, v4.domain()).bits);
  // Leaves are the full octants: the full root is one leaf at depth 0; at
  // level 4 the collapsed blocks sit above the voxels' depth 4.
  EXPECT_EQ(v.build_stats().leaf_count, 1u);
  EXPECT_EQ(v.build_stats().avg_leaf_depth, 0.0);
  EXPECT_GT(v4.build_stats().avg_leaf_depth, 0.0);
  EXPECT_LT(v4.build_stats().avg_leaf_depth, 4.0);
  // Without collapsed blocks every leaf is a voxel, at the level.
  const Voxels thin(flat_wall(), VoxelOptions{5});
  ASSERT_EQ(thin.build_stats().extra.at("full_blocks"), 0.0);
  EXPECT_DOUBLE_EQ(thin.build_stats().avg_leaf_depth, 5.0);
}

TEST(Voxels, HitIsTheEntryFaceOfTheFirstOccupiedVoxel) {
  // A wall in the plane z = 0.3 spanning the domain: the wall's voxels are the
  // first layer (the domain is anchored at the bounds' lower corner).
  const Scene s = flat_wall();
  const Voxels v(s, VoxelOptions{3});
  const VoxelDomain& d = v.domain();
  EXPECT_EQ(d.lo.z, 0.3f);
  const Ray down({0.1f, 0.1f, 5}, {0, 0, -1});
  const Hit h = v.closest_hit(down, {});
  ASSERT_TRUE(h.valid());
  // Coming from above, the first occupied voxel is entered through its top face.
  std::uint32_t vx[3];
  ASSERT_TRUE(d.voxel_of({0.1f, 0.1f, 0.3f}, vx));
  EXPECT_EQ(h.prim, d.linear(vx[0], vx[1], 0));
  EXPECT_FLOAT_EQ(h.t, 5.0f - d.plane(2, 1));
  EXPECT_EQ(h.ng, glm::vec3(0, 0, 1));
  const Ray up({0.1f, 0.1f, -5}, {0, 0, 1});
  const Hit hu = v.closest_hit(up, {});
  ASSERT_TRUE(hu.valid());
  EXPECT_FLOAT_EQ(hu.t, 5.3f);
  EXPECT_EQ(hu.ng, glm::vec3(0, 0, -1));
}

TEST(Voxels, RayStartingInsideAnOccupiedVoxel) {
  const Scene s = flat_wall();
  const Voxels v(s, VoxelOptions{3});
  const VoxelDomain& d = v.domain();
  // Origin inside the wall's voxel layer, going sideways (+x, tilted in y):
  // t = tmin, the normal is the face through which the ray's line entered.
  const float z = 0.5f * (d.plane(2, 0) + d.plane(2, 1));
  const Ray r({0.05f, 0.07f, z}, {1, 0.25f, -0.0f}, 0.0f, kInfinity);
  const Hit h = v.closest_hit(r, {});
  ASSERT_TRUE(h.valid());
  EXPECT_EQ(h.t, 0.0f);
  const Hit ref = dense_voxel_march(v.to_dense(), r);
  EXPECT_EQ(h.ng, ref.ng);
  EXPECT_EQ(h.prim, ref.prim);
  EXPECT_EQ(h.ng, glm::vec3(-1, 0, 0));  // x crossings come first along this ray's line (|dx| > |dy|, cells square)
}

TEST(Voxels, SegmentEndingBeforeTheSurfaceMisses) {
  const Voxels v(flat_wall(), VoxelOptions{4});
  const Ray r({0, 0, 5}, {0, 0, -1}, 0.0f, 4.0f);  // stops above the wall's voxels
  EXPECT_FALSE(v.closest_hit(r, {}).valid());
  EXPECT_FALSE(v.any_hit(r, {}));
  const Ray r2({0, 0, 5}, {0, 0, -1}, 0.0f, 4.8f);
  EXPECT_TRUE(v.any_hit(r2, {}));
}

TEST(Voxels, StatsCountEmptySpaceSkippedAndTrace) {
  const Voxels v(sphere_and_floor(), VoxelOptions{7});
  const Ray r({-3, 0.95f, 0.9f}, {1, 0, 0});  // grazes above the sphere: mostly empty space
  RayStats st;
  VisitTrace tr;
  const Hit h = v.closest_hit(r, {}, &st, &tr);
  EXPECT_EQ(h.valid(), dense_voxel_march(v.to_dense(), r).valid());
  EXPECT_GT(st.empty_cells, 0u);
  EXPECT_GT(st.nodes_visited, 0u);
  EXPECT_EQ(st.box_tests, 1u);
  // Far fewer steps than voxels on the way (128 per axis): the hierarchy skips.
  RayStats dense_st;
  dense_voxel_march(v.to_dense(), r, &dense_st);
  EXPECT_LT(st.nodes_visited + st.empty_cells, dense_st.nodes_visited);
  const Ray hit_ray({0.2f, 3, -0.1f}, {0, -1, 0});
  VisitTrace tr2;
  const Hit h2 = v.closest_hit(hit_ray, {}, nullptr, &tr2);
  ASSERT_TRUE(h2.valid());
  ASSERT_FALSE(tr2.steps.empty());
  EXPECT_EQ(tr2.steps.back().kind, VisitStep::Kind::prim_hit);
  EXPECT_EQ(tr2.steps.back().id, h2.prim);
  EXPECT_EQ(tr2.steps.front().kind, VisitStep::Kind::node_entered);
}

TEST(Voxels, CancelledBuildThrows) {
  const Scene s = sphere_and_floor();
  EXPECT_THROW(Voxels(s, VoxelOptions{6}, [](double) { return false; }), BuildCancelled);
  double last = 0.0;
  int calls = 0;
  Voxels ok(s, VoxelOptions{6}, [&](double f) {
    EXPECT_GE(f, last);
    last = f;
    ++calls;
    return true;
  });
  EXPECT_GT(calls, 1);
  EXPECT_DOUBLE_EQ(last, 1.0);
}

TEST(Voxels, DegenerateInputsTerminate) {
  // All triangles at one point, duplicates, a single segment.
  Scene point(50, Triangle{{1, 2, 3}, {1, 2, 3}, {1, 2, 3}});
  const Voxels vp(point, VoxelOptions{5});
  EXPECT_GE(vp.occupied_count(), 1u);
  EXPECT_TRUE(vp.occupied_at({1, 2, 3}));
  Scene dup(100, Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 1}});
  const Voxels vd(dup, VoxelOptions{5});
  EXPECT_EQ(vd.to_dense().bits, voxelize_dense(dup, vd.domain()).bits);
  Scene seg{{{0, 0, 0}, {1, 1, 1}, {1, 1, 1}}};
  const Voxels vs(seg, VoxelOptions{4});
  EXPECT_GE(vs.occupied_count(), 16u);  // the diagonal crosses at least one voxel per layer
  EXPECT_EQ(compare_with_dense(seg, 4, 3, 2000), 0);
}

TEST(VoxelsDifferential, MarchEqualsDenseReference) {
  // 4 scenes x levels, 105,000 rays in all.
  int bad = 0;
  bad += compare_with_dense(sphere_and_floor(), 7, 11, 30000);
  bad += compare_with_dense(sphere_and_floor(), 4, 12, 15000);
  bad += compare_with_dense(varied_soup(2, 500, 0.2f), 6, 13, 25000);
  bad += compare_with_dense(varied_soup(4, 60, 0.8f), 8, 14, 15000);
  bad += compare_with_dense(flat_wall(), 5, 15, 10000);
  bad += compare_with_dense(varied_soup(3, 4000, 0.4f), 4, 16, 10000);
  EXPECT_EQ(bad, 0);
}
}  // namespace unity_test_voxels
