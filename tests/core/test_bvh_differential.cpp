// Differential test: the BVH must answer exactly as brute force.
//
// For every splitter and several option sets (B = 2, 16, 256; leaf sizes 1,
// 4, 16; ordered and unordered traversal; watertight and Moller-Trumbore;
// the 4-wide fast path and the binary one)
// closest_hit must return the same primitive as BruteForce, or, where two
// primitives tie, a hit at the same distance (|t - t_ref| <= 1e-6·max(1,|t|));
// any_hit must equal closest.valid(). Rays are seeded and adversarial:
// origins inside and outside the scene box, uniform directions, axis-aligned
// directions with +0/-0 components (some lying in box face planes), rays
// aimed exactly at vertices and at points on edges, rays leaving a surface,
// and [tmin, tmax] segments. The packet queries (eight rays walked together)
// must answer each ray as its single-ray query does, on the same rays. Scenes: a random soup, a shared-edge height
// field, a closed box around a soup, and degenerate sets (identical,
// concentric, zero-area and coplanar triangles).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "core/accel/brute_force.h"
#include "core/accel/bvh/bvh.h"
#include "tests/core/mt_random.h"
#include "tests/support/reference_referee.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_bvh_differential {

using namespace accelviz;

namespace {

using test_random::random_direction;
using test_random::uniform;

std::vector<Triangle> soup(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<Triangle> tris(n);
  for (Triangle& t : tris) {
    const glm::vec3 c{uniform(rng), uniform(rng), uniform(rng)};
    const float s1 = uniform(rng);
    const float s = 0.02f + 0.2f * s1 * uniform(rng);
    t = {c + s * random_direction(rng), c + s * random_direction(rng), c + s * random_direction(rng)};
  }
  return tris;
}

/// Height field: every interior edge and vertex is shared, so rays through
/// them test watertightness and the padding of the box test.
std::vector<Triangle> height_field(int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<float> h((n + 1) * (n + 1));
  for (float& v : h) v = 0.1f * uniform(rng);
  const auto p = [&](int i, int j) {
    return glm::vec3(static_cast<float>(i) / static_cast<float>(n), h[j * (n + 1) + i],
                     static_cast<float>(j) / static_cast<float>(n));
  };
  std::vector<Triangle> tris;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      tris.push_back({p(i, j), p(i + 1, j), p(i + 1, j + 1)});
      tris.push_back({p(i, j), p(i + 1, j + 1), p(i, j + 1)});
    }
  return tris;
}

/// A closed box (12 triangles) around a soup: rays from inside always hit.
std::vector<Triangle> closed_box_with_soup(std::uint32_t seed) {
  std::vector<Triangle> tris = soup(200, seed);
  const glm::vec3 lo(-0.5f), hi(1.5f);
  const auto corner = [&](int i) { return glm::vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z); };
  const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  for (const auto& f : faces) {
    tris.push_back({corner(f[0]), corner(f[1]), corner(f[2])});
    tris.push_back({corner(f[0]), corner(f[2]), corner(f[3])});
  }
  return tris;
}

/// Degenerate company: identical copies, concentric triangles (one centroid),
/// zero-area slivers and points, and a coplanar sheet.
std::vector<Triangle> degenerate_mix(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<Triangle> tris;
  for (int i = 0; i < 40; ++i) tris.push_back({{0.2f, 0.2f, 0.2f}, {0.4f, 0.2f, 0.2f}, {0.2f, 0.4f, 0.25f}});
  for (int i = 1; i <= 40; ++i) {
    const float s = 0.005f * static_cast<float>(i);
    tris.push_back({{0.7f - s, 0.7f - s, 0.5f}, {0.7f + 2 * s, 0.7f - s, 0.5f}, {0.7f - s, 0.7f + 2 * s, 0.5f}});
  }
  for (int i = 0; i < 40; ++i) {
    const glm::vec3 a{uniform(rng), uniform(rng), uniform(rng)};
    const glm::vec3 b{uniform(rng), uniform(rng), uniform(rng)};
    tris.push_back({a, b, 0.5f * (a + b)});  // collinear: zero area
    tris.push_back({a, a, a});               // a point
  }
  for (int i = 0; i < 80; ++i) {
    const float x = uniform(rng), y = uniform(rng);
    tris.push_back({{x, y, 0.9f}, {x + 0.1f, y, 0.9f}, {x, y + 0.1f, 0.9f}});  // coplanar, overlapping
  }
  return tris;
}

