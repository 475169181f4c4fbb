#include "core/analysis/robustness_lab.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/accel/bvh/bvh.h"
#include "core/accel/factory.h"
#include "core/accel/reference.h"
#include "core/math/scene_scale.h"
#include "core/util/parallel.h"
#include "core/util/random.h"
#include "core/util/timing.h"

namespace accelviz {

const char* to_string(LabFamily f) {
  switch (f) {
    case LabFamily::vertex:
      return "vertex";
    case LabFamily::edge:
      return "edge";
    case LabFamily::axis:
      return "axis";
    case LabFamily::grazing:
      return "grazing";
  }
  return "?";
}

namespace {

using Clock = std::chrono::steady_clock;

using Rng = SplitMix64;  // core/util/random.h

glm::vec3 vertex_of(const Triangle& t, std::size_t i) {
  return i == 0 ? t.v0 : i == 1 ? t.v1 : t.v2;
}

// The lab's own BVH traversal, templated on the two tests so that only they
// differ between variants. Closest hit over [ray.tmin, ray.tmax].
template <bool Padded>
Hit lab_closest(const Bvh& bvh, std::span<const Triangle> tris, const Ray& ray, TriangleTest test,
                const WatertightRay& wr) {
  Hit best;
  const auto nodes = bvh.nodes();
  if (nodes.empty()) return best;
  const auto ids = bvh.prim_indices();
  std::uint32_t stack[kBvhMaxDepth + 2];
  int sp = 0;
  stack[sp++] = 0;
  float tmax = ray.tmax;
  while (sp > 0) {
    const BvhNode& n = nodes[stack[--sp]];
    SlabInterval si;
    if (!intersect_slab<Padded>(n.bounds, ray.origin, ray.inv_dir, ray.tmin, tmax, si)) continue;
    if (n.is_leaf()) {
      for (std::uint32_t k = n.index; k < n.index + n.count; ++k) {
        Hit h;
        if (intersect_triangle(test, ray, wr, tris[k], ray.tmin, tmax, h) &&
            (h.t < best.t || (h.t == best.t && ids[k] < best.prim))) {
          best = h;
          best.prim = ids[k];
          tmax = h.t;
        }
      }
    } else {
      stack[sp++] = n.index + 1;
      stack[sp++] = n.index;
    }
  }
  return best;
}

// Every primitive the variant hits in [t0, t1] (the closest surface point's
// tolerance window), counted.
template <bool Padded>
int lab_count(const Bvh& bvh, std::span<const Triangle> tris, const Ray& ray, TriangleTest test,
              const WatertightRay& wr, float t0, float t1) {
  const auto nodes = bvh.nodes();
  if (nodes.empty()) return 0;
  std::uint32_t stack[kBvhMaxDepth + 2];
  int sp = 0, count = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    const BvhNode& n = nodes[stack[--sp]];
    SlabInterval si;
    if (!intersect_slab<Padded>(n.bounds, ray.origin, ray.inv_dir, t0, t1, si)) continue;
    if (n.is_leaf()) {
      for (std::uint32_t k = n.index; k < n.index + n.count; ++k) {
        Hit h;
        count += intersect_triangle(test, ray, wr, tris[k], t0, t1, h);
      }
    } else {
      stack[sp++] = n.index + 1;
      stack[sp++] = n.index;
    }
  }
  return count;
}

// Calls visit(id) for every primitive in the leaves whose box, widened by
// `pad` on every side, the padded slab test accepts (near to far is not kept).
template <class Visit>
void for_each_padded_candidate(const Bvh& bvh, const Ray& ray, float pad, Visit&& visit) {
  const auto nodes = bvh.nodes();
  if (nodes.empty()) return;
  const auto ids = bvh.prim_indices();
  std::uint32_t stack[kBvhMaxDepth + 2];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    const BvhNode& n = nodes[stack[--sp]];
    Aabb wide = n.bounds;
    wide.lo -= glm::vec3(pad);
    wide.hi += glm::vec3(pad);
    SlabInterval si;
    if (!intersect_slab<true>(wide, ray.origin, ray.inv_dir, ray.tmin, ray.tmax, si)) continue;
    if (!n.is_leaf()) {
      stack[sp++] = n.index + 1;
      stack[sp++] = n.index;
      continue;
    }
    for (std::uint32_t k = n.index; k < n.index + n.count; ++k) visit(ids[k]);
  }
}

