#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <random>
#include <string>

#include "core/accel/brute_force.h"
#include "core/accel/bvh/bvh.h"
#include "core/accel/embree_backend.h"
#include "core/accel/reference.h"
#include "core/query/batch.h"
#include "core/query/camera.h"
#include "core/query/ray_sets.h"
#include "core/scene/effects.h"
#include "core/scene/load.h"
#include "tests/support/test_scale.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_embree {

using namespace accelviz;

#ifdef ACCELVIZ_HAVE_EMBREE

namespace {

/// Seeded soup of small random triangles in [-1, 1]^3.
std::vector<Triangle> random_soup(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-1.0f, 1.0f), off(-0.15f, 0.15f);
  std::vector<Triangle> tris;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 c{pos(rng), pos(rng), pos(rng)};
    tris.push_back({c + glm::vec3{off(rng), off(rng), off(rng)}, c + glm::vec3{off(rng), off(rng), off(rng)},
                    c + glm::vec3{off(rng), off(rng), off(rng)}});
  }
  return tris;
}

/// Rays from outside and inside the soup, random directions; a third are
/// segments with finite tmax, some start at tmin > 0.
std::vector<Ray> random_rays(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), len(0.1f, 3.0f);
  std::vector<Ray> rays;
  while (rays.size() < n) {
    const glm::vec3 d{u(rng), u(rng), u(rng)};
    if (glm::dot(d, d) < 1e-4f) continue;
    const bool outside = rays.size() % 2 == 0;
    const glm::vec3 o = outside ? glm::vec3{u(rng), u(rng), u(rng)} * 3.0f : glm::vec3{u(rng), u(rng), u(rng)};
    const float tmin = rays.size() % 5 == 0 ? 0.2f : 0.0f;
    const float tmax = rays.size() % 3 == 0 ? tmin + len(rng) : kInfinity;
    rays.emplace_back(o, outside ? glm::normalize(-o + 0.5f * d) : d, tmin, tmax);
  }
  return rays;
}

/// a and b agree to `rel` of b (absolute below 1).
bool same_t(float a, float b, float rel = 1e-4f) {
  return std::abs(a - b) <= rel * std::max(1.0f, std::abs(b));
}

/// A packet query's hit against the same structure's one-ray hit: both
/// miss, or both hit within a few ulps (leaves may be visited in another
/// order).
bool same_hit_as_single(const Hit& packet, const Hit& single) {
  return packet.valid() == single.valid() && (!packet.valid() || same_t(packet.t, single.t, 1e-6f));
}

}  // namespace

TEST(Embree, ClosestAndAnyHitAgreeWithBruteForce) {
  const std::vector<Triangle> tris = random_soup(3000, 11);
  const std::vector<Ray> rays = random_rays(4000, 12);
  const BruteForce reference(tris);
  const EmbreeAccelerator embree(tris);
  EXPECT_EQ(embree.name(), "embree");
  const QueryOptions q;
  int hits = 0, misses = 0, ties = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Hit expected = reference.closest_hit(rays[i], q);
    const Hit got = embree.closest_hit(rays[i], q);
    ASSERT_EQ(got.valid(), expected.valid()) << "ray " << i;
    if (expected.valid()) {
      ++hits;
      EXPECT_TRUE(same_t(got.t, expected.t)) << "ray " << i << ": " << got.t << " vs " << expected.t;
      if (got.prim != expected.prim) {
        ++ties;  // allowed only as a tie in t (checked above)
      } else {
        EXPECT_NEAR(got.u, expected.u, 1e-3f);
        EXPECT_NEAR(got.v, expected.v, 1e-3f);
        EXPECT_EQ(got.ng, expected.ng);
      }
    } else {
      ++misses;
    }
    EXPECT_EQ(embree.any_hit(rays[i], q), reference.any_hit(rays[i], q)) << "ray " << i;
  }
  // The data exercises both outcomes.
  EXPECT_GT(hits, 500);
  EXPECT_GT(misses, 500);
  EXPECT_LT(ties, 5);
}

