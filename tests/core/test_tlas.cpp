// Two-level structure (core/accel/tlas/): closest hits equal the flattened
// single BVH's on >= 1,000,000 rays over instances that are rotated,
// non-uniformly scaled, mirrored (negative determinant) and nearly singular
// (a 1e-4 squash); each unique mesh becomes one BLAS; world primitive and
// instance ids, normals and the dynamic updates (rigid motion, BLAS refit
// vs rebuild) all agree with a fresh flattened build.
//
// Ray count: ACCELVIZ_TLAS_RAYS, else 1,000,000 scaled by ACCELVIZ_VERIFY_SCALE
// (tests/support/test_scale.h: 50,000 in the sanitizer run, 250,000 in the
// scalar-path run; the release CI run does the full million); the other
// differential tests use 1/50 or 1/20 of it (at least 2,000 / 5,000).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <mutex>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "core/accel/bvh/bvh.h"
#include "core/accel/factory.h"
#include "core/accel/tlas/tlas.h"
#include "core/scene/load.h"
#include "core/util/parallel.h"
#include "tests/support/test_scale.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_tlas {

using namespace accelviz;

namespace {

// A million rays at full size (Release), scaled by ACCELVIZ_VERIFY_SCALE
// (tests/support/test_scale.h); ACCELVIZ_TLAS_RAYS sets the count outright.
std::size_t ray_count() {
  if (const char* v = std::getenv("ACCELVIZ_TLAS_RAYS")) return static_cast<std::size_t>(std::strtoull(v, nullptr, 10));
  return test_scale::scaled(1'000'000, 20'000);
}

/// The flattened scene's BVH, the reference of the comparisons. Without the EPO measurement, a
/// pass over the tree per triangle that no test here reads: it was most of the million-ray test's
/// time under the sanitizers.
Bvh flat_bvh(std::span<const Triangle> triangles) {
  return Bvh(triangles, BvhOptions{.compute_epo = false});
}

glm::mat4 trs(const glm::vec3& t, float angle, const glm::vec3& axis, const glm::vec3& s) {
  glm::mat4 m = glm::translate(glm::mat4(1.0f), t);
  m = glm::rotate(m, angle, glm::normalize(axis));
  return glm::scale(m, s);
}

/// The named robustness cases: one instance each, plus a crowd of ordinary ones.
struct NamedTransform {
  const char* name;
  glm::mat4 m;
};
std::vector<NamedTransform> robustness_transforms() {
  return {
      {"identity", glm::mat4(1.0f)},
      {"rotated", trs({6, 0, 0}, 0.9f, {1, 2, 3}, {1, 1, 1})},
      {"non-uniform scale", trs({0, 6, 0}, 0.4f, {0, 1, 0}, {3.0f, 0.5f, 1.5f})},
      {"mirrored x", trs({-6, 0, 0}, 0.0f, {0, 1, 0}, {-1, 1, 1})},
      {"mirrored and rotated, non-uniform", trs({0, -6, 0}, 2.1f, {1, 0, 1}, {-2.0f, 0.7f, 1.3f})},
      {"nearly singular (1e-4 squash)", trs({0, 0, 6}, 0.7f, {1, 1, 0}, {1.0f, 1e-4f, 1.0f})},
      {"tiny (1e-3) far away", trs({40, 40, 40}, 0.3f, {0, 0, 1}, {1e-3f, 1e-3f, 1e-3f})},
      {"huge (1e3)", trs({0, 0, -4000}, 0.2f, {1, 0, 0}, {1e3f, 1e3f, 1e3f})},
      {"shear",
       glm::mat4(glm::vec4(1, 0, 0, 0), glm::vec4(0.8f, 1, 0, 0), glm::vec4(0, 0.5f, 1, 0), glm::vec4(-12, 3, 2, 1))},
  };
}

/// Two meshes (teapot, terrain patch), the robustness instances of the
/// teapot, and a crowd of random rigid + scaled instances of both.
Scene make_instanced_scene(int crowd, std::uint64_t seed) {
  Scene s;
  Scene teapot = make_builtin("teapot?size=2000");
  Scene terrain = make_builtin("terrain?size=2000&seed=3");
  s.meshes.push_back(teapot.meshes.at(0));
  s.meshes.push_back(terrain.meshes.at(0));
  Mesh unused;  // a mesh no instance references: no BLAS for it
  unused.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  unused.indices = {{0, 1, 2}};
  s.meshes.push_back(unused);
  auto add = [&](std::uint32_t mesh, const glm::mat4& m) {
    Node n;
    n.mesh = static_cast<int>(mesh);
    n.local = m;
    s.nodes.push_back(n);
    s.roots.push_back(static_cast<int>(s.nodes.size()) - 1);
    Instance inst;
    inst.mesh = mesh;
    inst.node = static_cast<std::uint32_t>(s.nodes.size() - 1);
    inst.transform = m;
    s.instances.push_back(inst);
  };
  for (const NamedTransform& nt : robustness_transforms()) add(0, nt.m);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < crowd; ++i) {
    const glm::vec3 t{20.0f * u(rng), 20.0f * u(rng), 20.0f * u(rng)};
    const glm::vec3 axis{u(rng), u(rng), u(rng) + 1.5f};
    const float sc = 0.5f + 0.5f * (u(rng) + 1.0f);
    const glm::vec3 s3{sc * (u(rng) < 0.0f ? -1.0f : 1.0f), sc * (1.0f + 0.5f * u(rng)), sc};
    add(i % 3 == 0 ? 1u : 0u, trs(t, 3.0f * u(rng), axis, s3));
  }
  s.flatten();
  return s;
}

/// Rays: half aimed at an interior point of a random world triangle from a
/// random origin around the scene, half random origin and direction.
std::vector<Ray> make_rays(const Scene& s, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const Aabb b = s.bounds();
  const glm::vec3 c = b.center(), e = b.extent();
  std::vector<Ray> rays;
  rays.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 o = c + (glm::vec3{u(rng), u(rng), u(rng)} - 0.5f) * e * 1.2f;
    glm::vec3 d;
    if (i % 2 == 0) {
      const Triangle& t = s.triangles[rng() % s.triangles.size()];
      float a = 0.1f + 0.8f * u(rng), bb = 0.1f + 0.8f * u(rng);
      if (a + bb > 0.9f) {
        a = 0.9f - a * 0.5f;
        bb = 0.9f - a;
      }
      d = (t.v0 + a * (t.v1 - t.v0) + bb * (t.v2 - t.v0)) - o;
    } else {
      d = glm::vec3{u(rng), u(rng), u(rng)} * 2.0f - 1.0f;
    }
    if (glm::length(d) == 0.0f) d = glm::vec3(0, 0, 1);
    rays.emplace_back(o, d);
  }
  return rays;
}

