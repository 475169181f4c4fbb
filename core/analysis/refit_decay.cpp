// Refit decay experiment (see refit_decay.h).
#include "core/analysis/refit_decay.h"

#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "core/query/batch.h"
#include "core/util/parallel.h"
#include "core/util/random.h"
#include "core/util/timing.h"

namespace accelviz {

namespace {

constexpr double kTwoPi = 6.283185307179586;

double unit(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

/// The seed, salted, then the bits of `floats`, mixed: the same draw for the same rest geometry.
std::uint64_t hash_of(std::span<const float> floats, std::uint64_t seed, std::uint64_t salt) {
  std::uint64_t h = mix64(seed ^ kGolden64 ^ salt);
  for (const float f : floats) h = mix64(h ^ std::bit_cast<std::uint32_t>(f));
  return h;
}

/// A unit direction, uniform on the sphere, and a phase in [0, 1), from a hash.
struct Draw {
  glm::dvec3 dir;
  double phase = 0.0;
};
Draw draw(std::uint64_t h) {
  const double z = 2.0 * unit(mix64(h + 1)) - 1.0, phi = kTwoPi * unit(mix64(h + 2));
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {{r * std::cos(phi), r * std::sin(phi), z}, unit(mix64(h + 3))};
}

/// The swing of every motion: 0 at time 0 (the rest pose), at most 2 · amplitude half a period later,
/// back at whole periods.
double swing(double amplitude, double time, double phase) {
  return amplitude * (std::sin(kTwoPi * (time + phase)) - std::sin(kTwoPi * phase));
}

/// The vertex at rest position p moved along its own direction (jitter).
glm::vec3 displace(const glm::vec3& p, float amplitude, double time, std::uint64_t seed) {
  const Draw d = draw(hash_of({&p.x, 3}, seed, 0));
  return p + glm::vec3(d.dir * swing(amplitude, time, d.phase));
}

void count(const Accelerator& accel, std::span<const Ray> rays, unsigned threads, double& nodes, double& prims) {
  nodes = prims = 0;
  if (rays.empty()) return;
  std::vector<Hit> hits(rays.size());
  std::vector<RayStats> stats(rays.size());
  trace_closest(accel, rays, hits, QueryOptions{}, threads, stats);
  for (const RayStats& s : stats) {
    nodes += s.nodes_visited;
    prims += s.prim_tests;
  }
  nodes /= static_cast<double>(rays.size());
  prims /= static_cast<double>(rays.size());
}

}  // namespace

std::vector<Triangle> animate_vertices(std::span<const Triangle> rest, float amplitude, double time,
                                       std::uint64_t seed) {
  std::vector<Triangle> out(rest.begin(), rest.end());
  for (Triangle& t : out) {
    t.v0 = displace(t.v0, amplitude, time, seed);
    t.v1 = displace(t.v1, amplitude, time, seed);
    t.v2 = displace(t.v2, amplitude, time, seed);
  }
  return out;
}

std::string_view refit_motion_name(RefitMotion m) {
  switch (m) {
    case RefitMotion::jitter:
      return "jitter";
    case RefitMotion::explode:
      return "explode";
    case RefitMotion::wave:
      return "wave";
  }
  return "?";
}

std::optional<RefitMotion> parse_refit_motion(std::string_view name) {
  for (const RefitMotion m : {RefitMotion::jitter, RefitMotion::explode, RefitMotion::wave})
    if (refit_motion_name(m) == name) return m;
  return std::nullopt;
}

std::vector<Triangle> animate_triangles(std::span<const Triangle> rest, RefitMotion motion, float amplitude,
                                        float diagonal, double time, std::uint64_t seed) {
  if (motion == RefitMotion::jitter) return animate_vertices(rest, amplitude, time, seed);
  std::vector<Triangle> out(rest.begin(), rest.end());
  if (motion == RefitMotion::explode) {
    for (Triangle& t : out) {
      const float corners[9] = {t.v0.x, t.v0.y, t.v0.z, t.v1.x, t.v1.y, t.v1.z, t.v2.x, t.v2.y, t.v2.z};
      const Draw d = draw(hash_of(corners, seed, 0x9E3779B1u));
      const glm::vec3 shift(d.dir * swing(amplitude, time, d.phase));
      t.v0 += shift;
      t.v1 += shift;
      t.v2 += shift;
    }
    return out;
  }
  // wave: one wavelength across the scene's diagonal.
  const glm::dvec3 k = draw(hash_of({}, seed, 1)).dir / std::max(static_cast<double>(diagonal), 1e-30);
  const glm::dvec3 u = draw(hash_of({}, seed, 2)).dir;
  const auto move = [&](glm::vec3& p) {
    const double x = glm::dot(k, glm::dvec3(p));
    p += glm::vec3(u * (amplitude * (std::sin(kTwoPi * (time + x)) - std::sin(kTwoPi * x))));
  };
  for (Triangle& t : out) {
    move(t.v0);
    move(t.v1);
    move(t.v2);
  }
  return out;
}

RefitDecayResult run_refit_decay(std::span<const Triangle> rest, std::span<const Ray> rays,
                                 const RefitDecayOptions& opts, const FrameSource& source) {
  if (opts.frames < 1) throw std::invalid_argument("refit decay: frames must be at least 1");
  if (!(opts.rebuild_ratio >= 0) || !(opts.amplitude >= 0))
    throw std::invalid_argument("refit decay: amplitude and rebuild ratio must not be negative");
  Aabb box = Aabb::empty();
  for (const Triangle& t : rest) box.extend(t.bounds());
  const float amplitude = rest.empty() ? 0.0f : opts.amplitude * glm::length(box.extent());
  const unsigned threads = resolve_threads(opts.threads);
  BvhOptions bo = opts.bvh;
  bo.compute_epo = false;

  // Frame k's triangles must outlive the tree built over them (Bvh keeps a copy
  // in leaf order, but the source vector is kept anyway for the next refit).
  std::vector<Triangle> current(rest.begin(), rest.end());
  auto tree = std::make_unique<Bvh>(current, bo);
  int refits = 0;
  RefitDecayResult result;
  {  // frame 0: the rest pose the tree was built on, the baseline (refit = fresh build)
    RefitFrame f;
    f.rebuild_ms = tree->build_stats().build_ms;
    f.sah_refit = f.sah_fresh = tree->build_stats().sah_cost;
    f.ratio = 1.0;
    count(*tree, rays, threads, f.nodes_per_ray_refit, f.prims_per_ray_refit);
    f.nodes_per_ray_fresh = f.nodes_per_ray_refit;
    f.prims_per_ray_fresh = f.prims_per_ray_refit;
    result.frames.push_back(f);
  }
  for (int k = 1; k <= opts.frames; ++k) {
    current = source ? source(k)
                     : animate_triangles(rest, opts.motion, amplitude, glm::length(box.extent()), k * opts.frame_step,
                                         opts.seed);
    if (current.size() != rest.size()) throw std::invalid_argument("refit decay: frame changed the triangle count");
    RefitFrame f;
    f.frame = k;
    const auto t0 = std::chrono::steady_clock::now();
    tree->refit(current);
    f.refit_ms = ms_since(t0);
    f.refits_since_build = ++refits;
    f.sah_refit = tree->build_stats().sah_cost;
    auto fresh = std::make_unique<Bvh>(current, bo);
    f.rebuild_ms = fresh->build_stats().build_ms;
    f.sah_fresh = fresh->build_stats().sah_cost;
    f.ratio = f.sah_fresh > 0 ? f.sah_refit / f.sah_fresh : 1.0;
    count(*tree, rays, threads, f.nodes_per_ray_refit, f.prims_per_ray_refit);
    count(*fresh, rays, threads, f.nodes_per_ray_fresh, f.prims_per_ray_fresh);
    if (opts.rebuild_ratio > 0 && f.ratio > opts.rebuild_ratio) {
      tree = std::move(fresh);  // the next frame refits the fresh tree
      refits = 0;
      f.rebuilt = true;
      ++result.rebuilds;
    }
    result.frames.push_back(f);
  }
  return result;
}

}  // namespace accelviz