std::vector<Ray> adversarial_rays(std::span<const Triangle> tris, std::size_t count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  Aabb box;
  for (const Triangle& t : tris) box.extend(t.bounds());
  const glm::vec3 c = box.center();
  const float radius = 0.5f * glm::length(box.extent()) + 1e-3f;
  const auto inside = [&] {
    const glm::vec3 e = box.extent() * 1.2f;
    return c + (glm::vec3{uniform(rng), uniform(rng), uniform(rng)} - 0.5f) * e;
  };
  const auto outside = [&] { return c + 2.0f * radius * random_direction(rng); };
  const auto vertex = [&] {
    const Triangle& t = tris[rng() % tris.size()];
    const int k = static_cast<int>(rng() % 3);
    return k == 0 ? t.v0 : k == 1 ? t.v1 : t.v2;
  };
  const auto signed_zero = [&] { return (rng() & 1) ? 0.0f : -0.0f; };

  std::vector<Ray> rays;
  rays.reserve(count);
  while (rays.size() < count) {
    const int kind = static_cast<int>(rng() % 8);
    const glm::vec3 o = (rng() & 1) ? inside() : outside();
    switch (kind) {
      case 0:  // uniform direction
        rays.emplace_back(o, random_direction(rng));
        break;
      case 1:  // from outside toward a point of the scene box
        rays.emplace_back(outside(), glm::normalize(inside() - o + 1e-6f));
        break;
      case 2: {  // axis-aligned with signed zeros; half of them in a vertex's planes
        glm::vec3 d(signed_zero(), signed_zero(), signed_zero());
        const int axis = static_cast<int>(rng() % 3);
        d[axis] = (rng() & 1) ? 1.0f : -1.0f;
        glm::vec3 org = inside();
        if (rng() & 1) {
          const glm::vec3 v = vertex();
          for (int a = 0; a < 3; ++a)
            if (a != axis) org[a] = v[a];
        }
        rays.emplace_back(org, d);
        break;
      }
      case 3:  // exactly toward a vertex (direction not normalised: t = 1 at the vertex)
        rays.emplace_back(o, vertex() - o);
        break;
      case 4: {  // toward a point on an edge
        const Triangle& t = tris[rng() % tris.size()];
        const float s = uniform(rng);
        const glm::vec3 target = (rng() & 1) ? t.v0 + s * (t.v1 - t.v0) : t.v1 + s * (t.v2 - t.v1);
        rays.emplace_back(o, target - o);
        break;
      }
      case 5: {  // leaving a surface (shadow / secondary ray without offset)
        const Triangle& t = tris[rng() % tris.size()];
        float u = uniform(rng), v = uniform(rng);
        if (u + v > 1) u = 1 - u, v = 1 - v;
        rays.emplace_back(t.v0 + u * (t.v1 - t.v0) + v * (t.v2 - t.v0), random_direction(rng));
        break;
      }
      case 6: {  // a segment [tmin, tmax] of a uniform ray
        const float t0 = uniform(rng) * 2.0f * radius;
        const float t1 = t0 + uniform(rng) * 2.0f * radius;
        rays.emplace_back(o, random_direction(rng), t0, t1);
        break;
      }
      default: {  // a segment ending exactly at a vertex, or starting past it
        const glm::vec3 d = vertex() - o;
        rays.push_back(Ray{o, d, (rng() & 1) ? 0.0f : 1.0f, (rng() & 1) ? 1.0f : kInfinity});
        break;
      }
    }
  }
  return rays;
}

std::vector<BvhOptions> option_sets() {
  std::vector<BvhOptions> v;
  for (int leaf : {1, 4, 16}) {
    BvhOptions o;
    o.compute_epo = false;
    o.threads = 1;
    o.max_leaf_size = leaf;
    o.leaf_size_cap = std::max(leaf, 16);
    // Leaf 4: the 4-wide SSE fast path; otherwise the default (8-wide AVX2
    // where this CPU has AVX2, else 4-wide).
    o.wide_width = leaf == 4 ? 4 : 0;
    // Leaves 1 and 4: merged wide leaf slots (BvhOptions::wide_merge_blocks;
    // these small scenes would not merge by default); 16: the default.
    o.wide_merge_blocks = leaf == 16 ? -1 : 2;
    for (int b : {2, 16, 256}) {
      o.splitter = BvhSplitter::binned_sah;
      o.buckets = b;
      v.push_back(o);
    }
    o.splitter = BvhSplitter::exact_sah;
    v.push_back(o);
    o.splitter = BvhSplitter::median;
    v.push_back(o);
    o.splitter = BvhSplitter::lbvh;
    v.push_back(o);
  }
  // The binary fast path too (the default walks the 4-wide copy).
  for (BvhSplitter s : {BvhSplitter::binned_sah, BvhSplitter::exact_sah, BvhSplitter::median}) {
    BvhOptions o;
    o.compute_epo = false;
    o.threads = 1;
    o.splitter = s;
    o.wide_traversal = false;
    v.push_back(o);
  }
  return v;
}