TEST(Embree, PacketsAgreeWithSingleRays) {
  // rtcIntersect8/rtcOccluded8 (the reference for our packet figures) on
  // random rays (incoherent, idle lanes at the end) and camera rays
  // (coherent) against rtcIntersect1/rtcOccluded1.
  const std::vector<Triangle> tris = random_soup(3000, 13);
  std::vector<Ray> rays = random_rays(2001, 14);
  const std::vector<Ray> camera = primary_rays(frame_bounds(Aabb{glm::vec3(-1.2f), glm::vec3(1.2f)}, 1.0f), 40, 40);
  rays.insert(rays.end(), camera.begin(), camera.end());
  const EmbreeAccelerator embree(tris);
  std::vector<Hit> packet(rays.size());
  std::vector<std::uint8_t> occluded(rays.size());
  embree.closest_hits_packets(rays, packet, {});
  embree.any_hits_packets(rays, occluded, {});
  int hits = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Hit single = embree.closest_hit(rays[i], {});
    ASSERT_EQ(packet[i].valid(), single.valid()) << "ray " << i;
    if (single.valid()) {
      ++hits;
      EXPECT_TRUE(same_t(packet[i].t, single.t)) << "ray " << i << ": " << packet[i].t << " vs " << single.t;
    }
    EXPECT_EQ(occluded[i] != 0, embree.any_hit(rays[i], {})) << "ray " << i;
  }
  EXPECT_GT(hits, 500);
  EXPECT_LT(hits, static_cast<int>(rays.size()));
}

