// The double-precision reference and the classifier behind `accelviz verify`:
// hand-made rays whose answers are known exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <mutex>

#include "core/accel/brute_force.h"
#include "core/accel/reference.h"
#include "core/analysis/verify.h"
#include "tests/core/spatial_test_scenes.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_reference {

using namespace accelviz;

namespace {

// Unit square in z = 0 as two triangles sharing the diagonal (0,0)-(1,1).
std::vector<Triangle> square() {
  return {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, {{0, 0, 0}, {1, 1, 0}, {0, 1, 0}}};
}

}  // namespace

TEST(Reference, HitsInteriorAtExactT) {
  const auto tris = square();
  const ReferenceTracer ref(tris);
  const ReferenceHit h = ref.closest_hit(Ray({0.75f, 0.25f, 2.0f}, {0, 0, -1}));
  ASSERT_TRUE(h.valid());
  EXPECT_EQ(h.prim, 0u);
  EXPECT_EQ(h.t, 2.0);
  EXPECT_FALSE(h.closest_near_edge);
  EXPECT_TRUE(h.robust_hit);
  EXPECT_TRUE(ref.any_hit(Ray({0.75f, 0.25f, 2.0f}, {0, 0, -1})));
}

TEST(Reference, SharedDiagonalIsHitAndNearEdge) {
  const auto tris = square();
  const ReferenceHit h = ReferenceTracer(tris).closest_hit(Ray({0.5f, 0.5f, 1.0f}, {0, 0, -1}));
  ASSERT_TRUE(h.valid());
  EXPECT_EQ(h.t, 1.0);
  EXPECT_TRUE(h.closest_near_edge);
}

TEST(Reference, MissOutsideAndBeyondTmax) {
  const auto tris = square();
  const ReferenceTracer ref(tris);
  EXPECT_FALSE(ref.closest_hit(Ray({2.0f, 0.5f, 1.0f}, {0, 0, -1})).valid());
  EXPECT_FALSE(ref.closest_hit(Ray({0.5f, 0.25f, 1.0f}, {0, 0, -1}, 0.0f, 0.5f)).valid());
  EXPECT_FALSE(ref.any_hit(Ray({0.5f, 0.25f, 1.0f}, {0, 0, -1}, 0.0f, 0.5f)));
}

TEST(Reference, RayInThePlaneIsANearMissNotAHit) {
  const auto tris = square();
  const ReferenceHit h = ReferenceTracer(tris).closest_hit(Ray({-1.0f, 0.5f, 0.0f}, {1, 0, 0}));
  EXPECT_FALSE(h.valid());
  EXPECT_TRUE(h.near_hit);
  EXPECT_FALSE(h.robust_hit);
}