/// World-space distance from where RAY meets the plane of TRI to the
/// triangle's boundary, in double (0 when the ray is parallel to the plane).
double edge_distance(const Ray& ray, const Triangle& tri) {
  const glm::dvec3 o(ray.origin), d(ray.direction), a(tri.v0), b(tri.v1), c(tri.v2);
  const glm::dvec3 n = glm::cross(b - a, c - a);
  const double dn = glm::dot(d, n);
  if (dn == 0.0) return 0.0;
  const glm::dvec3 p = o + d * (glm::dot(a - o, n) / dn);
  const auto seg = [&](const glm::dvec3& x, const glm::dvec3& y) {
    const glm::dvec3 e = y - x;
    const double l2 = glm::dot(e, e);
    const double t = l2 > 0.0 ? std::clamp(glm::dot(p - x, e) / l2, 0.0, 1.0) : 0.0;
    return glm::length(p - (x + t * e));
  };
  return std::min({seg(a, b), seg(b, c), seg(c, a)});
}

/// World-space distance between the ray's line and the triangle's edges (a
/// grazing ray passes close to an edge far from where it meets the plane).
double line_edge_distance(const Ray& ray, const Triangle& tri) {
  const glm::dvec3 o(ray.origin), d = glm::normalize(glm::dvec3(ray.direction));
  const auto seg = [&](const glm::dvec3& x, const glm::dvec3& y) {
    // Closest point of segment xy to the line: minimise over s in [0, 1] by sampling the
    // analytic optimum, clamped.
    const glm::dvec3 e = y - x, w = x - o;
    const double ee = glm::dot(e, e), ed = glm::dot(e, d);
    const double denom = ee - ed * ed;
    double sp = denom > 0.0 ? (ed * glm::dot(w, d) - glm::dot(w, e)) / denom : 0.0;
    sp = std::clamp(sp, 0.0, 1.0);
    const glm::dvec3 q = x + sp * e - o;
    return glm::length(q - glm::dot(q, d) * d);
  };
  const glm::dvec3 a(tri.v0), b(tri.v1), c(tri.v2);
  return std::min({seg(a, b), seg(b, c), seg(c, a)});
}

/// Rounding scale of world coordinates near the hit: float vertices of the
/// flattened list are rounded to ~2^-23 of their magnitude, and the ray is
/// rounded again on its way into object space, so hits of the two
/// structures may differ by a few ulps of the coordinates (whatever the size
/// of the mesh: a tiny instance far from the origin, or a ray from far
/// away, is where this shows).
double world_tolerance(const Ray& ray, float t, const Triangle& tri) {
  const glm::dvec3 p = glm::dvec3(ray.origin) + glm::dvec3(ray.direction) * static_cast<double>(t);
  // The ray's own magnitudes count too: carrying a far origin into object
  // space rounds it at its own scale.
  const glm::dvec3 o(ray.origin);
  const double travel = std::abs(static_cast<double>(t)) * glm::length(glm::dvec3(ray.direction));
  double m = std::max(
      {std::abs(p.x), std::abs(p.y), std::abs(p.z), std::abs(o.x), std::abs(o.y), std::abs(o.z), travel, 1e-3});
  for (const glm::vec3& v : {tri.v0, tri.v1, tri.v2})
    m = std::max({m, (double)std::abs(v.x), (double)std::abs(v.y), (double)std::abs(v.z)});
  return 64.0 * m * 0x1.0p-23;
}

