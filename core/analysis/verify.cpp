#include "core/analysis/verify.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "core/math/scene_scale.h"
#include "core/query/camera.h"
#include "core/util/parallel.h"
#include "core/util/random.h"
#include "core/util/timing.h"

namespace accelviz {

VerifyCounts& VerifyCounts::operator+=(const VerifyCounts& o) {
  rays += o.rays;
  mismatched_prim += o.mismatched_prim;
  t_beyond_tolerance += o.t_beyond_tolerance;
  anyhit_disagree += o.anyhit_disagree;
  near_ties += o.near_ties;
  build_ms += o.build_ms;
  return *this;
}

std::vector<VerifyStructure> parse_verify_structures(const std::string& list, unsigned threads) {
  std::vector<std::string> names;
  std::stringstream ss(list);
  for (std::string item; std::getline(ss, item, ',');) names.push_back(item);
  if (!list.empty() && list.back() == ',') names.emplace_back();
  if (list.empty()) throw std::invalid_argument("--structure: empty list");
  // An empty item is a typo ("bvh,,kdtree"), as in the GUI's instance lists: said, not skipped.
  if (std::find(names.begin(), names.end(), std::string()) != names.end())
    throw std::invalid_argument("--structure: an empty item in '" + list + "'");
  std::vector<VerifyStructure> out;
  auto add = [&](const std::string& label, const std::string& factory, BvhSplitter splitter = BvhSplitter::binned_sah,
                 bool named = false) {
    for (VerifyStructure& s : out)
      if (s.label == label) {
        s.named = s.named || named;
        return;
      }
    VerifyStructure s{label, factory, {}, named};
    s.options.threads = threads;
    s.options.bvh.splitter = splitter;
    out.push_back(std::move(s));
  };
  auto add_bvh = [&](const std::string& which) {
    if (which == "bvh" || which == "bvh-binned") add("bvh-binned", "bvh", BvhSplitter::binned_sah);
    if (which == "bvh" || which == "bvh-exact") add("bvh-exact", "bvh", BvhSplitter::exact_sah);
    if (which == "bvh" || which == "bvh-median") add("bvh-median", "bvh", BvhSplitter::median);
    if (which == "bvh" || which == "bvh-lbvh") add("bvh-lbvh", "bvh", BvhSplitter::lbvh);
  };
  for (const std::string& n : names) {
    if (n == "all") {
      add("brute", "brute");
      add_bvh("bvh");
      add("kdtree", "kdtree");
      add("grid", "grid");
      add("octree", "octree");
      if (kHaveEmbree) add("embree", "embree");
    } else if (n == "bvh" || n == "bvh-binned" || n == "bvh-exact" || n == "bvh-median" || n == "bvh-lbvh") {
      add_bvh(n);
    } else if (n == "brute" || n == "brute-bbox" || n == "kdtree" || n == "grid" || n == "octree" || n == "embree") {
      if (n == "embree" && !kHaveEmbree) throw std::invalid_argument("--structure embree: this build has no Embree backend");
      add(n, n, BvhSplitter::binned_sah, /*named=*/true);
    } else if (n == "tlas") {
      add("tlas", "tlas", BvhSplitter::binned_sah,
          /*named=*/true);  // two levels from the scene's instances when verify_structures gets the scene
    } else if (n == "voxels") {
      throw std::invalid_argument("--structure voxels: voxel hits are voxels, not triangles; it cannot be verified against triangles");
    } else {
      throw std::invalid_argument(
          "--structure: unknown '" + n +
          "' (all, brute, brute-bbox, bvh, bvh-binned, bvh-exact, bvh-median, bvh-lbvh, kdtree, grid, octree, tlas" +
          (kHaveEmbree ? ", embree)" : ")"));
    }
  }
  return out;
}

namespace {

// One independent stream per ray index, so the rays do not depend on the
// order they are generated in.
using Rng = SplitMix64;  // core/util/random.h

glm::vec3 in_box(Rng& r, const glm::vec3& lo, const glm::vec3& hi) {
  return {r.uniform(lo.x, hi.x), r.uniform(lo.y, hi.y), r.uniform(lo.z, hi.z)};  // braces: x, y, z in order
}

Aabb scene_bounds(std::span<const Triangle> tris) {
  Aabb b;
  for (const Triangle& t : tris) b.extend(t.bounds());
  if (b.is_empty()) b = Aabb{glm::vec3(-1.0f), glm::vec3(1.0f)};
  return b;
}

}  // namespace

std::vector<Ray> verify_rays(std::span<const Triangle> triangles, std::size_t count, std::uint64_t seed) {
  std::vector<Ray> rays;
  rays.reserve(count);
  const Aabb b = scene_bounds(triangles);
  // Scale-invariant: everything is measured in the scene's own size (its
  // largest extent; 1 only for a point or an extent beyond the float range),
  // so a scene of 1e-20 is probed as a scene of 1 is. (A floor of 1e-6 put the
  // origins of a 1e-20 scene 1e14 scene sizes away, where rays aimed at a
  // vertex or an edge lost their aim when rounded to float.)
  float size = std::max({b.hi.x - b.lo.x, b.hi.y - b.lo.y, b.hi.z - b.lo.z});
  if (!(size > 0.0f) || !std::isfinite(size)) size = 1.0f;
  const glm::vec3 ext = glm::max(b.hi - b.lo, glm::vec3(1e-6f * size));   // a flat scene keeps some depth
  const float radius = static_cast<float>(glm::length(glm::dvec3(ext)));  // in double: no underflow or overflow
  const float unit = power_of_two_at_or_below(std::isfinite(radius) ? radius : size);
  const glm::vec3 centre = (b.lo + b.hi) * 0.5f;
  const glm::vec3 wide_lo = b.lo - 0.5f * ext, wide_hi = b.hi + 0.5f * ext;
  const Camera cam = frame_bounds(b, 1.0f);
  const bool have_tris = !triangles.empty();

  // One draw per statement here and below: the order of two draws in one
  // expression or argument list is unspecified (GCC and Clang differ), and a
  // seed must give the same rays whatever compiled the program.
  auto outside_point = [&](Rng& r) {
    const float reach = r.uniform(0.6f, 1.5f);
    return centre + r.unit_vector() * (radius * reach);
  };
  auto vertex = [&](const Triangle& t, std::size_t i) { return i == 0 ? t.v0 : i == 1 ? t.v1 : t.v2; };

  for (std::size_t i = 0; i < count; ++i) {
    Rng r{seed * 0x2545F4914F6CDD1Dull + i};
    const double kind = r.uniform();
    glm::vec3 o, d;
    if (kind < 0.40 || !have_tris) {
      // Random: half from inside/around the bounds in any direction, half
      // from outside aimed into the bounds.
      if (r.uniform() < 0.5) {
        o = in_box(r, wide_lo, wide_hi);
        d = r.unit_vector() * unit;
      } else {
        o = outside_point(r);
        d = in_box(r, b.lo, b.hi) - o;
      }
    } else if (kind < 0.85) {
      const Triangle& t = triangles[r.below(triangles.size())];
      const double sub = r.uniform();
      if (sub < 0.25) {
        // Aimed exactly at a vertex: shared by the neighbours of a closed mesh.
        o = outside_point(r);
        d = vertex(t, r.below(3)) - o;
      } else if (sub < 0.45) {
        // Aimed at a point on an edge (rounded to float: on the edge up to rounding).
        const std::size_t e = r.below(3);
        const glm::vec3 a = vertex(t, e), c = vertex(t, (e + 1) % 3);
        const float s = r.uniform() < 0.2 ? 0.5f : static_cast<float>(r.uniform());
        o = r.uniform() < 0.5 ? outside_point(r) : in_box(r, wide_lo, wide_hi);
        d = (a + s * (c - a)) - o;
      } else if (sub < 0.65) {
        // Axis-aligned through a vertex or a random point, with +0/-0 in the
        // other components (1/±0 = ±inf in the slab tests).
        const int axis = static_cast<int>(r.below(3));
        const glm::vec3 target = r.uniform() < 0.5 ? vertex(t, r.below(3)) : in_box(r, b.lo, b.hi);
        const float sign = r.uniform() < 0.5 ? 1.0f : -1.0f;
        for (int k = 0; k < 3; ++k) d[k] = r.uniform() < 0.5 ? 0.0f : -0.0f;
        d[axis] = sign * unit;
        o = target;
        o[axis] = sign > 0 ? wide_lo[axis] : wide_hi[axis];
      } else if (sub < 0.85) {
        // Grazing: in the triangle's plane, through a point inside it.
        const float u = static_cast<float>(r.uniform()), v = static_cast<float>(r.uniform()) * (1.0f - u);
        const glm::vec3 p = t.v0 + u * (t.v1 - t.v0) + v * (t.v2 - t.v0);
        const float w = r.uniform(-1.0f, 1.0f);
        d = (t.v1 - t.v0) + w * (t.v2 - t.v0);
        o = p - d * r.uniform(0.5f, 4.0f);
      } else {
        // Origin on a face or mid-plane of the bounds (root splits, cell and
        // node boundaries), direction random or axis-aligned along that plane.
        o = in_box(r, b.lo, b.hi);
        const int axis = static_cast<int>(r.below(3));
        const int which = static_cast<int>(r.below(3));
        o[axis] = which == 0 ? b.lo[axis] : which == 1 ? b.hi[axis] : centre[axis];
        d = r.unit_vector() * unit;
        if (r.uniform() < 0.3) d[axis] = 0.0f;  // in the plane
      }
    } else {
      o = cam.position;
      const float px = r.uniform();
      const float py = r.uniform();
      const Ray cr = camera_ray(cam, px, py, 1.0f);
      o = cr.origin;
      d = cr.direction * unit;
    }
    if (!usable_direction(d)) d = glm::vec3(0.0f, 0.0f, unit);
    rays.emplace_back(o, d);
  }
  return rays;
}

VerifyResult verify_structures(std::span<const Triangle> triangles, std::span<const Ray> rays,
                               const std::vector<VerifyStructure>& structures, unsigned threads, const Scene* scene,
                               const ProgressCallback& progress) {
  if (scene && (scene->triangles.data() != triangles.data() || scene->triangles.size() != triangles.size()))
    throw std::invalid_argument("verify: the scene given is not the one whose triangles are traced");
  using Clock = std::chrono::steady_clock;
  const auto t_start = Clock::now();
  VerifyResult res;
  res.rays = rays.size();

  // The rays traced so far, the reference's and each structure's, as a fraction of all of them
  // (100 million rays showed nothing for 10 s and more).
  std::atomic<std::size_t> traced{0};
  const double all_rays = static_cast<double>(rays.size()) * static_cast<double>(structures.size() + 1);
  const auto advance = [&](std::size_t n) {
    const std::size_t done = traced.fetch_add(n, std::memory_order_relaxed) + n;
    if (progress) (void)progress(static_cast<double>(done) / all_rays);
  };

  // Reference once: the brute force in double dominates the cost.
  const ReferenceTracer ref_tracer(triangles);
  std::vector<ReferenceHit> ref(rays.size());
  const auto t_ref = Clock::now();
  parallel_for(rays.size(), threads, 64, [&](std::size_t b, std::size_t e, unsigned) {
    for (std::size_t i = b; i < e; ++i) ref[i] = ref_tracer.closest_hit(rays[i]);
    advance(e - b);
  });
  res.reference_ms = ms_since(t_ref);
  for (const ReferenceHit& h : ref) res.reference_hits += h.valid();

  const QueryOptions q;  // watertight, ordered: the product's defaults
  std::mutex mutex;
  for (const VerifyStructure& s : structures) {
    StructureOptions so = s.options;
    so.scene = scene;  // "tlas": the scene's own instances (hits use the flattened ids the reference uses)
    std::unique_ptr<Accelerator> accel;
    try {
      accel = build_accelerator(s.factory_name, triangles, so);
    } catch (const std::runtime_error& e) {
      // Embree refuses a scene it cannot hold (a vertex beyond ±1.844e18):
      // the other structures are still checked.
      if (s.factory_name != "embree") throw;
      res.not_checked.push_back({s.label, s.named, true, rays.size(), 0, without_name_prefix(e.what(), "embree")});
      advance(rays.size());
      continue;
    }
    // Rays the structure cannot take (Embree's limits) are left out of its
    // check, counted and the first named; every other ray is checked.
    RayRefusals refusals = ray_refusals(*accel, rays);
    const std::vector<std::uint8_t>& refused = refusals.refused;
    const VerifyNotChecked skipped{s.label, s.named, false, refusals.count, refusals.first, std::move(refusals.reason)};
    if (skipped.rays > 0) res.not_checked.push_back(skipped);
    if (skipped.rays == rays.size() && !rays.empty()) {  // no ray to check it on: not among the checked
      advance(rays.size());
      continue;
    }
    const unsigned nt = resolve_threads(threads);
    std::vector<VerifyCounts> per_thread(nt);
    parallel_for(rays.size(), threads, 256, [&](std::size_t b, std::size_t e, unsigned ti) {
      VerifyCounts& c = per_thread[ti];
      for (std::size_t i = b; i < e; ++i) {
        if (refused[i]) continue;
        const Hit h = accel->closest_hit(rays[i], q);
        const Verdict vc = classify_closest(triangles, rays[i], ref[i], h);
        const Verdict va = classify_any(ref[i], accel->any_hit(rays[i], q));
        ++c.rays;
        c.mismatched_prim += vc == Verdict::mismatched_prim;
        c.t_beyond_tolerance += vc == Verdict::t_beyond_tolerance;
        c.near_ties += (vc == Verdict::near_tie) + (va == Verdict::near_tie);
        c.anyhit_disagree += va == Verdict::mismatched_prim;
        if (vc == Verdict::mismatched_prim || vc == Verdict::t_beyond_tolerance || va == Verdict::mismatched_prim) {
          const std::lock_guard<std::mutex> lock(mutex);
          if (res.examples.size() < 10) {
            std::ostringstream os;
            os.precision(9);
            const Ray& ray = rays[i];
            os << s.label << " ray " << i << " o=(" << ray.origin.x << "," << ray.origin.y << "," << ray.origin.z
               << ") d=(" << ray.direction.x << "," << ray.direction.y << "," << ray.direction.z << "): closest "
               << to_string(vc) << " got prim " << (h.valid() ? static_cast<long long>(h.prim) : -1LL) << " t "
               << h.t << ", reference prim " << (ref[i].valid() ? static_cast<long long>(ref[i].prim) : -1LL)
               << " t " << ref[i].t << "; any " << to_string(va);
            res.examples.push_back(os.str());
          }
        }
      }
      advance(e - b);
    });
    VerifyCounts sum;
    for (const VerifyCounts& c : per_thread) sum += c;
    sum.build_ms = accel->build_stats().build_ms;
    res.per_structure.emplace_back(s.label, sum);
    res.total += sum;
  }
  res.total_ms = ms_since(t_start);
  return res;
}

}  // namespace accelviz