// Embree as a second oracle on the real meshes of ../shared/assets (skipped
// where they are absent): our BVH (watertight test, the fast path) and
// Embree in robust mode (its watertight mode) give the same closest hit
// (the same triangle, or the same t where two triangles tie at a shared
// edge) and the same any-hit answer on camera rays, their diffuse bounces
// and shadow rays, and random rays through the mesh's box. Release: the
// bunny, the dragon and the kitchen, about 1.4 M rays each;
// ACCELVIZ_VERIFY_SCALE < 1 (the sanitizer run; tests/support/test_scale.h)
// keeps the bunny and scales the ray counts.
TEST(EmbreeOracle, SharedMeshesClosestAndAnyHitAgreeWithTheBvh) {
  const double scale = test_scale::verify_scale();
  std::vector<std::string> meshes = {"bunny", "dragon", "kitchen_partial"};
  if (scale < 1.0) meshes.resize(1);
  int tested = 0;
  for (const std::string& mesh : meshes) {
    const std::string file = std::string(ACCELVIZ_SHARED_ASSETS) + "/" + mesh + ".glb";
    if (!std::filesystem::exists(file)) continue;
    SCOPED_TRACE(file);
    const Scene scene = load_scene(file);
    const std::vector<Triangle>& tris = scene.triangles;
    BvhOptions bo;
    bo.compute_epo = false;
    const Bvh bvh(tris, bo);
    EmbreeOptions eo;
    eo.robust = true;
    const EmbreeAccelerator embree(tris, eo);

    // Camera rays at two distances, then their bounces and shadow rays.
    const Aabb box = scene.bounds();
    const int w = std::max(32, static_cast<int>(480 * std::sqrt(scale))), h = w * 3 / 4;
    std::vector<Ray> rays = primary_rays(frame_bounds(box, 4.0f / 3.0f), w, h);
    const Camera close = look_at(box.center() + 0.6f * (box.hi - box.center()), box.center(), 0.8f);
    const std::vector<Ray> near = primary_rays(close, w, h);
    rays.insert(rays.end(), near.begin(), near.end());
    std::vector<Hit> primary_hits(rays.size());
    trace_closest(bvh, rays, primary_hits, {}, 0u);
    const std::vector<Ray> bounces = diffuse_rays(tris, rays, primary_hits, 7);
    const Light light[] = {synthetic_light(box)};
    const std::vector<Ray> shadows = shadow_rays(tris, rays, primary_hits, light);
    rays.insert(rays.end(), bounces.begin(), bounces.end());
    rays.insert(rays.end(), shadows.begin(), shadows.end());
    // Random rays: from a sphere around the box towards random points inside it.
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const float radius = glm::length(box.hi - box.lo);
    const std::size_t random_count = static_cast<std::size_t>(600'000 * scale);
    for (std::size_t i = 0; i < random_count; ++i) {
      const glm::vec3 target = box.lo + glm::vec3{u(rng), u(rng), u(rng)} * (box.hi - box.lo);
      const float z = 2.0f * u(rng) - 1.0f, phi = 6.2831853f * u(rng), r = std::sqrt(std::max(0.0f, 1.0f - z * z));
      const glm::vec3 origin = box.center() + radius * glm::vec3(r * std::cos(phi), r * std::sin(phi), z);
      rays.emplace_back(origin, target - origin);
    }

    std::vector<Hit> ours(rays.size()), theirs(rays.size());
    std::vector<std::uint8_t> ours_any(rays.size()), theirs_any(rays.size());
    ASSERT_TRUE(trace_closest(bvh, rays, ours, {}, 0u));
    ASSERT_TRUE(trace_closest(embree, rays, theirs, {}, 0u));
    ASSERT_TRUE(trace_any(bvh, rays, ours_any, {}, 0u));
    ASSERT_TRUE(trace_any(embree, rays, theirs_any, {}, 0u));
    // The packet figures of bench compare rtcIntersect8/rtcOccluded8 with
    // our packet walk on these rays: each side's packets must give its own
    // one-ray answers (the same t; the same any-hit answer).
    {
      std::vector<Hit> ours_p(rays.size()), theirs_p(rays.size());
      std::vector<std::uint8_t> ours_any_p(rays.size()), theirs_any_p(rays.size());
      ASSERT_TRUE(trace_closest_packets(bvh, rays, ours_p, {}, BatchOptions{0u}));
      ASSERT_TRUE(trace_closest_packets(embree, rays, theirs_p, {}, BatchOptions{0u}));
      ASSERT_TRUE(trace_any_packets(bvh, rays, ours_any_p, {}, BatchOptions{0u}));
      ASSERT_TRUE(trace_any_packets(embree, rays, theirs_any_p, {}, BatchOptions{0u}));
      std::size_t packet_differ = 0;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        const bool ok = same_hit_as_single(ours_p[i], ours[i]) && same_hit_as_single(theirs_p[i], theirs[i]) &&
                        ours_any_p[i] == ours_any[i] && theirs_any_p[i] == theirs_any[i];
        if (!ok && ++packet_differ <= 5)
          ADD_FAILURE() << "ray " << i << ": packets differ from single rays (ours " << ours_p[i].t << " vs "
                        << ours[i].t << ", any " << int(ours_any_p[i]) << " vs " << int(ours_any[i]) << "; Embree "
                        << theirs_p[i].t << " vs " << theirs[i].t << ", any " << int(theirs_any_p[i]) << " vs "
                        << int(theirs_any[i]) << ")";
      }
      EXPECT_EQ(packet_differ, 0u);
    }
    // Where the two differ (a hit against a miss, another t, another
    // any-hit answer), the double-precision brute force judges: our answer
    // must match it or differ from it only within rounding (an edge or
    // vertex decision, equal t), as in `accelviz verify`.
    const ReferenceTracer reference(tris);
    std::size_t hits = 0, differ = 0, ours_wrong = 0, embree_wrong = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const Hit& a = ours[i];
      const Hit& b = theirs[i];
      ASSERT_EQ(ours_any[i] != 0, a.valid()) << "ray " << i << ": any hit and closest hit disagree";
      hits += a.valid();
      const bool same = a.valid() == b.valid() && ours_any[i] == theirs_any[i] &&
                        (!a.valid() || std::abs(a.t - b.t) <= 1e-5f * std::max(1.0f, std::abs(b.t)));
      if (same) continue;
      ASSERT_LT(++differ, 1000u) << "too many disagreements with Embree to judge";
      const ReferenceHit ref = reference.closest_hit(rays[i]);
      const auto wrong = [&](const Hit& h, bool any) {
        const Verdict c = classify_closest(tris, rays[i], ref, h), y = classify_any(ref, any);
        return (c != Verdict::match && c != Verdict::near_tie) || (y != Verdict::match && y != Verdict::near_tie);
      };
      if (wrong(a, ours_any[i] != 0)) {
        ++ours_wrong;
        ADD_FAILURE() << "ray " << i << " (" << rays[i].origin.x << ", " << rays[i].origin.y << ", " << rays[i].origin.z
                      << ") dir (" << rays[i].direction.x << ", " << rays[i].direction.y << ", " << rays[i].direction.z
                      << "): ours prim " << a.prim << " t " << a.t << ", Embree prim " << b.prim << " t " << b.t
                      << ", reference prim " << ref.prim << " t " << ref.t;
      }
      embree_wrong += wrong(b, theirs_any[i] != 0);
    }
    EXPECT_EQ(ours_wrong, 0u);
    std::printf(
        "%s: %zu rays, %zu hits; %zu differ from Embree (robust); beyond rounding of the double reference: "
        "ours %zu, Embree's %zu\n",
        mesh.c_str(), rays.size(), hits, differ, ours_wrong, embree_wrong);
    EXPECT_GT(hits, rays.size() / 10) << "the rays must mostly test hits";
    EXPECT_LT(hits, rays.size());
    ++tested;
  }
  if (tested == 0) GTEST_SKIP() << "no mesh of " << ACCELVIZ_SHARED_ASSETS << " present";
}

