// Packet queries (Accelerator::closest_hits_packets / any_hits_packets; the
// BVH's packet walk, bvh_packet_traverse.inl): eight rays walked together
// must answer every ray as its single-ray query does. The adversarial,
// incoherent side (mixed direction signs, lanes parting early) is checked in
// test_bvh_differential.cpp on every option set; here: coherent camera rays
// (one direction sign per packet: the walk's uniform-sign path), on the
// shared meshes where present, packets of every length, structures without
// a packet walk, the batch functions, and bad spans.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/accel/bvh/bvh.h"
#include "core/accel/kdtree/kdtree.h"
#include "core/query/batch.h"
#include "core/query/camera.h"
#include "core/query/ray_sets.h"
#include "core/scene/load.h"
#include "spatial_test_scenes.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_bvh_packets {

using namespace accelviz;

namespace {

/// Compares packet answers with single-ray answers ray by ray: the same hit
/// bit for bit, or another triangle within the brute-force comparison's
/// tolerance of the same t (leaves visited in another order can reach another
/// of two hits a few ulps apart; test_bvh_differential.cpp explains).
/// Returns the number of rays that differ otherwise; counts hits and ties.
std::size_t count_mismatches(const Accelerator& accel, std::span<const Ray> rays, const QueryOptions& q,
                             std::span<const Hit> packet, std::span<const std::uint8_t> occluded, std::size_t& hits,
                             std::size_t& ties) {
  std::size_t bad = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Hit single = accel.closest_hit(rays[i], q);
    const Hit& p = packet[i];
    bool ok = p.valid() == single.valid() && (occluded[i] != 0) == accel.any_hit(rays[i], q);
    if (ok && single.valid()) {
      ++hits;
      if (p.prim == single.prim) {
        ok = p.t == single.t && p.u == single.u && p.v == single.v && p.ng == single.ng;
      } else {
        ++ties;
        ok = std::fabs(p.t - single.t) <= 1e-6f * std::max(1.0f, std::fabs(single.t));
      }
    }
    if (!ok && ++bad <= 5)
      ADD_FAILURE() << accel.name() << " ray " << i << ": packet prim " << p.prim << " t " << p.t << " occluded "
                    << int(occluded[i]) << ", single prim " << single.prim << " t " << single.t;
  }
  return bad;
}

/// Eight triangles around the origin in the z = 0 plane (shared edges along
/// the axes and the diagonals, one shared vertex), for a BVH that keeps them
/// in one leaf (fan_options): every packet lane reaches the same leaf.
std::vector<Triangle> fan_of_eight() {
  std::vector<Triangle> fan;
  const glm::vec3 c(0.0f, 0.0f, 0.0f);
  const glm::vec3 rim[8] = {{1, 0, 0},  {1, 1, 0},   {0, 1, 0},  {-1, 1, 0},
                            {-1, 0, 0}, {-1, -1, 0}, {0, -1, 0}, {1, -1, 0}};
  for (int i = 0; i < 8; ++i) fan.push_back({c, rim[i], rim[(i + 1) % 8]});
  return fan;
}

BvhOptions fan_options() {
  BvhOptions o;
  o.compute_epo = false;
  o.max_leaf_size = 16;
  return o;
}

/// Packets against single rays with both triangle tests: the very same
/// triangle, t, u and v for every ray (the leaf's triangles are tested in the
/// same order), and most rays must hit.
void expect_packets_equal_single_rays(const Bvh& bvh, std::span<const Ray> rays) {
  for (TriangleTest test : {TriangleTest::watertight, TriangleTest::moller_trumbore}) {
    QueryOptions q;
    q.triangle_test = test;
    std::vector<Hit> packet(rays.size());
    std::vector<std::uint8_t> occluded(rays.size());
    bvh.closest_hits_packets(rays, packet, q);
    bvh.any_hits_packets(rays, occluded, q);
    std::size_t hits = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const Hit single = bvh.closest_hit(rays[i], q);
      ASSERT_EQ(packet[i].prim, single.prim) << "ray " << i;
      ASSERT_EQ(occluded[i] != 0, bvh.any_hit(rays[i], q)) << "ray " << i;
      if (!single.valid()) continue;
      ++hits;
      EXPECT_EQ(packet[i].t, single.t) << "ray " << i;
      EXPECT_EQ(packet[i].u, single.u) << "ray " << i;
      EXPECT_EQ(packet[i].v, single.v) << "ray " << i;
    }
    EXPECT_GT(hits, rays.size() / 2);
  }
}