/// |cos| of the angle between the ray and the triangle's normal (at least
/// 1e-3): a position error e across the surface moves the hit by e / |cos|
/// along the ray, so t differences are compared after multiplying by it.
double obliquity(const Ray& ray, const Triangle& tri) {
  const glm::dvec3 n = glm::cross(glm::dvec3(tri.v1) - glm::dvec3(tri.v0), glm::dvec3(tri.v2) - glm::dvec3(tri.v0));
  const double ln = glm::length(n), ld = glm::length(glm::dvec3(ray.direction));
  if (ln == 0.0 || ld == 0.0) return 1e-3;
  return std::max(1e-3, std::abs(glm::dot(n, glm::dvec3(ray.direction))) / (ln * ld));
}

struct Comparison {
  std::atomic<std::uint64_t> same{0}, near_ties{0}, unexplained{0}, wrong_instance{0}, bad_normal{0}, hits{0};
  std::mutex mutex;
  std::vector<std::string> examples;
  void example(std::size_t i, const Hit& f, const Hit& t) {
    std::lock_guard<std::mutex> lock(mutex);
    if (examples.size() < 5)
      examples.push_back("ray " + std::to_string(i) + ": flat prim " + std::to_string(f.prim) + " t " +
                         std::to_string(f.t) + ", tlas prim " + std::to_string(t.prim) + " t " + std::to_string(t.t));
  }
  std::string report() const {
    std::string s;
    for (const std::string& e : examples) s += e + "\n";
    return s;
  }
};

/// Closest hits of A and B on RAYS: equal, or a near tie within the rounding
/// of world coordinates (a t tie, or a ray within that distance of an edge
/// of the triangle one of them hit).
void compare(const Scene& s, const Accelerator& flat, const Accelerator& two, const std::vector<Ray>& rays,
             Comparison& out) {
  const QueryOptions qo;
  parallel_for(rays.size(), 0, 4096, [&](std::size_t b, std::size_t e, unsigned) {
    for (std::size_t i = b; i < e; ++i) {
      const Ray& r = rays[i];
      const Hit f = flat.closest_hit(r, qo);
      const Hit t = two.closest_hit(r, qo);
      if (f.valid()) out.hits.fetch_add(1, std::memory_order_relaxed);
      const double dlen = glm::length(glm::dvec3(r.direction));
      if (f.prim == t.prim) {
        if (!f.valid()) {
          out.same.fetch_add(1, std::memory_order_relaxed);
          continue;
        }
        const double tol = world_tolerance(r, f.t, s.triangles[f.prim]);
        if (std::abs(static_cast<double>(f.t) - t.t) * dlen * obliquity(r, s.triangles[f.prim]) > tol) {
          out.unexplained.fetch_add(1, std::memory_order_relaxed);
          out.example(i, f, t);
          continue;
        }
        out.same.fetch_add(1, std::memory_order_relaxed);
        const Instance& inst = s.instances.at(t.instance);
        if (t.prim < inst.first_triangle || t.prim >= inst.first_triangle + inst.triangle_count)
          out.wrong_instance.fetch_add(1, std::memory_order_relaxed);
        // Normals agree unless the world triangle is so thin that its float
        // normal is itself mostly rounding.
        const Triangle& tri = s.triangles[f.prim];
        const double area2 =
            glm::length(glm::cross(glm::dvec3(tri.v1) - glm::dvec3(tri.v0), glm::dvec3(tri.v2) - glm::dvec3(tri.v0)));
        const double tol_w = world_tolerance(r, f.t, tri);
        const double longest =
            std::max({glm::length(tri.v1 - tri.v0), glm::length(tri.v2 - tri.v1), glm::length(tri.v0 - tri.v2)});
        if (glm::dot(f.ng, t.ng) < 0.99f && area2 > 1e3 * tol_w * longest)
          out.bad_normal.fetch_add(1, std::memory_order_relaxed);
        continue;
      }
      bool tie = false;
      if (f.valid() && t.valid()) {
        const double tol = world_tolerance(r, std::min(f.t, t.t), s.triangles[f.prim]);
        tie = std::abs(static_cast<double>(f.t) - t.t) * dlen * obliquity(r, s.triangles[f.prim]) <= tol;
      }
      for (const Hit* h : {&f, &t})
        if (!tie && h->valid()) {
          const double tol = world_tolerance(r, h->t, s.triangles[h->prim]);
          // Near an edge, or at the origin (the origin on the surface, within rounding).
          tie = edge_distance(r, s.triangles[h->prim]) <= tol || line_edge_distance(r, s.triangles[h->prim]) <= tol ||
                h->t * dlen <= tol;
        }
      (tie ? out.near_ties : out.unexplained).fetch_add(1, std::memory_order_relaxed);
      if (!tie) out.example(i, f, t);
    }
  });
}

}  // namespace