// Embree's build reports its progress to ours (its scene progress monitor), and a false from ours
// cancels it: BuildCancelled (the factory said 0 % then 100 %, and a Cancel waited for the build).
TEST(Embree, TheBuildReportsProgressAndCanBeCancelled) {
  const std::vector<Triangle> tris = random_soup(200000, 5);
  std::vector<double> heard;
  const EmbreeAccelerator built(tris, EmbreeOptions{}, [&](double f) {
    heard.push_back(f);
    return true;
  });
  ASSERT_GE(heard.size(), 3u);
  EXPECT_EQ(heard.front(), 0.0);
  EXPECT_EQ(heard.back(), 1.0);
  EXPECT_TRUE(std::any_of(heard.begin(), heard.end(), [](double f) { return f > 0.0 && f < 1.0; }))
      << "Embree's own steps between 0 and 1";
  for (const double f : heard) {
    EXPECT_GE(f, 0.0);
    EXPECT_LE(f, 1.0);
  }
  int calls = 0;
  EXPECT_THROW(EmbreeAccelerator(tris, EmbreeOptions{}, [&](double f) { return ++calls < 2 || f <= 0.0; }),
               BuildCancelled);
  EXPECT_GE(calls, 2);
  // A build after the cancelled one is whole: it answers as the first.
  const EmbreeAccelerator again(tris);
  for (const Ray& r : {Ray({0, 0, -5}, {0, 0, 1}), Ray({-5, 0.1f, 0.2f}, {1, 0, 0})})
    EXPECT_EQ(again.closest_hit(r, {}).prim, built.closest_hit(r, {}).prim);
}

TEST(Embree, LeavesRayStatsAtZero) {
  // ... and says so: the views show n/a, not 0 nodes (Accelerator::inspectable()).
  const std::vector<Triangle> tris = random_soup(100, 3);
  const EmbreeAccelerator embree(tris);
  EXPECT_FALSE(embree.inspectable());
  EXPECT_TRUE(Bvh(tris).inspectable());
  RayStats st;
  embree.closest_hit(Ray({0, 0, -5}, {0, 0, 1}), {}, &st);
  embree.any_hit(Ray({0, 0, -5}, {0, 0, 1}), {}, &st);
  EXPECT_EQ(st.nodes_visited + st.prim_tests + st.box_tests, 0u);
  EXPECT_GT(embree.build_stats().memory_bytes, 100u * sizeof(Triangle));
  EXPECT_GE(embree.build_stats().build_ms, 0.0);
}

// Embree's kernels assert on these rays (an abort with Debian's build):
// every query refuses them with one line, and ray_problem names the cause;
// rays at the limits are traced.
TEST(Embree, RaysItsKernelsCannotTakeAreRefusedNotTraced) {
  const std::vector<Triangle> tris = random_soup(100, 3);
  const EmbreeAccelerator embree(tris);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  struct Case {
    Ray ray;
    const char* says;
  };
  const Case refused[] = {
      {Ray({0, 0, -5}, {0, 0, 1}, -100.0f, kInfinity), "tmin -100 is not >= 0"},
      {Ray({0, 0, -5}, {0, 0, 1}, -kInfinity, kInfinity), "tmin -inf is not >= 0"},
      {Ray({0, 0, -5}, {0, 0, 1}, nan, kInfinity), "tmin nan is not >= 0"},
      {Ray({0, 0, -5}, {0, 0, 1}, 0.0f, nan), "tmax is NaN"},
      {Ray({2e18f, 0, -5}, {0, 0, 1}), "origin (2e+18, 0, -5) has a component that is NaN or beyond"},
      {Ray({0, 0, -5}, {0, 0, -3e38f}), "direction (0, 0, -3e+38) has a component"},
      {Ray({0, 0, -5}, {1e-20f, -2e-20f, 9e-16f}), "direction (1e-20, -2e-20, 9e-16) has no component of 1e-15"},
      {Ray({0, 0, -5}, {0, 0, 0}), "direction (0, 0, 0) has no component of 1e-15"},
  };
  for (const Case& c : refused) {
    SCOPED_TRACE(c.says);
    EXPECT_NE(embree.ray_problem(c.ray).find(c.says), std::string::npos) << embree.ray_problem(c.ray);
    EXPECT_THROW(embree.closest_hit(c.ray, {}), std::invalid_argument);
    EXPECT_THROW(embree.any_hit(c.ray, {}), std::invalid_argument);
    // In a packet, after a good ray.
    const std::vector<Ray> rays = {Ray({0, 0, -5}, {0, 0, 1}), c.ray};
    std::vector<Hit> hits(rays.size());
    std::vector<std::uint8_t> occluded(rays.size());
    EXPECT_THROW(embree.closest_hits_packets(rays, hits, {}), std::invalid_argument);
    EXPECT_THROW(embree.any_hits_packets(rays, occluded, {}), std::invalid_argument);
    try {
      embree.closest_hit(c.ray, {});
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()), "embree: " + embree.ray_problem(c.ray));
    }
  }
  // At the limits: traced, and the same as the BVH's answer.
  const Bvh bvh(tris);
  for (const Ray& r : {Ray({0, 0, -5}, {0, 0, 1}, 0.0f, kInfinity), Ray({0, 0, -1.8e18f}, {0, 0, 1.8e18f}),
                       Ray({0, 0, -5}, {0, 0, 1}, -0.0f, 1e30f)}) {
    EXPECT_EQ(embree.ray_problem(r), "");
    EXPECT_EQ(embree.closest_hit(r, {}).valid(), bvh.closest_hit(r, {}).valid());
    EXPECT_EQ(embree.any_hit(r, {}), bvh.any_hit(r, {}));
  }
  // Our structures take every one of them.
  for (const Case& c : refused) EXPECT_EQ(bvh.ray_problem(c.ray), "");
}

