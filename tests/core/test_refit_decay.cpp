// Refit decay: motion keeps shared vertices together, and the rebuild rule
// fires exactly where refit SAH / fresh SAH exceeds the ratio (and never with
// a huge ratio), on a scripted perturbation.
#include <gtest/gtest.h>

#include <algorithm>

#include "core/analysis/refit_decay.h"
#include "core/scene/load.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace accelviz::unity_test_refit_decay {
namespace {

TEST(RefitDecay, MotionIsDeterministicAndKeepsSharedVerticesTogether) {
  const std::vector<Triangle> rest{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{1, 0, 0}, {1, 1, 0}, {0, 1, 0}}};
  const std::vector<Triangle> a = animate_vertices(rest, 0.1f, 0.3, 5), b = animate_vertices(rest, 0.1f, 0.3, 5);
  EXPECT_EQ(a[0].v1, b[0].v1);
  EXPECT_EQ(a[0].v1, a[1].v0);  // the shared vertex (1,0,0)
  EXPECT_EQ(a[0].v2, a[1].v2);  // the shared vertex (0,1,0)
  EXPECT_NE(a[0].v0, rest[0].v0);
  EXPECT_LE(glm::length(a[0].v0 - rest[0].v0), 0.2f + 1e-6f);  // at most 2 · amplitude
  EXPECT_EQ(animate_vertices(rest, 0.0f, 0.3, 5)[0].v0, rest[0].v0);
}

/// Frame k swaps the positions of more and more triangle pairs (far apart in
/// scene order, so far apart in space for a soup): the refitted tree's boxes
/// grow while a fresh build does not care.
std::vector<Triangle> scrambled(const std::vector<Triangle>& rest, int frame) {
  std::vector<Triangle> t = rest;
  const std::size_t n = t.size(), pairs = std::min(n / 2, static_cast<std::size_t>(frame) * n / 40);
  for (std::size_t i = 0; i < pairs; ++i) std::swap(t[i].v0, t[n - 1 - i].v0);
  return t;
}

TEST(RefitDecay, AutoRebuildTriggersExactlyAboveTheRatio) {
  const Scene scene = load_scene("builtin:soup?size=2000");
  const std::vector<Triangle>& rest = scene.triangles;
  RefitDecayOptions o;
  o.frames = 8;
  o.threads = 1;
  o.rebuild_ratio = 1.5;
  const RefitDecayResult r = run_refit_decay(rest, {}, o, [&](int k) { return scrambled(rest, k); });
  ASSERT_EQ(r.frames.size(), 9u);  // the rest pose (frame 0), then 1..8
  EXPECT_EQ(r.frames[0].frame, 0);
  EXPECT_EQ(r.frames[0].ratio, 1.0);
  EXPECT_EQ(r.frames[0].sah_refit, r.frames[0].sah_fresh);
  EXPECT_EQ(r.frames[0].refits_since_build, 0);
  EXPECT_EQ(r.frames[8].frame, 8);
  int rebuilds = 0;
  for (const RefitFrame& f : r.frames) {
    SCOPED_TRACE(f.frame);
    EXPECT_EQ(f.rebuilt, f.ratio > 1.5);
    EXPECT_GT(f.sah_fresh, 0.0);
    EXPECT_GE(f.refit_ms, 0.0);
    rebuilds += f.rebuilt;
  }
  EXPECT_EQ(r.rebuilds, rebuilds);
  EXPECT_GE(r.rebuilds, 1);
  // After a rebuild the next frame refits the fresh tree: its count restarts.
  for (std::size_t i = 1; i < r.frames.size(); ++i)
    if (r.frames[i - 1].rebuilt) {
      EXPECT_EQ(r.frames[i].refits_since_build, 1);
    }

  o.rebuild_ratio = 1e9;
  const RefitDecayResult never = run_refit_decay(rest, {}, o, [&](int k) { return scrambled(rest, k); });
  EXPECT_EQ(never.rebuilds, 0);
  EXPECT_EQ(never.frames.back().refits_since_build, 8);
  // Without rebuilds the scrambling only grows the refitted tree's SAH against a fresh build.
  EXPECT_GT(never.frames.back().ratio, never.frames.front().ratio);
}