TEST(Tlas, BuildsEachUniqueMeshOnce) {
  const Scene s = make_instanced_scene(60, 1);
  const Tlas tlas(s);
  EXPECT_EQ(tlas.blas_count(), 2u) << "two meshes referenced (the third is not)";
  EXPECT_EQ(tlas.instances().size(), s.instances.size());
  EXPECT_EQ(tlas.blas_of_mesh(2), -1);
  EXPECT_EQ(tlas.instanced_triangles(), s.triangles.size());
  EXPECT_EQ(tlas.blas(tlas.blas_of_mesh(0)).triangle_count(), s.meshes[0].indices.size());
  EXPECT_LT(tlas.memory_two_level(), tlas.memory_flattened_estimate() / 10);
  EXPECT_GT(tlas.build_stats().sah_cost, 0.0);
  for (const TlasInstance& inst : tlas.instances()) {
    EXPECT_FALSE(inst.world_bounds.is_empty());
  }
  const std::vector<NamedTransform> named = robustness_transforms();
  for (std::size_t i = 0; i < named.size(); ++i)
    EXPECT_EQ(tlas.instances()[i].mirrored, glm::determinant(glm::mat3(named[i].m)) < 0.0f) << named[i].name;
}

// The promise: on >= 1,000,000 rays (release CI), the two-level closest hit
// equals the flattened single BVH's (same primitive, t within 1e-4
// relative) except for near ties (a t tie, or a ray within 1e-4 barycentric
// of an edge), which must stay rare.
TEST(Tlas, ClosestHitsEqualFlattenedBvhOnAMillionRays) {
  const Scene s = make_instanced_scene(200, 7);
  const Bvh flat = flat_bvh(s.triangles);
  const Tlas two(s);
  const std::vector<Ray> rays = make_rays(s, ray_count(), 11);
  Comparison c;
  compare(s, flat, two, rays, c);
  RecordProperty("rays", std::to_string(rays.size()));
  RecordProperty("near_ties", std::to_string(c.near_ties.load()));
  EXPECT_EQ(c.unexplained.load(), 0u) << c.report();
  EXPECT_EQ(c.wrong_instance.load(), 0u);
  EXPECT_EQ(c.bad_normal.load(), 0u);
  EXPECT_LE(c.near_ties.load(), rays.size() / 1000) << "near ties should be rare";
  EXPECT_GT(c.hits.load(), rays.size() / 3) << "the rays must mostly hit for the comparison to mean anything";
}

// Each robustness transform alone: rays aimed at its own triangles.
TEST(Tlas, RobustnessCasesEachInstanceAlone) {
  for (const NamedTransform& nt : robustness_transforms()) {
    SCOPED_TRACE(nt.name);
    Scene s;
    s.meshes.push_back(make_builtin("teapot?size=2000").meshes.at(0));
    Node n;
    n.mesh = 0;
    n.local = nt.m;
    s.nodes.push_back(n);
    s.roots.push_back(0);
    Instance inst;
    inst.transform = nt.m;
    s.instances.push_back(inst);
    s.flatten();
    const Bvh flat = flat_bvh(s.triangles);
    const Tlas two(s);
    const std::vector<Ray> rays = make_rays(s, std::max<std::size_t>(2000, ray_count() / 50), 5);
    Comparison c;
    compare(s, flat, two, rays, c);
    EXPECT_EQ(c.unexplained.load(), 0u) << c.report();
    EXPECT_EQ(c.bad_normal.load(), 0u);
    EXPECT_GT(c.hits.load(), rays.size() / 4);
    // any-hit agrees with closest-hit validity where both closest hits agree (not a near tie).
    std::size_t disagree = 0;
    for (std::size_t i = 0; i < 2000; ++i) {
      const Hit f = flat.closest_hit(rays[i], QueryOptions{});
      if (f.prim == two.closest_hit(rays[i], QueryOptions{}).prim)
        disagree += two.any_hit(rays[i], QueryOptions{}) != f.valid();
    }
    EXPECT_EQ(disagree, 0u);
  }
}