// The double-precision reference accelerated by the BVH: candidates are the
// leaves whose box, widened by `pad` on every side, the padded slab test
// accepts; each candidate is then tested exactly as ReferenceTracer does.
// The widening keeps every triangle the exact ray touches (and its near
// misses) among the candidates.
ReferenceHit reference_closest(const Bvh& bvh, std::span<const Triangle> scene, const Ray& ray, float pad) {
  ReferenceHit best;
  for_each_padded_candidate(bvh, ray, pad, [&](std::uint32_t id) {
    fold_reference_hit(best, intersect_reference(ray, scene[id], ray.tmin, ray.tmax), id, ray);
  });
  return best;
}

// Triangles the reference itself hits within the closest hit's tolerance window.
int reference_count(const Bvh& bvh, std::span<const Triangle> scene, const Ray& ray, double t0, double t1, float pad) {
  int count = 0;
  for_each_padded_candidate(bvh, ray, pad,
                            [&](std::uint32_t id) { count += intersect_reference(ray, scene[id], t0, t1).hit; });
  return count;
}

}  // namespace

std::vector<LabRay> lab_rays(std::span<const Triangle> triangles, std::size_t count, std::uint64_t seed) {
  std::vector<LabRay> out;
  if (triangles.empty()) return out;
  out.reserve(count);
  Aabb b;
  for (const Triangle& t : triangles) b.extend(t.bounds());
  const glm::vec3 centre = b.center();
  // Scale-invariant: the scene's own diagonal (in double: no underflow at
  // 1e-20 nor overflow at 1e20), 1 only for a point or a diagonal beyond the
  // float range. (A floor of 1e-6 put the origins of a 1e-20 scene 1e14 scene
  // sizes away, where the rays aimed at a vertex or an edge lost their aim.)
  float radius = static_cast<float>(glm::length(glm::dvec3(b.extent())));
  if (!(radius > 0.0f) || !std::isfinite(radius)) radius = 1.0f;
  // Unit directions (axis, grazing) scaled to the scene, as the aimed rays
  // are (t = 1 at their target): the reference's t tolerances, 1e-6·max(1, t),
  // then mean the same at every scale.
  const float unit = power_of_two_at_or_below(radius);
  for (std::size_t i = 0; i < count; ++i) {
    Rng r{seed * 0x2545F4914F6CDD1Dull + i};
    const auto family = static_cast<LabFamily>(i % kLabFamilies);
    // Non-degenerate triangles only, a few tries.
    const Triangle* t = &triangles[r.below(triangles.size())];
    for (int k = 0; k < 8 && !(t->area() > 0.0f); ++k) t = &triangles[r.below(triangles.size())];
    // One draw per statement: the order of two draws in one expression is
    // unspecified (GCC and Clang differ), and the rays must not depend on it.
    const float reach = r.uniform(0.6f, 1.5f);
    const glm::vec3 outside = centre + r.unit_vector() * radius * reach;
    glm::vec3 o, d;
    switch (family) {
      case LabFamily::vertex:
        o = outside;
        d = vertex_of(*t, r.below(3)) - o;
        break;
      case LabFamily::edge: {
        const std::size_t e = r.below(3);
        const glm::vec3 a = vertex_of(*t, e), c = vertex_of(*t, (e + 1) % 3);
        const float s = r.uniform() < 0.25f ? 0.5f : r.uniform();
        o = outside;
        d = (a + s * (c - a)) - o;
        break;
      }
      case LabFamily::axis: {
        const int axis = static_cast<int>(r.below(3));
        const std::size_t e = r.below(3);
        const glm::vec3 a = vertex_of(*t, e), c = vertex_of(*t, (e + 1) % 3);
        const glm::vec3 target = r.uniform() < 0.5f ? a : a + 0.5f * (c - a);
        const float sign = (r.next() & 1) ? 1.0f : -1.0f;
        d = glm::vec3(0.0f);
        d[axis] = sign * unit;
        for (int k = 0; k < 3; ++k)
          if (k != axis) d[k] = (r.next() & 1) ? -0.0f : 0.0f;
        o = target;
        o[axis] = sign > 0.0f ? b.lo[axis] - 0.1f * radius : b.hi[axis] + 0.1f * radius;
        break;
      }
      case LabFamily::grazing: {
        const float u = r.uniform(), v = r.uniform() * (1.0f - u);
        const glm::vec3 p = t->v0 + u * (t->v1 - t->v0) + v * (t->v2 - t->v0);
        const glm::vec3 n = triangle_normal(*t);  // unit, redone in double where float under/overflows
        glm::vec3 in_plane = glm::cross(n, r.unit_vector());
        if (glm::length(in_plane) > 0.0f)
          in_plane = glm::normalize(in_plane);
        else  // in double: the edge of a 1e-20 triangle normalises too
          in_plane = glm::vec3(glm::normalize(glm::dvec3(t->v1) - glm::dvec3(t->v0)));
        o = p - in_plane * radius;
        d = in_plane * unit;
        break;
      }
    }
    if (!usable_direction(d)) d = glm::vec3(0.0f, 0.0f, unit);
    out.push_back({Ray(o, d), family});
  }
  return out;
}

