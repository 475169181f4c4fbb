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
  EXPECT_LE(glm::length(a[0].v0 - rest[0].v0), 0.1f + 1e-6f);
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
  ASSERT_EQ(r.frames.size(), 8u);
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
  ASSERT_EQ(r.frames.size(), 3u);
  EXPECT_EQ(r.rebuilds, 0);
  for (const RefitFrame& f : r.frames) {
    EXPECT_GT(f.nodes_per_ray_refit, 0.0);
    EXPECT_GT(f.nodes_per_ray_fresh, 0.0);
    EXPECT_GT(f.ratio, 0.0);
  }
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