// Embree clamps 1/d at 1e18 in its box tests, so a ray whose direction is
// that short misses what it hits (measured: from a largest component of
// ~1e-17 at distance ~6). It refuses directions below 1e-15 (above); from
// there on it agrees with brute force, segments and tmin > 0 included.
TEST(Embree, ShortDirectionsFrom1em15AgreeWithBruteForce) {
  const std::vector<Triangle> tris = random_soup(3000, 11);
  const BruteForce reference(tris);
  const EmbreeAccelerator embree(tris);
  int hits = 0;
  for (const Ray& unit : random_rays(4000, 21)) {
    const float m =
        std::max(std::abs(unit.direction.x), std::max(std::abs(unit.direction.y), std::abs(unit.direction.z)));
    const float s = 1e-15f / m;  // the largest component exactly at the limit (rounded up when it is not)
    Ray r(unit.origin, unit.direction * s, unit.tmin / s, unit.tmax / s);
    if (std::max(std::abs(r.direction.x), std::max(std::abs(r.direction.y), std::abs(r.direction.z))) < 1e-15f)
      r.direction *= 1.0000001f;
    ASSERT_EQ(embree.ray_problem(r), "");
    const Hit expected = reference.closest_hit(r, {});
    const Hit got = embree.closest_hit(r, {});
    ASSERT_EQ(got.valid(), expected.valid()) << unit.origin.x << " " << unit.direction.x;
    if (expected.valid()) {
      ++hits;
      EXPECT_TRUE(same_t(got.t, expected.t)) << got.t << " vs " << expected.t;
    }
    EXPECT_EQ(embree.any_hit(r, {}), reference.any_hit(r, {}));
  }
  EXPECT_GT(hits, 1000);
}