/// Camera rays at two distances over `tris`: whole views and close-ups, so
/// packets hit, miss and straddle silhouettes.
std::vector<Ray> camera_rays(std::span<const Triangle> tris, int width) {
  Aabb box;
  for (const Triangle& t : tris) box.extend(t.bounds());
  const int height = width * 3 / 4;
  std::vector<Ray> rays = primary_rays(frame_bounds(box, 4.0f / 3.0f), width, height);
  const Camera close = look_at(box.center() + 0.6f * (box.hi - box.center()), box.center(), 0.8f);
  const std::vector<Ray> near = primary_rays(close, width, height);
  rays.insert(rays.end(), near.begin(), near.end());
  return rays;
}

/// A soup over a floor of shared-edge quads (rays through shared edges and
/// vertices of the floor between the soup's triangles).
std::vector<Triangle> soup_over_floor(std::uint64_t seed, int n) {
  std::vector<Triangle> s = test_scenes::soup(seed, n, 0.08f);
  const int cells = 24;
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      const auto p = [&](int a, int b) {
        return glm::vec3(-1.5f + 3.0f * a / cells, -1.2f + 0.01f * ((a * 7 + b * 3) % 5), -1.5f + 3.0f * b / cells);
      };
      test_scenes::quad(s, p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
    }
  return s;
}

void check_camera_rays(std::span<const Triangle> tris, int width) {
  const std::vector<Ray> rays = camera_rays(tris, width);
  for (int wide_width : {4, 8}) {
    BvhOptions o;
    o.compute_epo = false;
    o.wide_width = wide_width;
    const Bvh bvh(tris, o);
    ASSERT_TRUE(bvh.has_packets());
    for (TriangleTest test : {TriangleTest::watertight, TriangleTest::moller_trumbore})
      for (bool ordered : {true, false}) {
        SCOPED_TRACE("width " + std::to_string(wide_width) + (ordered ? " ordered" : " unordered") +
                     (test == TriangleTest::watertight ? " watertight" : " MT"));
        QueryOptions q;
        q.triangle_test = test;
        q.ordered = ordered;
        std::vector<Hit> packet(rays.size());
        std::vector<std::uint8_t> occluded(rays.size());
        bvh.closest_hits_packets(rays, packet, q);
        bvh.any_hits_packets(rays, occluded, q);
        std::size_t hits = 0, ties = 0;
        EXPECT_EQ(count_mismatches(bvh, rays, q, packet, occluded, hits, ties), 0u);
        EXPECT_GT(hits, rays.size() / 10) << "the views must hit the scene";
        EXPECT_LT(hits, rays.size()) << "and miss it in places";
        EXPECT_LT(ties, rays.size() / 1000 + 1);
      }
  }
}

}  // namespace

TEST(BvhPackets, CoherentCameraRaysAnswerAsSingleRays) {
  // Silhouettes, shared edges and rays from outside in coherent packets.
  check_camera_rays(soup_over_floor(21, 3000), 96);
  check_camera_rays(test_scenes::soup(22, 5000, 0.05f), 96);
}

TEST(BvhPackets, SharedMeshesCameraRaysAnswerAsSingleRays) {
  int tested = 0;
  for (const char* mesh : {"bunny", "dragon"}) {
    const std::string file = std::string(ACCELVIZ_SHARED_ASSETS) + "/" + mesh + ".glb";
    if (!std::filesystem::exists(file)) continue;
    SCOPED_TRACE(file);
    check_camera_rays(load_scene(file).triangles, 160);
    ++tested;
  }
  if (tested == 0) GTEST_SKIP() << "no mesh of " << ACCELVIZ_SHARED_ASSETS << " present";
}

TEST(BvhPackets, ParallelRaysThroughSharedEdgesAndVerticesInOneLeaf) {
  // Packets of parallel rays (one sheared axis set for all lanes: the
  // ray-parallel triangle test) aimed exactly at the shared edges and the
  // shared vertex of a fan of eight triangles kept in one leaf, so the packet
  // and the single ray test the same triangles in the same order: the very
  // same triangle, t, u and v, including the lanes whose edge function is
  // exactly zero (answered by the scalar test, as for a single ray).
  const Bvh bvh(fan_of_eight(), fan_options());
  std::vector<Ray> rays;
  for (const glm::vec3 d : {glm::vec3(0, 0, -1), glm::vec3(0.25f, 0.125f, -1), glm::vec3(-0.5f, 0.25f, -1)})
    for (int y = -8; y <= 8; ++y)
      for (int x = -8; x <= 8; ++x) {
        // Points on the axes, the diagonals and the rim's edges (multiples of 1/8).
        const glm::vec3 target(x / 8.0f, y / 8.0f, 0.0f);
        rays.emplace_back(target - d, d);
      }
  expect_packets_equal_single_rays(bvh, rays);
}