struct Tally {
  std::size_t closest = 0, any = 0, mismatches = 0, spurious_reference = 0;
  std::size_t packet_rays = 0, packet_mismatches = 0;
};

/// The packet queries (eight rays at a time, here in the adversarial set's
/// random order: mixed direction signs, idle lanes) against the per-ray fast
/// path: the same hit bit for bit, or, where the packet reached another
/// triangle, one within the brute-force comparison's tolerance of the same t;
/// any hit as closest.valid(). Why another triangle can be found: packets
/// visit leaves in another order, and which of two hits a few ulps apart
/// wins depends on the order (the watertight test compares T against
/// tmax·det, not t against tmax; a Moller-Trumbore hit near a vertex can lie
/// just outside its triangle's box, which a closer hit found first culls),
/// as the brute-force comparison allows for every structure. Under
/// Moller-Trumbore a difference is a rounding decision when the double
/// reference judges both answers a match or a tie (see check_scene).
void check_packets(const std::string& what, std::span<const Triangle> tris, const Bvh& bvh, std::span<const Ray> rays,
                   const QueryOptions& q, Tally& tally) {
  std::vector<Hit> packet(rays.size());
  std::vector<std::uint8_t> occluded(rays.size());
  bvh.closest_hits_packets(rays, packet, q);
  bvh.any_hits_packets(rays, occluded, q);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Hit single = bvh.closest_hit(rays[i], q);
    const Hit& p = packet[i];
    ++tally.packet_rays;
    bool ok = p.valid() == single.valid() && (occluded[i] != 0) == single.valid();
    if (ok && single.valid())
      ok = p.prim == single.prim ? p.t == single.t && p.u == single.u && p.v == single.v && p.ng == single.ng
                                 : std::fabs(p.t - single.t) <= 1e-6f * std::max(1.0f, std::fabs(single.t));
    if (!ok && q.triangle_test == TriangleTest::moller_trumbore) {
      const test_referee::Referee referee(tris, rays[i]);
      if (referee.accepts(p, occluded[i] != 0) && referee.accepts(single, single.valid())) {
        ++tally.spurious_reference;
        continue;
      }
    }
    if (!ok && ++tally.packet_mismatches <= 10)
      ADD_FAILURE() << what << " packets: ray " << i << ": packet prim " << p.prim << " t " << p.t << " occluded "
                    << int(occluded[i]) << ", single prim " << single.prim << " t " << single.t;
  }
}

/// Checks one scene; returns the number of rays compared.
void check_scene(const std::string& name, std::span<const Triangle> tris, std::size_t ray_count, std::uint32_t seed,
                 Tally& tally) {
  const std::vector<Ray> rays = adversarial_rays(tris, ray_count, seed);
  const BruteForce bf(tris);
  for (TriangleTest test : {TriangleTest::watertight, TriangleTest::moller_trumbore}) {
    QueryOptions q;
    q.triangle_test = test;
    std::vector<Hit> ref(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) ref[i] = bf.closest_hit(rays[i], q);
    for (const BvhOptions& o : option_sets()) {
      const Bvh bvh(tris, o);
      for (bool ordered : {true, false}) {
        q.ordered = ordered;
        for (std::size_t i = 0; i < rays.size(); ++i) {
          const Hit h = bvh.closest_hit(rays[i], q);
          const bool any = bvh.any_hit(rays[i], q);
          ++tally.closest;
          ++tally.any;
          const Hit& r = ref[i];
          bool ok = h.valid() == r.valid() && any == r.valid();
          if (ok && r.valid()) {
            if (h.prim == r.prim)
              ok = h.t == r.t && h.u == r.u && h.v == r.v;
            else
              ok = std::fabs(h.t - r.t) <= 1e-6f * std::max(1.0f, std::fabs(r.t));
          }
          // Moller-Trumbore has no guard for zero-area triangles (rounding can
          // give det != 0 and a "hit" at a point that is not on the triangle,
          // nor in its box, which the BVH rightly never reaches), and where a
          // ray grazes a triangle at a vertex its t can be off by more than
          // 1e-6, placing the hit outside the triangle's box. Where the double
          // reference judges the BVH's answers a match or a tie, the brute
          // force's hit is not a hit to reproduce.
          if (!ok && test == TriangleTest::moller_trumbore && test_referee::reference_accepts(tris, rays[i], h, any)) {
            ++tally.spurious_reference;
            continue;
          }
          if (!ok && ++tally.mismatches <= 10) {
            const Ray& ray = rays[i];
            ADD_FAILURE() << name << " " << to_string(o.splitter) << " B=" << o.buckets << " leaf=" << o.max_leaf_size
                          << (o.wide_traversal ? " wide" : " binary") << (ordered ? " ordered" : " unordered")
                          << (test == TriangleTest::watertight ? " watertight" : " MT") << " ray " << i << " o=("
                          << ray.origin.x << "," << ray.origin.y << "," << ray.origin.z << ") d=(" << ray.direction.x
                          << "," << ray.direction.y << "," << ray.direction.z << ") [" << ray.tmin << "," << ray.tmax
                          << "]: bvh prim " << h.prim << " t " << h.t << " any " << any << ", brute prim " << r.prim
                          << " t " << r.t;
          }
        }
        check_packets(name + " " + to_string(o.splitter) + " leaf=" + std::to_string(o.max_leaf_size) +
                          (ordered ? " ordered" : " unordered") +
                          (test == TriangleTest::watertight ? " watertight" : " MT"),
                      tris, bvh, rays, q, tally);
      }
    }
  }
}

}  // namespace