TEST(Tlas, StatsCountBothLevels) {
  const Scene s = make_instanced_scene(60, 2);
  const Tlas two(s);
  const std::vector<Ray> rays = make_rays(s, 2000, 3);
  std::uint64_t inst = 0, tlas_nodes = 0, blas_nodes = 0, prims = 0;
  for (const Ray& r : rays) {
    TwoLevelRayStats ts;
    RayStats rs;
    const Hit a = two.closest_hit_two_level(r, QueryOptions{}, &ts);
    const Hit b = two.closest_hit(r, QueryOptions{}, &rs);
    ASSERT_EQ(a.prim, b.prim);
    EXPECT_EQ(rs.nodes_visited, ts.tlas_nodes + ts.blas_nodes);
    EXPECT_EQ(rs.prim_tests, ts.prim_tests);
    if (a.valid()) {
      EXPECT_GE(ts.instances_visited, 1u);
      EXPECT_GE(ts.prim_tests, 1u);
    }
    inst += ts.instances_visited;
    tlas_nodes += ts.tlas_nodes;
    blas_nodes += ts.blas_nodes;
    prims += ts.prim_tests;
  }
  EXPECT_GT(inst, 0u);
  EXPECT_GT(tlas_nodes, inst / 2);
  EXPECT_GT(blas_nodes, 0u);
  EXPECT_GT(prims, 0u);
  // A trace names TLAS nodes and world primitive ids.
  VisitTrace trace;
  const Hit h = two.closest_hit(rays[0], QueryOptions{}, nullptr, &trace);
  bool saw_hit = false;
  for (const VisitStep& st : trace.steps)
    if (st.kind == VisitStep::Kind::prim_hit) {
      EXPECT_LT(st.id, s.triangles.size());
      saw_hit = saw_hit || st.id == h.prim;
    }
  EXPECT_EQ(saw_hit, h.valid());
}

// max_depth and avg_leaf_depth are the two-level tree's as rays walk it: a BLAS root one level below
// the TLAS leaf that holds its instance, each placed BLAS's leaves counted once per instance.
TEST(Tlas, LeafDepthsSpanBothLevels) {
  const Scene s = make_instanced_scene(60, 2);
  const Tlas two(s);
  ASSERT_GT(two.tlas_nodes().size(), 1u);
  double sum = 0.0, leaves = 0.0;
  std::uint32_t deepest = 0;
  const auto walk = [&](std::span<const BvhNode> nodes, std::uint32_t i, std::uint32_t depth, const auto& at_leaf,
                        const auto& self) -> void {
    if (nodes[i].is_leaf()) return at_leaf(nodes[i], depth);
    self(nodes, nodes[i].index, depth + 1, at_leaf, self);
    self(nodes, nodes[i].index + 1, depth + 1, at_leaf, self);
  };
  walk(
      two.tlas_nodes(), 0, 0,
      [&](const BvhNode& leaf, std::uint32_t d) {
        for (std::uint32_t k = leaf.index; k < leaf.index + leaf.count; ++k) {
          const Bvh& b = two.blas(two.instances()[two.tlas_instance_order()[k]].blas);
          walk(
              b.nodes(), 0, d + 1,
              [&](const BvhNode&, std::uint32_t e) {
                sum += e;
                leaves += 1.0;
                deepest = std::max(deepest, e);
              },
              walk);
        }
      },
      walk);
  ASSERT_GT(leaves, 0.0);
  EXPECT_NEAR(two.build_stats().avg_leaf_depth, sum / leaves, 1e-9 * sum / leaves);
  EXPECT_GE(two.build_stats().max_depth, deepest) << "the deepest TLAS leaf plus the deepest BLAS: an upper bound";
  EXPECT_GT(two.build_stats().avg_leaf_depth, 1.0);
}

TEST(Tlas, FactoryBuildsFromTheSceneOrOneInstance) {
  const Scene s = make_instanced_scene(20, 4);
  StructureOptions so;
  so.scene = &s;
  const auto two = build_accelerator("tlas", s.triangles, so);
  ASSERT_NE(dynamic_cast<const Tlas*>(two.get()), nullptr);
  EXPECT_EQ(dynamic_cast<const Tlas&>(*two).blas_count(), 2u);
  EXPECT_EQ(two->name(), "tlas");
  // Without the scene: one identity instance over the triangles, same hits.
  const auto one = build_accelerator("tlas", s.triangles, StructureOptions{});
  EXPECT_EQ(dynamic_cast<const Tlas&>(*one).blas_count(), 1u);
  const Bvh flat = flat_bvh(s.triangles);
  const std::vector<Ray> rays = make_rays(s, 5000, 9);
  for (const Ray& r : rays)
    ASSERT_EQ(one->closest_hit(r, QueryOptions{}).prim, flat.closest_hit(r, QueryOptions{}).prim);
  bool listed = false;
  for (const std::string& n : structure_names()) listed = listed || n == "tlas";
  EXPECT_TRUE(listed);
}

