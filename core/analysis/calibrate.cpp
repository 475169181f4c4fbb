// Micro-benchmarks behind `accelviz calibrate` (see calibrate.h).
//
// Dead-code elimination is defeated by folding every result (hit flag and
// entry distance) into a checksum that is written to a volatile sink after
// each loop; the index pattern (a stride coprime to the array size) keeps the
// hardware prefetcher honest, and the arrays are small enough to stay in the
// caches, so the loop times the tests, not memory: over 65,536 items (until
// 2026-12-06) every test paid a cache miss and both figures leaned towards
// the miss's latency. Indices wrap by a mask (the size is a power of two: a
// division per step cost about as much as a slab test), and the pairs of ray
// and item do not repeat every n tests (with n pairs replayed, the branch
// predictor learnt the loop: a slab test read 3.1 ns, 12.5 ns with n × n).
#include "core/analysis/calibrate.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <vector>

#include "core/geometry/triangle.h"
#include "core/math/aabb.h"
#include "core/math/ray.h"
#include "core/util/random.h"
#include "core/util/timing.h"

namespace accelviz {

namespace {

volatile double g_sink = 0;  // results of the timed loops end here

struct Rng {
  SplitMix64 g;
  double next() { return g.uniform_double(); }
  glm::vec3 point() { return {float(next()), float(next()), float(next())}; }
};

/// Median ns per call of `test(ray_index, item_index)` -> (hit, t).
template <typename Test>
double time_tests(const CalibrateOptions& o, double& hit_fraction, Test&& test) {
  std::vector<double> ns;
  const std::size_t mask = o.items - 1, stride = 7919;  // items: a power of two; the prime stride is coprime to it
  for (int r = 0; r < std::max(1, o.repeat); ++r) {
    double sum = 0;
    std::size_t hits = 0, item = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t k = 0; k < o.tests; ++k) {
      float t = 0;
      const bool h = test(k & mask, item, t);
      hits += h;
      sum += h ? t : 0.0f;
      // Past each round of the rays one step more, so that the pairs do not repeat every n tests
      // (n × n of them: six triangle hits replayed 8,192 times taught the branch predictor the loop).
      item = (item + stride + ((k & mask) == mask ? 1 : 0)) & mask;
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    g_sink = g_sink + sum + static_cast<double>(hits);
    ns.push_back(s * 1e9 / static_cast<double>(std::max<std::size_t>(1, o.tests)));
    hit_fraction = static_cast<double>(hits) / static_cast<double>(std::max<std::size_t>(1, o.tests));
  }
  return median(ns);
}

}  // namespace

Calibration calibrate(const CalibrateOptions& opts) {
  CalibrateOptions o = opts;
  o.items = std::bit_ceil(std::max<std::size_t>(o.items, 1));
  Rng rng{SplitMix64(o.seed)};
  // Rays from points in the unit cube towards other points in it; boxes and
  // triangles of a size that gives a mix of hits and misses (a test that
  // always misses early would flatter the fast path).
  std::vector<Ray> rays(o.items);
  for (Ray& r : rays) {
    const glm::vec3 a = rng.point(), b = rng.point();
    glm::vec3 d = b - a;
    if (glm::length(d) < 1e-3f) d = {1, 0, 0};
    r = Ray(a, d);
  }
  std::vector<Aabb> boxes(o.items);
  for (Aabb& b : boxes) {
    const glm::vec3 c = rng.point(), h(0.05f + 0.2f * float(rng.next()));
    b = Aabb{c - h, c + h};
  }
  std::vector<Triangle> tris(o.items);
  for (Triangle& t : tris) {
    const glm::vec3 c = rng.point();
    const float s = 0.3f;
    t = {c + s * (rng.point() - 0.5f), c + s * (rng.point() - 0.5f), c + s * (rng.point() - 0.5f)};
  }
  std::vector<WatertightRay> wrs(o.items);
  for (std::size_t i = 0; i < o.items; ++i) wrs[i] = WatertightRay(rays[i].direction);

  Calibration c;
  c.ns_box = time_tests(o, c.box_hit_fraction, [&](std::size_t ri, std::size_t bi, float& t) {
    SlabInterval iv;
    const bool h = intersect_slab(boxes[bi], rays[ri], iv);
    t = iv.t_entry;
    return h;
  });
  // The watertight test's per-ray shear is precomputed once per ray in a
  // traversal, so it is precomputed here too and not charged to the test.
  c.ns_triangle_watertight = time_tests(o, c.triangle_hit_fraction, [&](std::size_t ri, std::size_t ti, float& t) {
    Hit hit;
    const bool h = intersect_watertight(rays[ri], wrs[ri], tris[ti], rays[ri].tmin, rays[ri].tmax, hit);
    t = hit.t;
    return h;
  });
  double fast_hits = 0;
  c.ns_triangle_fast = time_tests(o, fast_hits, [&](std::size_t ri, std::size_t ti, float& t) {
    Hit hit;
    const bool h = intersect_moller_trumbore(rays[ri], tris[ti], rays[ri].tmin, rays[ri].tmax, hit);
    t = hit.t;
    return h;
  });
  return c;
}

}  // namespace accelviz