TEST(RefitDecay, SmoothMotionCountsTraversalOfBothTrees) {
  const Scene scene = load_scene("builtin:teapot?size=1000");
  std::vector<Ray> rays;
  for (int i = 0; i < 64; ++i) rays.emplace_back(glm::vec3(-10.0f, 1.5f, -1.9f + 0.06f * i), glm::vec3(1, 0, 0));
  RefitDecayOptions o;
  o.frames = 3;
  o.threads = 1;
  o.amplitude = 0.05f;
  const RefitDecayResult r = run_refit_decay(scene.triangles, rays, o);
  ASSERT_EQ(r.frames.size(), 4u);
  EXPECT_EQ(r.rebuilds, 0);
  for (const RefitFrame& f : r.frames) {
    EXPECT_GT(f.nodes_per_ray_refit, 0.0);
    EXPECT_GT(f.nodes_per_ray_fresh, 0.0);
    EXPECT_GT(f.ratio, 0.0);
  }
}

TEST(RefitDecay, EveryMotionStartsAtTheRestPoseAndReturnsAfterAPeriod) {
  const Scene scene = load_scene("builtin:teapot?size=300");
  const std::vector<Triangle>& rest = scene.triangles;
  for (const RefitMotion m : {RefitMotion::jitter, RefitMotion::explode, RefitMotion::wave}) {
    SCOPED_TRACE(std::string(refit_motion_name(m)));
    EXPECT_EQ(parse_refit_motion(refit_motion_name(m)), m);
    const auto at = [&](double t) { return animate_triangles(rest, m, 0.1f, 10.0f, t, 3); };
    const std::vector<Triangle> t0 = at(0.0), half = at(0.5), whole = at(1.0), again = at(0.5);
    float moved = 0.0f, back = 0.0f;
    for (std::size_t i = 0; i < rest.size(); ++i) {
      EXPECT_EQ(t0[i].v0, rest[i].v0);     // sin(2π·phase) − sin(2π·phase) = 0 exactly
      EXPECT_EQ(half[i].v1, again[i].v1);  // deterministic
      moved = std::max(moved, glm::length(half[i].v0 - rest[i].v0));
      back = std::max(back, glm::length(whole[i].v0 - rest[i].v0));
      EXPECT_LE(glm::length(half[i].v2 - rest[i].v2), 0.2f + 1e-5f);  // at most 2 · amplitude
      if (m == RefitMotion::explode) {                                // rigid: the triangle keeps its edges
        EXPECT_LT(glm::length((half[i].v1 - half[i].v0) - (rest[i].v1 - rest[i].v0)), 1e-5f);
      }
    }
    EXPECT_GT(moved, 0.05f);
    EXPECT_LT(back, 1e-5f);
  }
  EXPECT_FALSE(parse_refit_motion("shake"));
}

TEST(RefitDecay, ExplodingTrianglesDecayTheRefitWhileABendDoesNot) {
  // The lesson of the two motions: triangles that drift apart on their own
  // make the refitted tree's grouping stale; a smooth bend keeps neighbours
  // together, and the refitted tree stays as good as a fresh one.
  const Scene scene = load_scene("builtin:teapot?size=2000");
  RefitDecayOptions o;
  o.frames = 10;  // up to half a period: the largest displacement
  o.threads = 1;
  double worst[2] = {0, 0};
  for (const RefitMotion m : {RefitMotion::explode, RefitMotion::wave}) {
    o.motion = m;
    const RefitDecayResult r = run_refit_decay(scene.triangles, {}, o);
    for (const RefitFrame& f : r.frames)
      worst[m == RefitMotion::wave] = std::max(worst[m == RefitMotion::wave], f.ratio);
  }
  EXPECT_GT(worst[0], 1.3) << "explode";
  EXPECT_LT(worst[1], 1.05) << "wave";
  EXPECT_GT(worst[0] - 1.0, 5.0 * (worst[1] - 1.0));
}

TEST(RefitDecay, RejectsBadOptions) {
  const std::vector<Triangle> rest{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  RefitDecayOptions o;
  o.frames = 0;
  EXPECT_THROW(run_refit_decay(rest, {}, o), std::invalid_argument);
  o.frames = 1;
  EXPECT_THROW(run_refit_decay(rest, {}, o, [](int) { return std::vector<Triangle>{}; }), std::invalid_argument);
}

}  // namespace
}  // namespace accelviz::unity_test_refit_decay