TEST(BvhPackets, LanesOfMixedShearAxesAndSignsAnswerAsSingleRays) {
  // The ray-parallel watertight test needs every lane to shear the same axes
  // (same dominant axis, same sign along it); the packet's set-up decides
  // that for all lanes at once. Packets of eight rays aimed at one point of
  // a fan kept in one leaf (so all lanes reach the leaf together): lanes with
  // different dominant axes, the same axis with both signs, ties between
  // axes (x or y over z only when strictly larger), and uniform packets
  // along x and along y. Each lane answers as its ray alone, bit for bit.
  const Bvh bvh(fan_of_eight(), fan_options());
  using D = glm::vec3;
  const std::vector<std::vector<D>> patterns = {
      {D(0, 0, -1), D(0.25f, 0.125f, -1), D(1, 0.1f, -0.5f), D(0.1f, -1, -0.5f), D(-1, 0.2f, -0.3f), D(0.3f, 1, -0.2f),
       D(1, 0, -1), D(1, 1, -1)},  // lane 0 along -z, others along x or y, every z component negative
      {D(1, 0.1f, -0.5f), D(0.2f, 0.1f, -1), D(0.5f, -1, 0.4f), D(2, 0.5f, -1), D(0.1f, 0.1f, 1), D(1, 0.9f, 0.1f),
       D(0.3f, 1.5f, -0.7f), D(1, 0, 0.25f)},  // lane 0 along +x, others along y or z, every x component positive
      {D(0, 0, -1), D(0.1f, 0, -1), D(0, 0.1f, -1), D(0.2f, 0.1f, -1), D(0, 0, 1), D(0.1f, 0, 1), D(0, 0.1f, 1),
       D(-0.2f, 0.1f, 1)},  // along z, both signs
      {D(1, 0.1f, -0.5f), D(1, -0.2f, 0.5f), D(2, 0.5f, -1), D(1, 0, -0.25f), D(1.5f, 0.3f, 0.7f), D(1, -0.9f, 0.1f),
       D(1, 0.5f, -0.9f), D(3, 1, 1)},  // along +x everywhere
      {D(0.1f, -1, 0.5f), D(-0.2f, -1, -0.5f), D(0.5f, -2, 1), D(0, -1, 0.25f), D(0.3f, -1.5f, -0.7f),
       D(-0.9f, -1, 0.1f), D(0.5f, -1, -0.9f), D(1, -3, 1)},  // along -y everywhere
      {D(1, 0, -1), D(0, 1, -1), D(1, 1, -1), D(-1, -1, -1), D(-1, 0, -1), D(0, -1, -1), D(1, -1, -1),
       D(-1, 1, -1)},  // ties: z wins (x or y only when strictly larger)
      {D(1, 0, -1), D(0, 1, -1), D(1, 1, -1), D(-1, -1, 1), D(-1, 0, 1), D(0, -1, 1), D(1, 1, 1),
       D(-1, 1, -1)},  // ties, both signs
  };
  // Targets on the grid of eighths (edges, diagonals, the shared vertex) and
  // jittered off it; directions as written and normalised (inexact floats:
  // a lane sheared along another lane's axes would round differently).
  std::vector<Ray> rays;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> jitter(-0.06f, 0.06f);
  for (const std::vector<D>& pattern : patterns)
    for (bool exact : {true, false})
      for (int y = -8; y <= 8; y += 2)
        for (int x = -8; x <= 8; x += 2) {
          const glm::vec3 target{x / 8.0f + (exact ? 0.0f : jitter(rng)), y / 8.0f + (exact ? 0.0f : jitter(rng)),
                                 0.0f};
          for (const D& d : pattern) {
            const glm::vec3 dir = exact ? d : glm::normalize(d);
            rays.emplace_back(target - 1.37f * dir, dir);
          }
        }
  expect_packets_equal_single_rays(bvh, rays);
}