LabResult run_robustness_lab(std::span<const Triangle> triangles, const LabOptions& opts,
                             const std::function<bool()>& keep_going) {
  auto check = [&] {
    if (keep_going && !keep_going()) throw BuildCancelled();
  };
  if (opts.structure == "voxels")
    throw std::invalid_argument("--structure voxels: voxel hits are voxels, not triangles; the lab needs triangles");
  LabResult res;
  res.triangles = triangles.size();
  res.lab_rays = lab_rays(triangles, opts.rays, opts.seed);
  res.rays = res.lab_rays.size();
  for (const LabRay& r : res.lab_rays) ++res.rays_by_family[static_cast<int>(r.family)];

  BvhOptions bo;
  bo.threads = opts.threads;
  const Bvh bvh(triangles, bo);
  const std::vector<Triangle> leaf_tris = bvh.copy_leaf_triangles();  // the lab's traversals index leaf positions
  // The structure's own traversal; Embree ignores our triangle test, so it is
  // built twice instead: its default mode and its robust mode.
  const bool embree = opts.structure == "embree";
  std::unique_ptr<Accelerator> own, own_robust;
  std::vector<std::uint8_t> own_refuses;  // per ray: the structure cannot take it (Embree's limits)
  if (!opts.structure.empty()) {
    StructureOptions so;
    so.threads = opts.threads;
    try {
      own = build_accelerator(opts.structure, triangles, so);
      if (embree) {
        so.embree.robust = true;
        own_robust = build_accelerator(opts.structure, triangles, so);
      }
    } catch (const std::runtime_error& e) {
      if (!embree) throw;
      res.structure_refused = e.what();  // a scene Embree cannot hold: the lab's own variants still run
    }
    if (own) {
      std::vector<Ray> rays;
      for (const LabRay& l : res.lab_rays) rays.push_back(l.ray);
      RayRefusals r = ray_refusals(*own, rays);
      own_refuses = std::move(r.refused);
      res.structure_rays_refused = r.count;
      res.structure_first_refused_ray = r.first;
      res.structure_refused_ray_reason = std::move(r.reason);
    }
  }
  check();

  // Reference: candidates from leaves widened by a hair of the scene's size.
  Aabb b;
  for (const Triangle& t : triangles) b.extend(t.bounds());
  const float pad = b.is_empty() ? 0.0f
                                 : 1e-5f * std::max({static_cast<float>(glm::length(glm::dvec3(b.extent()))),
                                                     std::fabs(b.lo.x), std::fabs(b.lo.y), std::fabs(b.lo.z),
                                                     std::fabs(b.hi.x), std::fabs(b.hi.y), std::fabs(b.hi.z)});
  std::vector<ReferenceHit> ref(res.rays);
  std::vector<int> ref_count(res.rays, 0);
  const auto t_ref = Clock::now();
  parallel_for(res.rays, opts.threads, 64, [&](std::size_t lo, std::size_t hi, unsigned) {
    for (std::size_t i = lo; i < hi; ++i) {
      const Ray& ray = res.lab_rays[i].ray;
      ref[i] = reference_closest(bvh, triangles, ray, pad);
      if (ref[i].valid())
        ref_count[i] =
            reference_count(bvh, triangles, ray, ref[i].t - ref[i].t_tolerance, ref[i].t + ref[i].t_tolerance, pad);
    }
  });
  res.reference_ms = ms_since(t_ref);
  for (const ReferenceHit& h : ref) res.reference_hits += h.valid();
  check();

  struct Spec {
    std::string name;
    TriangleTest test;
    bool padded;
    bool own;
    const Accelerator* accel = nullptr;  ///< own: the structure traced
    const char* embree_mode = nullptr;   ///< Embree's rows: "default" or "robust" (our triangle test does not apply)
  };
  std::vector<Spec> specs = {
      {"moller-trumbore + plain slab", TriangleTest::moller_trumbore, false, false},
      {"moller-trumbore + padded slab", TriangleTest::moller_trumbore, true, false},
      {"watertight + plain slab", TriangleTest::watertight, false, false},
      {"watertight + padded slab", TriangleTest::watertight, true, false},
  };
  if (own && embree) {
    specs.push_back({"embree (default mode)", TriangleTest::moller_trumbore, true, true, own.get(), "default"});
    specs.push_back({"embree (robust mode)", TriangleTest::watertight, true, true, own_robust.get(), "robust"});
  } else if (own) {
    specs.push_back({opts.structure + " (moller-trumbore)", TriangleTest::moller_trumbore, true, true, own.get()});
    specs.push_back({opts.structure + " (watertight)", TriangleTest::watertight, true, true, own.get()});
  }

  for (const Spec& s : specs) {
    LabVariant v;
    v.name = s.name;
    v.triangle_test = s.test;
    v.padded_slab = s.padded;
    v.own_structure = s.own;
    if (s.embree_mode) {
      v.embree_mode = s.embree_mode;
      v.double_hits_counted = false;
    }
    v.per_ray.assign(res.rays, 0);
    std::vector<Hit> hits(res.rays);
    QueryOptions q;
    q.triangle_test = s.test;
    // Timing: one thread, closest hit of every ray.
    const auto t0 = Clock::now();
    for (std::size_t i = 0; i < res.rays; ++i) {
      const Ray& ray = res.lab_rays[i].ray;
      if (s.own) {
        if (!own_refuses[i]) hits[i] = s.accel->closest_hit(ray, q);
      } else {
        const WatertightRay wr(ray.direction);
        hits[i] = s.padded ? lab_closest<true>(bvh, leaf_tris, ray, s.test, wr)
                           : lab_closest<false>(bvh, leaf_tris, ray, s.test, wr);
      }
      if ((i & 4095) == 4095) check();
    }
    v.ms = ms_since(t0);
    const std::size_t traced = s.own ? res.rays - res.structure_rays_refused : res.rays;
    v.mrays_per_s = v.ms > 0.0 ? static_cast<double>(traced) / (v.ms * 1e3) : 0.0;
    // Classification (not timed).
    for (std::size_t i = 0; i < res.rays; ++i) {
      if (s.own && own_refuses[i]) {
        ++v.not_traced;
        v.per_ray[i] = 4;
        continue;
      }
      const LabRay& lr = res.lab_rays[i];
      const ReferenceHit& rh = ref[i];
      const Hit& h = hits[i];
      const int fam = static_cast<int>(lr.family);
      // A miss: nothing at the reference's closest surface point (no hit, or
      // only a farther one), where that point is a clear hit or the ray goes
      // on to hit something clearly (it entered the surface: a hole). A
      // silhouette graze with nothing clear behind is a rounding decision.
      if (rh.valid() && (!rh.closest_near_edge || rh.robust_hit) &&
          (!h.valid() ||
           static_cast<double>(h.t) > rh.t + std::max(rh.t_tolerance, kTTolerance * std::max(1.0, rh.t)))) {
        ++v.misses;
        ++v.misses_by_family[fam];
        v.per_ray[i] = 1;
        continue;
      }
      const Verdict verdict = classify_closest(triangles, lr.ray, rh, h);
      if (verdict == Verdict::mismatched_prim || verdict == Verdict::t_beyond_tolerance) {
        ++v.wrong;
        v.per_ray[i] = 3;
      }
      if (v.double_hits_counted && rh.valid() && ref_count[i] == 1) {
        const WatertightRay wr(lr.ray.direction);
        const float t0f = static_cast<float>(rh.t - rh.t_tolerance), t1f = static_cast<float>(rh.t + rh.t_tolerance);
        const int n = s.padded ? lab_count<true>(bvh, leaf_tris, lr.ray, s.test, wr, t0f, t1f)
                               : lab_count<false>(bvh, leaf_tris, lr.ray, s.test, wr, t0f, t1f);
        if (n >= 2) {
          ++v.double_hits;
          ++v.double_hits_by_family[fam];
          if (v.per_ray[i] == 0) v.per_ray[i] = 2;
        }
      }
    }
    res.variants.push_back(std::move(v));
    check();
  }
  return res;
}

}  // namespace accelviz