TEST(Tlas, SingularTransformIsRefused) {
  Scene s = make_instanced_scene(0, 1);
  const auto message = [&] {
    try {
      Tlas t(s);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(built)");
  };
  s.instances[0].transform = glm::scale(glm::mat4(1.0f), glm::vec3(1.0f, 0.0f, 1.0f));
  EXPECT_NE(message().find("tlas: instance 0: its transform is singular (determinant 0"), std::string::npos)
      << message();
  s.instances[0].transform[3][1] = std::numeric_limits<float>::quiet_NaN();  // it said "not invertible (determinant 1)"
  EXPECT_EQ(message(), "tlas: instance 0: its transform has a non-finite entry");
  // A uniform scale whose float determinant overflows (1e13: 1e39) or underflows (1e-16: 1e-48) is no
  // singular transform: both were refused as "singular (determinant inf / 0)".
  for (const float scale : {1e13f, 1e-16f}) {
    s.instances[0].transform = glm::scale(glm::mat4(1.0f), glm::vec3(scale));
    EXPECT_EQ(message(), "(built)") << scale;
  }
}

// A tiny mirrored instance (scale -1e-16, 1e-16, 1e-16) flips its normals as a large one does: its
// float determinant (-1e-48) flushed to -0, so it counted as not mirrored and the two-level hit's
// normal pointed the other way from the flattened triangle's.
TEST(Tlas, ATinyMirroredInstanceIsMirrored) {
  Scene s;
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.indices = {{0, 1, 2}};
  s.meshes.push_back(m);
  Instance inst;
  inst.mesh = 0;
  inst.transform = glm::scale(glm::mat4(1.0f), glm::vec3(-1e-16f, 1e-16f, 1e-16f));
  s.instances.push_back(inst);
  s.flatten();
  ASSERT_EQ(s.triangles.size(), 1u);
  const Tlas two(s);
  ASSERT_EQ(two.instances().size(), 1u);
  EXPECT_TRUE(two.instances()[0].mirrored);
  const Bvh flat = flat_bvh(s.triangles);
  const Ray r({-0.25e-16f, 0.25e-16f, 1.0f}, {0, 0, -1}, 0.0f, kInfinity);
  const Hit a = two.closest_hit(r, QueryOptions{}), b = flat.closest_hit(r, QueryOptions{});
  ASSERT_TRUE(a.valid());
  ASSERT_TRUE(b.valid());
  EXPECT_GT(glm::dot(a.ng, b.ng), 0.99f) << "two-level (" << a.ng.x << ", " << a.ng.y << ", " << a.ng.z
                                         << ") against flattened (" << b.ng.x << ", " << b.ng.y << ", " << b.ng.z
                                         << ")";
}

// The ray carried into an instance's space keeps its aim (instance_ray): from far away along an axis
// (1e8: the float rotation of the origin lost the units that aim at a 2-unit cube, and the instance
// was missed from there on, every other structure hitting), and into a tiny instance (1e-30: a 1e9
// direction became infinite in its space, and the BLAS said a hit at t = 0).
TEST(Tlas, FarOriginsAndExtremeScalesKeepTheirAim) {
  Mesh cube;
  cube.positions = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}};
  cube.indices = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                  {3, 7, 6}, {3, 6, 2}, {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}};
  const auto scene_with = [&](const glm::mat4& m) {
    Scene s;
    s.meshes.push_back(cube);
    Instance inst;
    inst.mesh = 0;
    inst.transform = m;
    s.instances.push_back(inst);
    s.flatten();
    return s;
  };
  const auto agree = [](const Accelerator& a, const Accelerator& b, const Ray& r, const std::string& what) {
    const Hit x = a.closest_hit(r, QueryOptions{}), y = b.closest_hit(r, QueryOptions{});
    ASSERT_TRUE(y.valid()) << what << ": the flattened BVH hits";
    EXPECT_TRUE(x.valid()) << what;
    if (!x.valid()) return;
    EXPECT_NEAR(x.t, y.t, 1e-5 * y.t) << what;
    EXPECT_TRUE(a.any_hit(r, QueryOptions{})) << what;
  };
  const Scene rotated = scene_with(glm::rotate(glm::mat4(1.0f), glm::radians(30.0f), glm::vec3(0, 1, 0)));
  const Tlas two(rotated);
  const Bvh flat = flat_bvh(rotated.triangles);
  for (const float far : {1e3f, 3e7f, 1e8f, 1e12f, 1e14f})
    for (const glm::vec2 aim : {glm::vec2(0.1f, 0.1f), glm::vec2(-0.7f, 0.4f), glm::vec2(0.5f, -0.9f)}) {
      agree(two, flat, Ray({aim.x, aim.y, -far}, {0, 0, 1}), "from z = -" + std::to_string(far));
      agree(two, flat, Ray({far, aim.x, aim.y}, {-1, 0, 0}), "from x = " + std::to_string(far));
    }
  const Scene tiny = scene_with(glm::scale(glm::mat4(1.0f), glm::vec3(1e-30f)));
  const Tlas small(tiny);
  const Bvh small_flat = flat_bvh(tiny.triangles);
  agree(small, small_flat, Ray({-1.0f, 3e-31f, 2e-31f}, {1e9f, 0, 0}), "a 1e9 direction into a 1e-30 instance");
  const Hit h = small.closest_hit(Ray({-1.0f, 3e-31f, 2e-31f}, {1e9f, 0, 0}), QueryOptions{});
  EXPECT_GT(h.t, 0.0f) << "not a hit at the origin";

  // A triangle far from the coordinate origin (3e15) under the identity: the ray's own float origin is
  // exact, and one moved near the triangle and rounded there (float's spacing 2.7e8, the triangle's
  // size) lost the aim (an audit's case: every other structure hit).
  Mesh far_tri;
  far_tri.positions = {{2999997075292160.0f, -2000001853030400.0f, 999998846140416.0f},
                       {2999997343727616.0f, -2000001853030400.0f, 999998913249280.0f},
                       {2999997343727616.0f, -2000001987248128.0f, 999998711922688.0f}};
  far_tri.indices = {{0, 1, 2}};
  Scene far_scene;
  far_scene.meshes.push_back(far_tri);
  far_scene.instances.push_back(Instance{});
  far_scene.flatten();
  agree(Tlas(far_scene), flat_bvh(far_scene.triangles),
        Ray({2997817647824896.0f, -2004741752094720.0f, 996452411113472.0f},
            {0.0003455208789091557f, 0.0007513753371313214f, 0.0005621836171485484f}),
        "a triangle at 3e15 from 1.7e4 of its sizes away");
  // Near-axis rays from 6.3e8 onto a unit-sized triangle, with direction lengths 1e3 to 1e10: the
  // float slab entry's rounding there exceeded the diagonal kept before the box, and the moved origin
  // went past the triangle for some lengths (1e3, 1e10) and not others.
  Mesh unit_tri;
  unit_tri.positions = {{-0.4577852487564087f, -0.898190975189209f, -0.25532540678977966f},
                        {-0.5581909418106079f, -0.6353254318237305f, -0.41778525710105896f},
                        {-0.2953253984451294f, -0.797785222530365f, -0.5181909799575806f}};
  unit_tri.indices = {{0, 1, 2}};
  Scene near_scene;
  near_scene.meshes.push_back(unit_tri);
  near_scene.instances.push_back(Instance{});
  near_scene.flatten();
  const Tlas near_two(near_scene);
  const Bvh near_flat = flat_bvh(near_scene.triangles);
  for (const float length : {1e3f, 1e5f, 1e7f, 1e8f, 1e10f})
    agree(near_two, near_flat, Ray({629530304.0f, -0.7966833114624023f, -0.4705464243888855f}, {-length, 0, 0}),
          "an axis ray from 6.3e8, direction length " + std::to_string(length));
  agree(near_two, near_flat,
        Ray({629530304.0f, -0.7966833114624023f, -0.4705464243888855f},
            {-1e10f, 4.2847162262660277e-08f, 5.367832844882514e-09f}),
        "a near-axis ray from 6.3e8");
}