TEST(BvhPackets, EveryPacketLengthAndOffset) {
  // Spans of 1..19 rays starting anywhere: short last packets, idle lanes.
  const std::vector<Triangle> tris = test_scenes::soup(23, 2000, 0.06f);
  const Bvh bvh(tris, BvhOptions{.compute_epo = false});
  const std::vector<Ray> rays = camera_rays(tris, 40);
  const QueryOptions q;
  for (std::size_t offset : {0u, 3u, 517u})
    for (std::size_t n = 1; n <= 19; ++n) {
      const std::span<const Ray> part(rays.data() + offset, n);
      std::vector<Hit> packet(n);
      std::vector<std::uint8_t> occluded(n, 7);
      bvh.closest_hits_packets(part, packet, q);
      bvh.any_hits_packets(part, occluded, q);
      std::size_t hits = 0, ties = 0;
      EXPECT_EQ(count_mismatches(bvh, part, q, packet, occluded, hits, ties), 0u) << "offset " << offset << " n " << n;
      for (std::uint8_t o : occluded) EXPECT_LE(o, 1);
    }
  // Empty spans and an empty scene answer nothing and everything missed.
  std::vector<Hit> none;
  std::vector<std::uint8_t> none_any;
  bvh.closest_hits_packets({}, none, q);
  bvh.any_hits_packets({}, none_any, q);
  const Bvh empty(std::vector<Triangle>{}, BvhOptions{.compute_epo = false});
  std::vector<Hit> h(9);
  std::vector<std::uint8_t> o(9, 1);
  empty.closest_hits_packets(std::span(rays).first(9), h, q);
  empty.any_hits_packets(std::span(rays).first(9), o, q);
  for (std::size_t i = 0; i < 9; ++i) {
    EXPECT_FALSE(h[i].valid());
    EXPECT_EQ(o[i], 0);
  }
}

TEST(BvhPackets, StructuresWithoutAPacketWalkAnswerPerRay) {
  const std::vector<Triangle> tris = test_scenes::soup(24, 1500, 0.06f);
  const std::vector<Ray> rays = camera_rays(tris, 48);
  const Bvh binary(tris, BvhOptions{.compute_epo = false, .wide_traversal = false});
  const KdTree kd(tris);
  for (const Accelerator* a : {static_cast<const Accelerator*>(&binary), static_cast<const Accelerator*>(&kd)}) {
    EXPECT_FALSE(a->has_packets()) << a->name();
    std::vector<Hit> packet(rays.size());
    std::vector<std::uint8_t> occluded(rays.size());
    a->closest_hits_packets(rays, packet, {});
    a->any_hits_packets(rays, occluded, {});
    std::size_t hits = 0, ties = 0;
    EXPECT_EQ(count_mismatches(*a, rays, {}, packet, occluded, hits, ties), 0u);
    EXPECT_EQ(ties, 0u) << "per ray: the very same walk";
  }
}

TEST(BvhPackets, BatchOverThreadsEqualsOneCall) {
  // trace_*_packets rounds its chunks to whole packets (chunk 5 -> 8): the
  // same packets, so the same answers, for every thread count.
  const std::vector<Triangle> tris = test_scenes::soup(25, 3000, 0.06f);
  const Bvh bvh(tris, BvhOptions{.compute_epo = false});
  const std::vector<Ray> rays = camera_rays(tris, 64);
  std::vector<Hit> one(rays.size()), many(rays.size());
  std::vector<std::uint8_t> one_any(rays.size()), many_any(rays.size());
  bvh.closest_hits_packets(rays, one, {});
  bvh.any_hits_packets(rays, one_any, {});
  ASSERT_TRUE(trace_closest_packets(bvh, rays, many, {}, BatchOptions{.threads = 3, .chunk = 5}));
  ASSERT_TRUE(trace_any_packets(bvh, rays, many_any, {}, BatchOptions{.threads = 3, .chunk = 5}));
  for (std::size_t i = 0; i < rays.size(); ++i) {
    ASSERT_EQ(many[i].prim, one[i].prim) << i;
    ASSERT_EQ(many[i].t, one[i].t) << i;
    ASSERT_EQ(many_any[i], one_any[i]) << i;
  }
}

TEST(BvhPackets, MismatchedSpansThrow) {
  const std::vector<Triangle> tris = test_scenes::soup(26, 100, 0.06f);
  const Bvh bvh(tris, BvhOptions{.compute_epo = false});
  const std::vector<Ray> rays = camera_rays(tris, 8);
  std::vector<Hit> short_hits(rays.size() - 1);
  std::vector<std::uint8_t> long_any(rays.size() + 1);
  EXPECT_THROW(bvh.closest_hits_packets(rays, short_hits, {}), std::invalid_argument);
  EXPECT_THROW(bvh.any_hits_packets(rays, long_any, {}), std::invalid_argument);
  EXPECT_THROW(trace_closest_packets(bvh, rays, short_hits, {}, BatchOptions{}), std::invalid_argument);
}

}  // namespace unity_test_bvh_packets