// Embree's triangle tests multiply three scene-sized figures in float
// (|v0 - o|·|e1|·|e2| and the like): on a soup scaled to 1e13 with rays of
// the scene's size they overflow and Embree loses hits (verify mismatched
// 1854 of 5000 rays on such a cube). Every ray Embree takes agrees with
// brute force, in both modes; at 1e11 it takes them all, at 1e14 none.
TEST(Embree, RaysWhoseTriangleProductsWouldOverflowAreRefused) {
  for (const bool robust : {false, true}) {
    for (const float scale : {1e11f, 1e12f, 3e12f, 1e13f, 1e14f}) {
      SCOPED_TRACE(std::string(robust ? "robust " : "default ") + std::to_string(scale));
      std::vector<Triangle> tris = random_soup(400, 5);
      for (Triangle& t : tris) t = {t.v0 * scale, t.v1 * scale, t.v2 * scale};
      const BruteForce reference(tris);
      EmbreeOptions o;
      o.robust = robust;
      const EmbreeAccelerator embree(tris, o);
      std::size_t taken = 0, hits = 0;
      const std::vector<Ray> unit = random_rays(1500, 6);
      for (const Ray& u : unit) {
        // Origin and direction scaled alike: the same t, the same hits.
        const Ray r(u.origin * scale, u.direction * scale, u.tmin, u.tmax);
        const std::string problem = embree.ray_problem(r);
        if (!problem.empty()) {
          EXPECT_NE(problem.find("would overflow"), std::string::npos) << problem;
          EXPECT_THROW((void)embree.closest_hit(r, {}), std::invalid_argument);
          EXPECT_THROW((void)embree.any_hit(r, {}), std::invalid_argument);
          continue;
        }
        ++taken;
        const Hit expected = reference.closest_hit(r, {}), got = embree.closest_hit(r, {});
        ASSERT_EQ(got.valid(), expected.valid()) << "ray " << taken;
        if (expected.valid()) {
          ++hits;
          EXPECT_TRUE(same_t(got.t, expected.t)) << got.t << " vs " << expected.t;
        }
        EXPECT_EQ(embree.any_hit(r, {}), reference.any_hit(r, {}));
      }
      if (scale == 1e11f) {
        EXPECT_EQ(taken, unit.size());
        EXPECT_GT(hits, 100u);
      }
      if (scale == 1e14f) {
        EXPECT_EQ(taken, 0u);
      }
    }
  }
}

// Embree's build silently leaves out a triangle with a coordinate beyond
// ±1.844e18: the accelerator refuses the scene instead of missing it.
TEST(Embree, TrianglesItsBuildWouldLeaveOutAreRefused) {
  std::vector<Triangle> tris = random_soup(10, 3);
  tris.push_back({{0, 0, 0}, {1.9e18f, 0, 0}, {0, 1, 0}});
  tris.push_back({{0, 0, 0}, {0, -1e30f, 0}, {0, 0, 1}});
  try {
    const EmbreeAccelerator embree(tris);
    ADD_FAILURE() << "built a scene whose triangles 10 and 11 Embree leaves out";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("embree: 2 triangles (the first: triangle 10) have a vertex coordinate "
                                         "beyond ±1.844e18"),
              std::string::npos)
        << e.what();
  }
  tris.resize(11);  // one: named
  try {
    const EmbreeAccelerator embree(tris);
    ADD_FAILURE() << "built a scene whose triangle 10 Embree leaves out";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("embree: triangle 10 has a vertex coordinate beyond ±1.844e18"),
              std::string::npos)
        << e.what();
  }
  tris.resize(10);
  tris.push_back({{0, 0, 0}, {1.8e18f, 0, 0}, {0, 1, 0}});  // within the limit: built
  EXPECT_NO_THROW(EmbreeAccelerator{tris});
}

// Embree's float triangle test underflows on tiny scenes: a 4x4-per-face cube of half-size 1e-12
// mismatched 4 of 5,000 `verify` rays and one of 1e-14 418, where its products (edge²·extent) fall to
// 5e-37 and 5e-43. Such a scene is refused with one line; a soup of 1e-10 is traced and agrees with
// brute force. Where the edges are tiny and the extent is not, a ray whose direction is too short for
// the products is refused instead.
TEST(Embree, ScenesAndDirectionsTooSmallForItsFloatTestAreRefused) {
  for (const bool robust : {false, true}) {
    EmbreeOptions o;
    o.robust = robust;
    for (const float s : {1e-10f, 1e-12f, 1e-20f}) {
      SCOPED_TRACE(std::string(robust ? "robust " : "default ") + std::to_string(s));
      std::vector<Triangle> tris = random_soup(400, 5);
      for (Triangle& t : tris) t = {t.v0 * s, t.v1 * s, t.v2 * s};
      if (s < 1e-11f) {
        try {
          const EmbreeAccelerator embree(tris, o);
          ADD_FAILURE() << "built a scene too small for Embree's float test";
        } catch (const std::runtime_error& e) {
          EXPECT_NE(std::string(e.what()).find("embree: the scene is too small for Embree's float triangle test"),
                    std::string::npos)
              << e.what();
        }
        continue;
      }
      const EmbreeAccelerator embree(tris, o);
      const BruteForce reference(tris);
      std::size_t hits = 0;
      for (const Ray& u : random_rays(1500, 6)) {
        const Ray r(u.origin * s, u.direction * s, u.tmin, u.tmax);
        ASSERT_EQ(embree.ray_problem(r), "");
        const Hit expected = reference.closest_hit(r, {}), got = embree.closest_hit(r, {});
        ASSERT_EQ(got.valid(), expected.valid());
        if (expected.valid()) {
          ++hits;
          EXPECT_TRUE(same_t(got.t, expected.t)) << got.t << " vs " << expected.t;
        }
        EXPECT_EQ(embree.any_hit(r, {}), reference.any_hit(r, {}));
      }
      EXPECT_GT(hits, 100u);
    }
  }
  // Edges of about 1e-12 over an extent of 1e-6: the scene is taken, a direction needs a component
  // of about 1e-37 / (1e-12)² = 1e-13.
  const glm::vec3 far(1e-6f, 1e-6f, 1e-6f);
  const std::vector<Triangle> tiny = {{{0, 0, 0}, {1e-12f, 0, 0}, {0, 1e-12f, 0}},
                                      {far, far + glm::vec3(1e-12f, 0, 0), far + glm::vec3(0, 1e-12f, 0)}};
  const EmbreeAccelerator embree(tiny);
  const Ray short_ray({2e-13f, 2e-13f, -1e-6f}, {0, 0, 1e-14f}), long_ray({2e-13f, 2e-13f, -1e-6f}, {0, 0, 1e-12f});
  const std::string problem = embree.ray_problem(short_ray);
  EXPECT_NE(problem.find("has no component of 9.55201e-14 or more in this scene"), std::string::npos) << problem;
  EXPECT_NE(problem.find("would underflow"), std::string::npos) << problem;
  EXPECT_THROW((void)embree.closest_hit(short_ray, {}), std::invalid_argument);
  ASSERT_EQ(embree.ray_problem(long_ray), "");
  const Hit h = embree.closest_hit(long_ray, {});
  ASSERT_TRUE(h.valid());
  EXPECT_EQ(h.prim, 0u);
  EXPECT_TRUE(same_t(h.t, BruteForce(tiny).closest_hit(long_ray, {}).t));
}