// A hit names its world triangle with 32 bits: a scene of 2^32 or more instanced triangles is refused
// in one line before any BLAS is built (the ids wrapped, and a hit could read as a miss).
TEST(Tlas, MoreInstancedTrianglesThanHitIdsIsRefused) {
  Scene s;
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.indices.assign(std::size_t{1} << 20, glm::uvec3(0, 1, 2));
  s.meshes.push_back(std::move(m));
  for (int i = 0; i < 4096; ++i) {  // 2^32 instanced triangles
    Instance inst;
    inst.mesh = 0;
    inst.transform = glm::translate(glm::mat4(1.0f), glm::vec3(2.0f * i, 0, 0));
    s.instances.push_back(inst);
  }
  try {
    Tlas t(s);
    ADD_FAILURE() << "built";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "tlas: 4294967296 instanced triangles, more than the 4294967295 world triangle ids a hit can name "
              "(32-bit)");
  }
}

// A scale of 0 on every axis (glTF's way to hide a node, often animated) is
// no singular transform to refuse: the instance has no surface and is left out
// of the top level; `animate` stopped at the frame a scale reached 0. The
// flattened scene's triangles of it are points: no structure hits them.
TEST(Tlas, AnInstanceScaledToZeroIsHiddenNotRefused) {
  Scene s = make_instanced_scene(40, 4);
  const glm::mat4 hidden = glm::scale(glm::translate(glm::mat4(1.0f), {1, 2, 3}), glm::vec3(0.0f));
  Scene at_zero = s;
  at_zero.instances[1].transform = hidden;
  at_zero.flatten();
  Tlas built(at_zero);
  EXPECT_TRUE(built.instances()[1].world_bounds.is_empty());
  const Bvh flat = flat_bvh(at_zero.triangles);
  Comparison c;
  compare(at_zero, flat, built, make_rays(at_zero, 5000, 8), c);
  EXPECT_EQ(c.unexplained.load(), 0u) << c.report();
  // Animated: to 0 and back again, each frame as a fresh build of the same pose.
  s.flatten();
  Tlas two(s);
  std::vector<glm::mat4> pose;
  for (const Instance& inst : s.instances) pose.push_back(inst.transform);
  std::vector<glm::mat4> zero = pose;
  zero[1] = hidden;
  two.update_transforms(zero);
  Comparison z;
  compare(at_zero, flat, two, make_rays(at_zero, 5000, 9), z);
  EXPECT_EQ(z.unexplained.load(), 0u) << z.report();
  two.update_transforms(pose);
  const Bvh again = flat_bvh(s.triangles);
  Comparison back;
  compare(s, again, two, make_rays(s, 5000, 10), back);
  EXPECT_EQ(back.unexplained.load(), 0u) << back.report();
  EXPECT_FALSE(two.instances()[1].world_bounds.is_empty());
}