TEST(Reference, ClosestOfTwoParallelTriangles) {
  std::vector<Triangle> tris = {{{0, 0, 1}, {1, 0, 1}, {0, 1, 1}}, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  const ReferenceHit h = ReferenceTracer(tris).closest_hit(Ray({0.2f, 0.2f, -1.0f}, {0, 0, 1}));
  ASSERT_TRUE(h.valid());
  EXPECT_EQ(h.prim, 1u);
  EXPECT_EQ(h.t, 1.0);
}

TEST(Classifier, SamePrimSameTIsMatchOtherTIsBeyondTolerance) {
  const auto tris = square();
  const Ray ray({0.75f, 0.25f, 2.0f}, {0, 0, -1});
  const ReferenceHit ref = ReferenceTracer(tris).closest_hit(ray);
  Hit got;
  got.prim = 0;
  got.t = 2.0f;
  EXPECT_EQ(classify_closest(tris, ray, ref, got), Verdict::match);
  got.t = 2.1f;
  EXPECT_EQ(classify_closest(tris, ray, ref, got), Verdict::t_beyond_tolerance);
}

TEST(Classifier, NeighbourOnSharedEdgeIsNearTie) {
  const auto tris = square();
  const Ray ray({0.5f, 0.5f, 1.0f}, {0, 0, -1});
  const ReferenceHit ref = ReferenceTracer(tris).closest_hit(ray);
  Hit got;
  got.prim = ref.prim == 0 ? 1 : 0;
  got.t = 1.0f;
  EXPECT_EQ(classify_closest(tris, ray, ref, got), Verdict::near_tie);
}

TEST(Classifier, WrongPrimAtOtherTIsMismatch) {
  std::vector<Triangle> tris = {{{0, 0, 1}, {1, 0, 1}, {0, 1, 1}}, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  const Ray ray({0.2f, 0.2f, -1.0f}, {0, 0, 1});
  const ReferenceHit ref = ReferenceTracer(tris).closest_hit(ray);
  Hit got;
  got.prim = 0;  // the farther one: a structure that skipped the closer hit
  got.t = 2.0f;
  EXPECT_EQ(classify_closest(tris, ray, ref, got), Verdict::mismatched_prim);
  EXPECT_EQ(classify_closest(tris, ray, ref, Hit{}), Verdict::mismatched_prim);  // a plain miss
}

TEST(Classifier, HitWhereReferenceMissesClearlyIsMismatch) {
  const auto tris = square();
  const Ray ray({3.0f, 3.0f, 1.0f}, {0, 0, -1});
  const ReferenceHit ref = ReferenceTracer(tris).closest_hit(ray);
  Hit got;
  got.prim = 0;
  got.t = 1.0f;
  EXPECT_EQ(classify_closest(tris, ray, ref, got), Verdict::mismatched_prim);
}

// A direction with denormal components (1.4e-45 beside -1000): the float test's shear constants
// (d.x / d.y, d.z / d.y) underflow to 0, so it walks exactly along the mesh's outer edge at z = 0 and
// hits; the reference, in double, puts the ray 4e-50 outside it. Underflow is an absolute rounding
// the relative tolerance did not cover: every float structure, brute force too, was condemned
// (found by an audit on a lattice of 1/8 squares).
TEST(Classifier, DenormalDirectionComponentsRoundAsTheFloatTestDoes) {
  const std::vector<Triangle> tris = {{{0, 0.25f, 0}, {0.125f, 0.25f, 0}, {0, 0.25f, 0.125f}}};
  const Ray ray({0.03125f, 0.28125f, 0.0f}, {1.4e-45f, -1000.0f, -1.4e-45f});
  ASSERT_GT(ray.direction.x, 0.0f) << "the denormal survives";
  const BruteForce brute(tris);
  const Hit got = brute.closest_hit(ray, {});
  ASSERT_TRUE(got.valid()) << "the float test hits on the edge";
  const ReferenceHit ref = ReferenceTracer(tris).closest_hit(ray);
  const Verdict v = classify_closest(tris, ray, ref, got);
  EXPECT_TRUE(v == Verdict::match || v == Verdict::near_tie) << to_string(v);
  EXPECT_NE(classify_any(ref, true), Verdict::mismatched_prim) << "the any hit too";
}

TEST(Classifier, AnyHit) {
  ReferenceHit miss;
  EXPECT_EQ(classify_any(miss, false), Verdict::match);
  EXPECT_EQ(classify_any(miss, true), Verdict::mismatched_prim);
  ReferenceHit robust;
  robust.prim = 0;
  robust.t = 1.0;
  robust.robust_hit = robust.near_hit = true;
  EXPECT_EQ(classify_any(robust, true), Verdict::match);
  EXPECT_EQ(classify_any(robust, false), Verdict::mismatched_prim);
  ReferenceHit edge_only = robust;
  edge_only.robust_hit = false;
  EXPECT_EQ(classify_any(edge_only, false), Verdict::near_tie);
}

TEST(Reference, AgreesWithFloatBruteForceOnRandomRays) {
  std::vector<Triangle> tris;
  for (int i = 0; i < 200; ++i) {
    const float x = static_cast<float>(i % 20) * 0.1f, y = static_cast<float>(i / 20) * 0.1f;
    tris.push_back({{x, y, 0.01f * static_cast<float>(i % 7)}, {x + 0.1f, y, 0.0f}, {x, y + 0.1f, 0.02f}});
  }
  const std::vector<Ray> rays = verify_rays(tris, 5000, 7);
  const ReferenceTracer ref(tris);
  const BruteForce brute(tris);
  int hits = 0;
  for (const Ray& r : rays) {
    const ReferenceHit rh = ref.closest_hit(r);
    hits += rh.valid();
    const Verdict v = classify_closest(tris, r, rh, brute.closest_hit(r, {}));
    EXPECT_TRUE(v == Verdict::match || v == Verdict::near_tie) << to_string(v);
  }
  EXPECT_GT(hits, 500);
}

TEST(Verify, StructureListParsing) {
  const auto all = parse_verify_structures("all", 1);
  ASSERT_GE(all.size(), 7u);
  EXPECT_EQ(all[0].label, "brute");
  EXPECT_EQ(parse_verify_structures("bvh", 1).size(), 4u);  // binned, exact, median, lbvh
  EXPECT_EQ(parse_verify_structures("kdtree,grid,kdtree", 1).size(), 2u);
  EXPECT_THROW(parse_verify_structures("voxels", 1), std::invalid_argument);
  EXPECT_THROW(parse_verify_structures("nope", 1), std::invalid_argument);
  // tlas is verified when asked for (two levels from the scene given), not in "all".
  const auto tl = parse_verify_structures("tlas,brute", 1);
  ASSERT_EQ(tl.size(), 2u);
  EXPECT_EQ(tl[0].factory_name, "tlas");
  for (const auto& s : all) EXPECT_NE(s.factory_name, "tlas");
  // A structure named by itself is marked so (its refusal is the run's error); "all" names none.
  for (const auto& s : all) EXPECT_FALSE(s.named) << s.label;
  for (const auto& s : parse_verify_structures("brute,tlas", 1)) EXPECT_TRUE(s.named || s.label == "brute") << s.label;
  if (kHaveEmbree) {
    const auto e = parse_verify_structures("all,embree", 1);
    for (const auto& s : e) EXPECT_EQ(s.named, s.label == "embree") << s.label;
  }
}

// verify reports how far it is (100 million rays showed nothing for 10 s and more): the fraction of the rays
// traced, the reference's and each structure's, reaching 1.
TEST(Verify, ReportsTheFractionOfTheRaysTraced) {
  const std::vector<Triangle> tris = test_scenes::soup(4, 200, 0.2f);
  const std::vector<Ray> rays = verify_rays(tris, 3000, 5);
  std::mutex mutex;
  std::vector<double> heard;
  const VerifyResult r =
      verify_structures(tris, rays, parse_verify_structures("bvh-binned,grid", 2), 2, nullptr, [&](double f) {
        const std::lock_guard<std::mutex> lock(mutex);
        heard.push_back(f);
        return true;
      });
  EXPECT_EQ(r.total.rays, 2 * rays.size());
  ASSERT_GE(heard.size(), 3u);
  EXPECT_DOUBLE_EQ(*std::max_element(heard.begin(), heard.end()), 1.0);
  for (const double f : heard) EXPECT_GT(f, 0.0);
}

// The rays are made in the scene's own size: a closed cube of 1e-20 gets as
// few near ties (decisions within rounding) as one of 1. With a floor of 1e-6
// on the size, the tiny cube's rays came from 1e14 sizes away and lost their
// aim: 43% of its checks were near ties against 4% at scale 1.
TEST(Verify, ATinySceneIsProbedAsAUnitSceneIs) {
  const auto structures = parse_verify_structures("bvh-binned", 2);
  const auto share_of_near_ties = [&](float half, std::uint64_t* reference_hits) {
    const auto tris = test_scenes::subdivided_cube(glm::vec3(-half), 2.0f * half, 4);
    const std::vector<Ray> rays = verify_rays(tris, 6000, 1);
    const VerifyResult r = verify_structures(tris, rays, structures, 2);
    EXPECT_TRUE(r.ok()) << half;
    *reference_hits = r.reference_hits;
    return static_cast<double>(r.total.near_ties) / (2.0 * static_cast<double>(rays.size()));  // closest + any
  };
  std::uint64_t unit_hits = 0, tiny_hits = 0;
  const double unit = share_of_near_ties(1.0f, &unit_hits), tiny = share_of_near_ties(1e-20f, &tiny_hits);
  EXPECT_GT(unit, 0.0);
  EXPECT_LT(tiny, 2.0 * unit + 0.01) << "unit " << unit << ", tiny " << tiny;
  EXPECT_NEAR(static_cast<double>(tiny_hits), static_cast<double>(unit_hits), 0.05 * 6000);
}

// Embree refuses a scene with a vertex beyond ±1.844e18 and rays it cannot
// take (here: directions without a component of 1e-15): the other structures
// are still checked on every ray, Embree on the rays it takes, and the
// refusal is listed, not a disagreement (verify used to stop at the first).
TEST(Verify, AnEmbreeRefusalLeavesTheOtherStructuresChecked) {
  if (!kHaveEmbree) GTEST_SKIP() << "no Embree in this build";
  const auto structures = parse_verify_structures("brute,bvh-binned,embree", 1);
  {
    const auto huge = test_scenes::subdivided_cube(glm::vec3(-2e18f), 4e18f, 3);
    const std::vector<Ray> rays = verify_rays(huge, 600, 5);
    const VerifyResult r = verify_structures(huge, rays, structures, 1);
    ASSERT_EQ(r.per_structure.size(), 2u);
    for (const auto& [label, c] : r.per_structure) {
      EXPECT_NE(label, "embree");
      EXPECT_EQ(c.rays, rays.size()) << label;
      EXPECT_TRUE(c.ok()) << label;
    }
    ASSERT_EQ(r.not_checked.size(), 1u);
    EXPECT_EQ(r.not_checked[0].label, "embree");
    EXPECT_TRUE(r.not_checked[0].scene_refused);
    EXPECT_TRUE(r.not_checked[0].named);
    EXPECT_EQ(r.not_checked[0].rays, rays.size());
    EXPECT_NE(r.not_checked[0].reason.find("beyond ±1.844e18"), std::string::npos) << r.not_checked[0].reason;
    EXPECT_TRUE(r.ok());
    EXPECT_TRUE(r.named_refused());
  }
  {
    const auto cube = test_scenes::subdivided_cube(glm::vec3(0.0f), 1.0f, 3);
    std::vector<Ray> rays = verify_rays(cube, 400, 9);
    std::size_t short_rays = 0;
    for (std::size_t i = 0; i < rays.size(); i += 3, ++short_rays)
      rays[i] = Ray(rays[i].origin, glm::normalize(rays[i].direction) * 1e-20f);
    const VerifyResult r = verify_structures(cube, rays, parse_verify_structures("all", 1), 1);
    ASSERT_EQ(r.not_checked.size(), 1u);
    const VerifyNotChecked& n = r.not_checked[0];
    EXPECT_EQ(n.label, "embree");
    EXPECT_FALSE(n.scene_refused);
    EXPECT_FALSE(n.named);
    EXPECT_EQ(n.rays, short_rays);
    EXPECT_EQ(n.first_ray, 0u);
    EXPECT_NE(n.reason.find("no component of 1e-15"), std::string::npos) << n.reason;
    EXPECT_EQ(r.per_structure.size(), parse_verify_structures("all", 1).size());
    for (const auto& [label, c] : r.per_structure) {
      EXPECT_EQ(c.rays, label == "embree" ? rays.size() - short_rays : rays.size()) << label;
      EXPECT_TRUE(c.ok()) << label;
    }
    EXPECT_FALSE(r.named_refused());
  }
}

TEST(Verify, RaysAreDeterministic) {
  const auto tris = square();
  const auto a = verify_rays(tris, 1000, 3), b = verify_rays(tris, 1000, 3);
  ASSERT_EQ(a.size(), 1000u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].origin, b[i].origin);
    EXPECT_EQ(a[i].direction, b[i].direction);
  }
}
}  // namespace unity_test_reference