TEST(Embree, EmptySceneMissesEverything) {
  const EmbreeAccelerator embree(std::span<const Triangle>{});
  EXPECT_FALSE(embree.closest_hit(Ray({0, 0, 0}, {0, 0, 1}), {}).valid());
  EXPECT_FALSE(embree.any_hit(Ray({0, 0, 0}, {0, 0, 1}), {}));
}

TEST(Embree, QualityAndRobustOptionsGiveTheSameHits) {
  const std::vector<Triangle> tris = random_soup(500, 5);
  const std::vector<Ray> rays = random_rays(500, 6);
  const EmbreeAccelerator medium(tris);
  for (EmbreeQuality quality : {EmbreeQuality::low, EmbreeQuality::high}) {
    const EmbreeAccelerator other(tris, EmbreeOptions{.quality = quality, .robust = true, .threads = 1});
    for (const Ray& r : rays) {
      const Hit a = medium.closest_hit(r, {}), b = other.closest_hit(r, {});
      ASSERT_EQ(a.valid(), b.valid());
      if (a.valid()) {
        EXPECT_TRUE(same_t(a.t, b.t));
      }
    }
  }
}

TEST(Embree, PinnedIsaGivesTheSameHitsAsItsOwnChoice) {
  // isa=sse2 (every x86-64 CPU has it) and, where the CPU has them, avx2 and
  // avx512: the same hits as Embree's own choice of kernels (t may differ in
  // its last bits: the wider kernels contract to FMA).
  const std::vector<Triangle> tris = random_soup(500, 7);
  const std::vector<Ray> rays = random_rays(2000, 8);
  const EmbreeAccelerator own(tris);
  std::vector<EmbreeIsa> isas = {EmbreeIsa::sse2};
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
  if (__builtin_cpu_supports("avx2")) isas.push_back(EmbreeIsa::avx2);
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl")) isas.push_back(EmbreeIsa::avx512);
#endif
  for (EmbreeIsa isa : isas) {
    SCOPED_TRACE(std::string(embree_isa_name(isa)));
    const EmbreeAccelerator pinned(tris, EmbreeOptions{.threads = 1, .isa = isa});
    int hits = 0;
    for (const Ray& r : rays) {
      const Hit a = own.closest_hit(r, {}), b = pinned.closest_hit(r, {});
      ASSERT_EQ(a.valid(), b.valid());
      EXPECT_EQ(own.any_hit(r, {}), pinned.any_hit(r, {}));
      if (!a.valid()) continue;
      ++hits;
      EXPECT_EQ(a.prim, b.prim);
      EXPECT_TRUE(same_t(a.t, b.t));
    }
    EXPECT_GT(hits, 100);
  }
}