TEST(BvhDifferential, MatchesBruteForceOnAdversarialRays) {
  Tally tally;
  check_scene("soup", soup(400, 1), 2500, 101, tally);
  check_scene("height-field", height_field(14, 2), 2500, 102, tally);
  check_scene("closed-box", closed_box_with_soup(3), 2500, 103, tally);
  check_scene("degenerate", degenerate_mix(4), 2500, 104, tally);
  EXPECT_EQ(tally.mismatches, 0u);
  EXPECT_EQ(tally.packet_mismatches, 0u);
  std::printf(
      "compared %zu closest-hit and %zu any-hit queries against brute force (%zu Moller-Trumbore differences the "
      "double reference judged rounding); "
      "%zu packet queries against single rays\n",
      tally.closest, tally.any, tally.spurious_reference, tally.packet_rays);
  EXPECT_EQ(tally.packet_rays, tally.closest);
  EXPECT_LT(tally.spurious_reference, tally.closest / 1000);
  RecordProperty("closest_hit_queries", static_cast<int>(tally.closest));
  EXPECT_GE(tally.closest, 300000u);
}

TEST(BvhDifferential, MatchesBruteForceOnALargerSoupWithThreadedBuild) {
  // A larger scene built with several threads (the node array equals the
  // single-threaded one; this checks the answers too).
  const std::vector<Triangle> tris = soup(10000, 9);
  const std::vector<Ray> rays = adversarial_rays(tris, 1500, 109);
  const BruteForce bf(tris);
  BvhOptions o;
  o.threads = 4;
  o.compute_epo = false;
  const Bvh bvh(tris, o);
  std::size_t bad = 0;
  for (const Ray& ray : rays) {
    const Hit r = bf.closest_hit(ray, {});
    const Hit h = bvh.closest_hit(ray, {});
    const bool same = h.valid() == r.valid() && (!r.valid() || h.prim == r.prim ||
                                                 std::fabs(h.t - r.t) <= 1e-6f * std::max(1.0f, std::fabs(r.t)));
    if (!same || bvh.any_hit(ray, {}) != r.valid()) ++bad;
  }
  EXPECT_EQ(bad, 0u);
}

TEST(BvhDifferential, StatisticsPathAnswersAsTheFastPath) {
  // The counting traversal tests boxes against the segment end and classifies
  // culling itself; it must take the same decisions as the binary fast path.
  const std::vector<Triangle> tris = soup(1000, 5);
  const std::vector<Ray> rays = adversarial_rays(tris, 3000, 105);
  for (const BvhOptions& o : option_sets()) {
    const Bvh bvh(tris, o);
    BvhOptions binary_options = o;
    binary_options.wide_traversal = false;
    const Bvh binary(tris, binary_options);
    for (bool ordered : {true, false}) {
      QueryOptions q;
      q.ordered = ordered;
      for (const Ray& ray : rays) {
        RayStats st;
        VisitTrace trace;
        const Hit fast = binary.closest_hit(ray, q);
        const Hit counted = bvh.closest_hit(ray, q, &st, &trace);
        ASSERT_EQ(fast.prim, counted.prim);
        ASSERT_EQ(fast.t, counted.t);
        // The wide fast path finds the same hit (a tie could pick the other
        // triangle at the same t; this soup has none).
        const Hit wide = bvh.closest_hit(ray, q);
        ASSERT_EQ(wide.prim, counted.prim);
        ASSERT_EQ(wide.t, counted.t);
        RayStats any_st;
        ASSERT_EQ(bvh.any_hit(ray, q), bvh.any_hit(ray, q, &any_st));
      }
    }
  }
}
}  // namespace unity_test_bvh_differential