// A frame with one bad transform is refused whole: the instances stay where they were.
TEST(Tlas, ARefusedFrameMovesNoInstance) {
  Scene s = make_instanced_scene(40, 4);
  Tlas two(s);
  std::vector<glm::mat4> moved;
  for (const Instance& inst : s.instances) moved.push_back(glm::translate(glm::mat4(1.0f), {3, 0, 0}) * inst.transform);
  moved.back() = glm::scale(glm::mat4(1.0f), glm::vec3(1.0f, 0.0f, 1.0f));  // flattened to a plane: singular
  try {
    two.update_transforms(moved);
    ADD_FAILURE() << "a singular transform was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("tlas: instance " + std::to_string(moved.size() - 1) + ": "),
              std::string::npos)
        << e.what();
  }
  s.flatten();
  const Bvh flat = flat_bvh(s.triangles);
  Comparison c;
  compare(s, flat, two, make_rays(s, 5000, 8), c);
  EXPECT_EQ(c.unexplained.load(), 0u) << c.report();
}

// Rigid motion: new transforms, TLAS rebuilt only; equals a fresh flattened build.
TEST(Tlas, RigidUpdateEqualsFreshBuild) {
  Scene s = make_instanced_scene(80, 5);
  Tlas two(s);
  std::vector<glm::mat4> moved;
  for (std::size_t i = 0; i < s.instances.size(); ++i) {
    s.instances[i].transform = glm::translate(glm::mat4(1.0f), glm::vec3(0.5f * static_cast<float>(i % 7), 0, 1)) *
                               glm::rotate(glm::mat4(1.0f), 0.1f * static_cast<float>(i), glm::vec3(0, 1, 0)) *
                               s.instances[i].transform;
    moved.push_back(s.instances[i].transform);
  }
  const TlasUpdateStats st = two.update_transforms(moved);
  EXPECT_GE(st.tlas_rebuild_ms, 0.0);
  EXPECT_EQ(st.blas_refit_ms, 0.0);
  EXPECT_EQ(st.blas_rebuild_ms, 0.0);
  s.flatten();
  const Bvh flat = flat_bvh(s.triangles);
  Comparison c;
  compare(s, flat, two, make_rays(s, std::max<std::size_t>(5000, ray_count() / 20), 6), c);
  EXPECT_EQ(c.unexplained.load(), 0u) << c.report();
  EXPECT_EQ(c.bad_normal.load(), 0u);
  EXPECT_THROW(two.update_transforms(std::span<const glm::mat4>(moved).first(2)), std::invalid_argument);
}

// Deforming geometry: refit-then-query equals rebuild-then-query.
TEST(Tlas, RefitThenQueryEqualsRebuildThenQuery) {
  Scene s = make_instanced_scene(40, 8);
  Tlas refit(s);
  Tlas rebuilt(s);
  // Wave the teapot mesh (mesh 0) in object space.
  for (glm::vec3& p : s.meshes[0].positions)
    p += glm::vec3(0.3f * std::sin(2.0f * p.y), 0.2f * std::cos(3.0f * p.x), 0);
  std::vector<Triangle> tris;
  for (const glm::uvec3& i : s.meshes[0].indices)
    tris.push_back({s.meshes[0].positions[i.x], s.meshes[0].positions[i.y], s.meshes[0].positions[i.z]});
  const std::size_t b = static_cast<std::size_t>(refit.blas_of_mesh(0));
  const double sah_before = refit.blas(b).build_stats().sah_cost;
  const TlasUpdateStats r1 = refit.refit_blas(b, tris);
  const TlasUpdateStats r2 = rebuilt.rebuild_blas(b, tris);
  EXPECT_GT(r1.blas_refit_ms, 0.0);
  EXPECT_GT(r2.blas_rebuild_ms, 0.0);
  EXPECT_NE(refit.blas(b).build_stats().sah_cost, sah_before);
  s.flatten();
  const std::vector<Ray> rays = make_rays(s, std::max<std::size_t>(5000, ray_count() / 20), 12);
  std::size_t differ = 0;
  for (const Ray& r : rays) {
    const Hit a = refit.closest_hit(r, QueryOptions{});
    const Hit c = rebuilt.closest_hit(r, QueryOptions{});
    if (a.valid() != c.valid() || (a.valid() && a.t != c.t)) ++differ;
  }
  // Same triangles, same arithmetic per triangle: the same t bit for bit
  // (an exact tie, a shared edge, may name either triangle).
  EXPECT_EQ(differ, 0u);
  const Bvh flat = flat_bvh(s.triangles);
  Comparison c;
  compare(s, flat, refit, rays, c);
  EXPECT_EQ(c.unexplained.load(), 0u) << c.report();
  EXPECT_THROW(rebuilt.rebuild_blas(b, std::span<const Triangle>(tris).first(3)), std::invalid_argument);
}
}  // namespace unity_test_tlas