TEST(Embree, IsaTheCpuLacksIsRefusedWithOneLine) {
  // Every ISA either builds (the CPU has it) or is refused before Embree
  // could run an instruction the CPU lacks, with a one-line message.
  const std::vector<Triangle> tris = random_soup(50, 9);
  for (EmbreeIsa isa : {EmbreeIsa::sse2, EmbreeIsa::sse42, EmbreeIsa::avx, EmbreeIsa::avx2, EmbreeIsa::avx512}) {
    SCOPED_TRACE(std::string(embree_isa_name(isa)));
    if (embree_cpu_has(isa)) {
      EXPECT_NO_THROW(EmbreeAccelerator(tris, EmbreeOptions{.threads = 1, .isa = isa}));
    } else {
      try {
        const EmbreeAccelerator refused(tris, EmbreeOptions{.threads = 1, .isa = isa});
        ADD_FAILURE() << "built on a CPU without the ISA";
      } catch (const std::runtime_error& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("lacks that instruction set"), std::string::npos) << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
      }
    }
  }
}

TEST(Embree, IsaNamesRoundTrip) {
  for (EmbreeIsa isa :
       {EmbreeIsa::automatic, EmbreeIsa::sse2, EmbreeIsa::sse42, EmbreeIsa::avx, EmbreeIsa::avx2, EmbreeIsa::avx512})
    EXPECT_EQ(parse_embree_isa(embree_isa_name(isa)), isa);
  EXPECT_EQ(embree_isa_name(EmbreeIsa::automatic), "auto");
  EXPECT_FALSE(parse_embree_isa("avx3").has_value());
  EXPECT_FALSE(parse_embree_isa("").has_value());
}

TEST(Embree, BinaryBvhSahOfOneTriangleIsOneIntersection) {
  const std::vector<Triangle> one = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  const EmbreeBvhFigures fig = embree_binary_bvh_sah(one, 1.0f, 2.5f, 1);
  EXPECT_DOUBLE_EQ(fig.sah_cost, 2.5);  // a root leaf with one primitive: C_isect · 1 · A/A
  EXPECT_EQ(fig.node_count, 1u);
  EXPECT_EQ(fig.leaf_count, 1u);
}

TEST(Embree, BinaryBvhSahOfTwoFarTrianglesSplits) {
  // Two unit triangles far apart: splitting is far cheaper than one leaf of 2,
  // so with min_leaf 1 the tree is a root and two leaves, and the SAH follows
  // from the boxes: C_trav + C_isect·(A(b0) + A(b1)) / A(root).
  const std::vector<Triangle> two = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 1}}, {{10, 0, 0}, {11, 0, 0}, {10, 1, 1}}};
  const EmbreeBvhFigures fig = embree_binary_bvh_sah(two, 1.0f, 1.0f, 1, /*min_leaf=*/1, /*max_leaf=*/4);
  EXPECT_EQ(fig.node_count, 3u);
  EXPECT_EQ(fig.leaf_count, 2u);
  EXPECT_EQ(fig.max_depth, 1u);
  const double a_leaf = 2.0 * (1 * 1 + 1 * 1 + 1 * 1);
  const double a_root = 2.0 * (11 * 1 + 1 * 1 + 1 * 11);
  EXPECT_NEAR(fig.sah_cost, 1.0 + 2.0 * a_leaf / a_root, 1e-9);
}

TEST(Embree, BinaryBvhOfSoupIsAFullBinaryTree) {
  const std::vector<Triangle> tris = random_soup(5000, 21);
  const EmbreeBvhFigures fig = embree_binary_bvh_sah(tris, 1.0f, 1.0f, 2);
  EXPECT_EQ(fig.node_count, 2 * fig.leaf_count - 1);
  // Leaves hold between 1 and 16 primitives, so there are at least N/16 of them.
  EXPECT_GE(fig.leaf_count, tris.size() / 16);
  // A real hierarchy: far cheaper than testing everything, dearer than one test.
  EXPECT_GT(fig.sah_cost, 1.0);
  EXPECT_LT(fig.sah_cost, 0.05 * static_cast<double>(tris.size()));
  EXPECT_THROW(embree_binary_bvh_sah(tris, 1.0f, 1.0f, 1, 4, 64), std::invalid_argument);
}

#else

TEST(Embree, NotBuilt) {
  GTEST_SKIP() << "built without ACCELVIZ_WITH_EMBREE";
}

#endif
}  // namespace unity_test_embree
