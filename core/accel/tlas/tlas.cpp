// Two-level structure: BLAS per unique mesh, TLAS over instance boxes,
// traversal in instance space (see tlas.h).
#include "core/accel/tlas/tlas.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/accel/tlas/tlas_overlap.h"
#include "core/analysis/sah.h"
#include "core/util/timing.h"

namespace accelviz {

Aabb corners_box(const Aabb& box, const glm::mat4& m) {
  Aabb out;
  if (box.is_empty()) return out;
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 c((i & 1) ? box.hi.x : box.lo.x, (i & 2) ? box.hi.y : box.lo.y, (i & 4) ? box.hi.z : box.lo.z);
    out.extend(glm::vec3(m * glm::vec4(c, 1.0f)));
  }
  return out;
}

namespace {

using Clock = std::chrono::steady_clock;

bool finite3(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// Object-space triangles of a mesh in index order, without the non-finite
/// ones (Scene::flatten drops the same ones, so kept index k is the k-th
/// world triangle of every instance).
std::vector<Triangle> object_triangles(const Mesh& mesh) {
  std::vector<Triangle> out;
  out.reserve(mesh.indices.size());
  for (const glm::uvec3& idx : mesh.indices) {
    const Triangle t{mesh.positions[idx.x], mesh.positions[idx.y], mesh.positions[idx.z]};
    if (finite3(t.v0) && finite3(t.v1) && finite3(t.v2)) out.push_back(t);
  }
  return out;
}

/// The world box of an object box under M, padded by a few ulps of its
/// magnitude: world triangles flattened vertex by vertex round differently
/// from the box corners, and a ray carried into object space rounds too.
Aabb transform_box(const Aabb& box, const glm::mat4& m) {
  Aabb out = corners_box(box, m);
  if (out.is_empty()) return out;
  const glm::vec3 mag = glm::max(glm::abs(out.lo), glm::abs(out.hi));
  const float pad = 1e-5f * std::max({mag.x, mag.y, mag.z, out.extent().x, out.extent().y, out.extent().z});
  out.lo -= glm::vec3(pad);
  out.hi += glm::vec3(pad);
  return out;
}

BvhOptions quiet(BvhOptions o) {
  o.compute_epo = false;
  return o;
}

/// A transform whose linear part is all zero (a scale of 0 on every axis,
/// glTF's usual way to hide a node, often animated): every point of the
/// instance lands on one, it has no surface, and it is left out of the top
/// level instead of refused as singular (`animate` stopped at the frame a
/// scale reached 0).
bool collapses_to_a_point(const glm::mat4& to_world) {
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (to_world[c][r] != 0.0f) return false;
  return true;
}

/// Why the two-level structure cannot carry an instance with this transform
/// ("" when it can): rays go into the instance's space through its inverse.
std::string transform_problem(const glm::mat4& to_world) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(to_world[c][r])) return "its transform has a non-finite entry";
  if (collapses_to_a_point(to_world)) return {};
  // In double: a uniform scale of 1e13 (determinant 1e39) or 1e-16 (1e-48) is no singular transform,
  // though its float determinant overflows or underflows.
  const double det = glm::determinant(glm::dmat3(glm::mat3(to_world)));
  if (!std::isfinite(det) || det == 0.0) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", det);
    return std::string("its transform is singular (determinant ") + text +
           ": a scale of 0 on one or two axes flattens it), so rays cannot be carried into its space; the single-level "
           "structures (bvh, ...) take the scene";
  }
  return {};
}

std::string instance_problem(std::size_t index, const glm::mat4& to_world) {
  const std::string problem = transform_problem(to_world);
  return problem.empty() ? problem : "tlas: instance " + std::to_string(index) + ": " + problem;
}

}  // namespace

Tlas::Tlas(const Scene& scene, const TlasOptions& opts, const ProgressCallback& progress) : opts_(opts) {
  const auto t0 = Clock::now();
  validate(opts_.blas);
  validate(opts_.tlas);
  // A hit names its world triangle with 32 bits (kInvalidId: a miss); beyond that the ids wrapped
  // and a hit could read as a miss. Checked before any BLAS is built.
  if (const std::uint64_t n = scene.instanced_triangle_count(); n > kInvalidId)  // ids 0 .. n - 1 < kInvalidId
    throw std::invalid_argument("tlas: " + std::to_string(n) +
                                " instanced triangles, more than the 4294967295 world triangle ids a hit can name "
                                "(32-bit)");
  build_blas_list(scene, progress);
  // Instances, with the world primitive ids flattening gives (or would give).
  std::vector<std::uint64_t> kept(blas_.size());
  for (std::size_t b = 0; b < blas_.size(); ++b) kept[b] = blas_[b]->triangle_count();
  std::uint64_t next = 0;
  instances_.reserve(scene.instances.size());
  const bool flattened = !scene.triangles.empty();
  for (const Instance& si : scene.instances) {
    TlasInstance inst;
    inst.mesh = si.mesh;
    const int b = blas_of_mesh(si.mesh);
    if (b < 0)
      throw std::invalid_argument("tlas: instance references mesh " + std::to_string(si.mesh) +
                                  " that is not in the scene");
    inst.blas = static_cast<std::uint32_t>(b);
    inst.first_prim = flattened ? si.first_triangle : next;
    next += kept[inst.blas];
    if (const std::string problem = instance_problem(instances_.size(), si.transform); !problem.empty())
      throw std::invalid_argument(problem);
    set_instance_transform(inst, si.transform);
    instances_.push_back(inst);
  }
  instanced_triangles_ = next;
  stats_.extra["tlas_ms"] = build_top();
  stats_.build_ms = ms_since(t0);
  {  // at build time (not per frame: an update's timings stay the TLAS's own)
    std::vector<Aabb> boxes;
    boxes.reserve(instances_.size());
    for (const TlasInstance& inst : instances_) boxes.push_back(inst.world_bounds);
    const InstanceOverlap ov = instance_overlap(boxes);
    stats_.extra["instance_overlap_area"] = ov.area_ratio;
    stats_.extra["instance_overlap_volume"] = ov.volume_ratio;
    stats_.extra["instance_overlap_pairs"] = static_cast<double>(ov.overlapping_pairs);
  }
  update_memory_stats();
  if (progress) progress(1.0);
}

Tlas::Tlas(std::span<const Triangle> triangles, const TlasOptions& opts, const ProgressCallback& progress)
    : opts_(opts) {
  const auto t0 = Clock::now();
  validate(opts_.blas);
  validate(opts_.tlas);
  blas_.push_back(std::make_shared<Bvh>(triangles, quiet(opts_.blas), progress));
  blas_mesh_.push_back(0);
  TlasInstance inst;
  set_instance_transform(inst, glm::mat4(1.0f));
  instances_.push_back(inst);
  instanced_triangles_ = triangles.size();
  stats_.extra["tlas_ms"] = build_top();
  stats_.build_ms = ms_since(t0);
  update_memory_stats();
}

Tlas::~Tlas() = default;

std::shared_ptr<const Tlas> Tlas::snapshot() const {
  return std::shared_ptr<const Tlas>(new Tlas(*this));
}

Bvh& Tlas::own_blas(std::size_t b) {
  // Only the updating thread copies this structure (snapshot()), so a count
  // of 1 cannot grow behind our back; a snapshot released elsewhere can only
  // make the copy unnecessary, never unsafe.
  if (blas_[b].use_count() > 1) blas_[b] = std::make_shared<Bvh>(*blas_[b]);
  return *blas_[b];
}

void Tlas::build_blas_list(const Scene& scene, const ProgressCallback& progress) {
  std::vector<bool> used(scene.meshes.size(), false);
  for (const Instance& si : scene.instances)
    if (si.mesh < used.size()) used[si.mesh] = true;
  std::uint64_t total = 0, done = 0;
  for (std::size_t m = 0; m < used.size(); ++m)
    if (used[m]) total += scene.meshes[m].indices.size();
  for (std::size_t m = 0; m < used.size(); ++m) {
    if (!used[m]) continue;
    const std::vector<Triangle> tris = object_triangles(scene.meshes[m]);
    const double lo = total ? static_cast<double>(done) / static_cast<double>(total) : 0.0;
    const double span = total ? static_cast<double>(scene.meshes[m].indices.size()) / static_cast<double>(total) : 0.0;
    ProgressCallback sub;
    if (progress) sub = [&](double f) { return progress(lo + span * f); };
    blas_.push_back(std::make_shared<Bvh>(tris, quiet(opts_.blas), sub));
    blas_mesh_.push_back(static_cast<std::uint32_t>(m));
    done += scene.meshes[m].indices.size();
  }
}

int Tlas::blas_of_mesh(std::uint32_t mesh) const {
  const auto it = std::find(blas_mesh_.begin(), blas_mesh_.end(), mesh);
  return it == blas_mesh_.end() ? -1 : static_cast<int>(it - blas_mesh_.begin());
}

void Tlas::set_instance_transform(TlasInstance& inst, const glm::mat4& to_world) {
  if (const std::string problem = transform_problem(to_world); !problem.empty())
    throw std::invalid_argument("tlas: " + problem);
  inst.to_world = to_world;
  if (collapses_to_a_point(to_world)) {  // hidden: no surface, no box, not in the top level
    inst.to_object = glm::mat4(0.0f);
    inst.mirrored = false;
    inst.normal_to_world = glm::mat3(0.0f);
    inst.world_bounds = Aabb{};
    return;
  }
  // The inverse and the determinant's sign in double: nearly singular transforms (a 1e-4 squash)
  // keep their digits, and a tiny mirrored one (scale -1e-16, 1e-16, 1e-16: a float determinant of
  // -1e-48 flushes to -0) still flips its normals.
  const glm::dmat4 inv = glm::inverse(glm::dmat4(to_world));
  inst.to_object = glm::mat4(inv);
  inst.mirrored = glm::determinant(glm::dmat3(glm::mat3(to_world))) < 0.0;
  inst.normal_to_world = glm::mat3(glm::transpose(glm::dmat3(inv))) * (inst.mirrored ? -1.0f : 1.0f);
  update_world_bounds(inst);
}

void Tlas::update_world_bounds(TlasInstance& inst) const {
  if (collapses_to_a_point(inst.to_world)) return;  // hidden: stays without a box
  const Bvh& b = *blas_[inst.blas];
  inst.world_bounds = b.nodes().empty() ? Aabb{} : transform_box(b.nodes()[0].bounds, inst.to_world);
}

double Tlas::build_top() {
  const auto t0 = Clock::now();
  std::vector<Aabb> bounds;
  std::vector<glm::vec3> centroids;
  std::vector<std::uint32_t> ids;
  for (std::uint32_t i = 0; i < instances_.size(); ++i) {
    if (instances_[i].world_bounds.is_empty()) continue;
    bounds.push_back(instances_[i].world_bounds);
    centroids.push_back(instances_[i].world_bounds.center());
    ids.push_back(i);
  }
  BvhTopology topo = build_bvh(bounds, centroids, opts_.tlas);
  tlas_nodes_ = std::move(topo.nodes);
  tlas_prims_.resize(topo.prim_indices.size());
  for (std::size_t k = 0; k < topo.prim_indices.size(); ++k) tlas_prims_[k] = ids[topo.prim_indices[k]];
  // Figures: both levels together.
  stats_.node_count = tlas_nodes_.size();
  stats_.leaf_count = topo.stats.leaf_count;
  std::uint32_t blas_depth = 0;
  for (const auto& b : blas_) {
    stats_.node_count += b->build_stats().node_count;
    stats_.leaf_count += b->build_stats().leaf_count;
    blas_depth = std::max(blas_depth, b->build_stats().max_depth);
  }
  stats_.max_depth = topo.stats.max_depth + 1 + blas_depth;
  // Mean leaf depth of the two-level tree as rays walk it: each instance's BLAS leaves sit one level
  // below its TLAS leaf (as in max_depth), weighted by how many leaves each placed BLAS has.
  {
    double sum = 0.0, leaves = 0.0;
    for_each_leaf_depth(tlas_nodes_, [&](std::size_t i, std::uint32_t depth) {
      const BvhNode& n = tlas_nodes_[i];
      for (std::uint32_t k = n.index; k < n.index + n.count; ++k) {
        const BuildStats& b = blas_[instances_[tlas_prims_[k]].blas]->build_stats();
        sum += static_cast<double>(b.leaf_count) * (depth + 1 + b.avg_leaf_depth);
        leaves += static_cast<double>(b.leaf_count);
      }
    });
    stats_.avg_leaf_depth = leaves > 0.0 ? sum / leaves : 0.0;
  }
  // Expected cost per ray: TLAS nodes by area, then each instance's BLAS SAH
  // weighted by the chance of entering its world box (the box stands in for
  // the BLAS root, whose cost is normalised by its own area).
  double sah = 0.0, tlas_sah = 0.0;
  if (!tlas_nodes_.empty()) {
    const double root = std::max(static_cast<double>(tlas_nodes_[0].bounds.surface_area()), 1e-30);
    for (const BvhNode& n : tlas_nodes_) {
      const double p = n.bounds.surface_area() / root;
      tlas_sah += opts_.tlas.cost_traversal * p;
      if (!n.is_leaf()) continue;
      for (std::uint32_t k = n.index; k < n.index + n.count; ++k) {
        const TlasInstance& inst = instances_[tlas_prims_[k]];
        sah += inst.world_bounds.surface_area() / root * blas_[inst.blas]->build_stats().sah_cost;
      }
    }
  }
  stats_.sah_cost = sah + tlas_sah;
  stats_.extra["tlas_sah"] = tlas_sah;
  stats_.extra["tlas_nodes"] = static_cast<double>(tlas_nodes_.size());
  stats_.extra["instances"] = static_cast<double>(instances_.size());
  stats_.extra["blas"] = static_cast<double>(blas_.size());
  return ms_since(t0);
}

void Tlas::update_memory_stats() {
  std::uint64_t blas_bytes = 0, flat = 0;
  for (const auto& b : blas_) blas_bytes += b->build_stats().memory_bytes;
  for (const TlasInstance& inst : instances_) flat += blas_[inst.blas]->build_stats().memory_bytes;
  const std::uint64_t top = tlas_nodes_.size() * sizeof(BvhNode) + tlas_prims_.size() * sizeof(std::uint32_t) +
                            instances_.size() * sizeof(TlasInstance);
  stats_.memory_bytes = blas_bytes + top;
  stats_.extra["memory_two_level"] = static_cast<double>(stats_.memory_bytes);
  stats_.extra["memory_flattened_estimate"] = static_cast<double>(flat);
  stats_.extra["instanced_triangles"] = static_cast<double>(instanced_triangles_);
  std::uint64_t unique = 0;
  for (const auto& b : blas_) unique += b->triangle_count();
  stats_.extra["unique_triangles"] = static_cast<double>(unique);
}

namespace {

struct Counters {
  RayStats* rs;
  TwoLevelRayStats* ts;
  VisitTrace* trace;
  bool any() const { return rs || ts || trace; }
};

}  // namespace

/// A world ray carried into an instance's space: world t = shift + scale · local t.
struct InstanceRay {
  Ray ray;
  double shift = 0.0;
  double scale = 1.0;
  float world_t(float local_t) const {
    return shift == 0.0 && scale == 1.0 ? local_t : static_cast<float>(shift + scale * static_cast<double>(local_t));
  }
};

/// RAY's stretch [ray.tmin, tmax] in INST's space (BOX: its BLAS root's box, in that space), so that
/// far origins and extreme transforms keep their aim. A ray that needs neither step below goes
/// through the float inverse as it always did; the others go through it in double and are rounded
/// to float once:
///  - an object-space origin that rounding would move by a sizeable part of the instance (a rotation
///    mixes a far coordinate, 1e8, into the others, and float's spacing there, 8, outweighed the
///    few units that aim at a 2-unit cube: whole instances were missed) is first moved along the
///    ray, in double, to one box diagonal before BOX. Only where that brings it at least 1024 times
///    nearer the object-space origin: an instance that lies far from it (a triangle at 3e15) has
///    the same float spacing near it as the ray's own origin, and a moved origin rounded there
///    lost the aim the exact one had. The entry distance is the double slab test's on BOX, whose
///    rounding is a few parts in 1e16 of t (the float slab test's, at 1e10 diagonals away, was
///    more than the diagonal: the origin went past the instance);
///  - an object-space direction beyond 2^±40 is scaled by a power of two: a 1e-30 instance made a
///    1e9 direction infinite, and the BLAS reported hits at t = 0.
/// t is the same number in both spaces (the direction is not renormalised) but for these two steps:
/// world t = shift + scale · local t.
InstanceRay instance_ray(const TlasInstance& inst, const Aabb& box, const Ray& ray, float tmax) {
  InstanceRay r;
  // The common ray first, in float as it always was: an origin within 1024 diagonals of the
  // object-space origin (float's rounding of it then stays under 1e-4 of a diagonal) and a direction
  // within 2^±40. The double path below cost every instance entered 8-12 % of the two-level walk.
  {
    const glm::vec3 fo(inst.to_object * glm::vec4(ray.origin, 1.0f));
    const glm::vec3 fd(glm::mat3(inst.to_object) * ray.direction);
    const float fm = std::max({std::abs(fd.x), std::abs(fd.y), std::abs(fd.z)});
    const float ffar = std::max({std::abs(fo.x), std::abs(fo.y), std::abs(fo.z)});
    if (box.is_empty() || (ffar <= 1024.0f * glm::length(box.extent()) && fm <= 0x1p40f && fm >= 0x1p-40f)) {
      r.ray = Ray(fo, fd, ray.tmin, tmax);
      return r;
    }
  }
  const glm::dmat4 to_object(inst.to_object);
  glm::dvec3 o = glm::dvec3(to_object * glm::dvec4(glm::dvec3(ray.origin), 1.0));
  glm::dvec3 d = glm::dmat3(to_object) * glm::dvec3(ray.direction);
  double tmin = ray.tmin, tmax_d = tmax;
  const auto largest = [](const glm::dvec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); };
  const double diag = glm::length(glm::dvec3(box.extent()));
  const double far = largest(o);
  if (!box.is_empty() && far > 1024.0 * diag && far < 0x1p48 * diag) {
    // The double slab test on BOX: the entry distance along the ray.
    double t0 = tmin, t1 = tmax_d;
    bool parallel_outside = false;
    for (int a = 0; a < 3; ++a) {
      if (d[a] == 0.0) {
        parallel_outside = parallel_outside || o[a] < box.lo[a] || o[a] > box.hi[a];
        continue;
      }
      const double n = (static_cast<double>(box.lo[a]) - o[a]) / d[a],
                   f = (static_cast<double>(box.hi[a]) - o[a]) / d[a];
      t0 = std::max(t0, std::min(n, f));
      t1 = std::min(t1, std::max(n, f));
    }
    const double shift = t0 - diag / glm::length(d);
    if (!parallel_outside && t0 <= t1 && shift > 0.0 && std::isfinite(shift)) {
      const glm::dvec3 moved = o + shift * d;
      if (largest(moved) * 1024.0 < far) {  // nearer the object-space origin: float resolves it
        r.shift = shift;
        o = moved;
        tmin = std::max(0.0, tmin - shift);  // before the shift lies nothing of the instance
        tmax_d -= shift;
      }
    }
  }
  const double m = largest(d);
  if (m > 0x1p40 || (m > 0.0 && m < 0x1p-40)) {
    int e = 0;
    std::frexp(m, &e);
    // d·s has its largest component in [0.5, 1); a point o + u·(d·s) is o + (u·s)·d, so world
    // t = shift + s·u and the stretch in u is the stretch in t over s.
    const double s = std::ldexp(1.0, -e);
    d *= s;
    r.scale = s;
    tmin /= s;
    tmax_d /= s;
  }
  const auto to_float = [](double t) {
    return t >= static_cast<double>(std::numeric_limits<float>::max()) ? kInfinity : static_cast<float>(t);
  };
  r.ray = Ray(glm::vec3(o), glm::vec3(d), to_float(tmin), to_float(tmax_d));
  return r;
}

/// The two-level walk. Collect false (no counter asked for: the fast path) makes every counter
/// pointer below a null the compiler knows, so no counting branch is left in that instance.
template <bool AnyHit, bool Collect>
static Hit traverse_two_level(const Tlas& t, std::span<const BvhNode> nodes, std::span<const std::uint32_t> prims,
                              const Ray& ray, const QueryOptions& qo, const Counters& counters) {
  const Counters c = Collect ? counters : Counters{nullptr, nullptr, nullptr};
  Hit best;
  if (nodes.empty()) return best;
  float tmax = ray.tmax;
  std::uint32_t stack[2 * kBvhMaxDepth + 2];
  int sp = 0;
  stack[sp++] = 0;
  const auto instances = t.instances();
  while (sp > 0) {
    const std::uint32_t idx = stack[--sp];
    const BvhNode& node = nodes[idx];
    SlabInterval iv;
    const bool hit_box = intersect_slab(node.bounds, ray.origin, ray.inv_dir, ray.tmin, tmax, iv);
    if (c.rs) ++c.rs->box_tests;
    if (!hit_box) {
      if (c.rs) ++c.rs->nodes_missed;
      if (c.trace) c.trace->steps.push_back({VisitStep::Kind::node_missed, idx, kInfinity, kInfinity});
      continue;
    }
    if (c.rs) ++c.rs->nodes_visited;
    if (c.ts) ++c.ts->tlas_nodes;
    if (c.trace) c.trace->steps.push_back({VisitStep::Kind::node_entered, idx, iv.t_entry, iv.t_exit});
    if (!node.is_leaf()) {
      // Near child first: order by the ray's sign on the box's longest axis.
      const glm::vec3 e = node.bounds.extent();
      const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
      const bool flip = ray.direction[axis] < 0.0f && qo.ordered;
      stack[sp++] = flip ? node.index : node.index + 1;
      stack[sp++] = flip ? node.index + 1 : node.index;
      continue;
    }
    for (std::uint32_t k = node.index; k < node.index + node.count; ++k) {
      const std::uint32_t id = prims[k];
      const TlasInstance& inst = instances[id];
      // Into object space (instance_ray: far origins moved near, extreme directions scaled).
      const Bvh& blas = t.blas(inst.blas);
      const InstanceRay ir = instance_ray(inst, blas.nodes().empty() ? Aabb{} : blas.nodes()[0].bounds, ray, tmax);
      const Ray& local = ir.ray;
      RayStats ls;
      RayStats* lsp = c.any() ? &ls : nullptr;
      if (c.ts) ++c.ts->instances_visited;
      if (c.rs) ++c.rs->instances_visited;
      if constexpr (AnyHit) {
        const bool h = blas.any_hit(local, qo, lsp);
        if (c.rs) *c.rs += ls;
        if (c.ts) {
          c.ts->blas_nodes += ls.nodes_visited;
          c.ts->prim_tests += ls.prim_tests;
        }
        if (h) {
          best.prim = 0;  // any-hit: validity only
          best.instance = id;
          return best;
        }
      } else {
        VisitTrace lt;
        Hit h = blas.closest_hit(local, qo, lsp, c.trace ? &lt : nullptr);
        if (c.rs) *c.rs += ls;
        if (c.ts) {
          c.ts->blas_nodes += ls.nodes_visited;
          c.ts->prim_tests += ls.prim_tests;
        }
        if (c.trace)
          for (VisitStep s : lt.steps)
            if (s.kind == VisitStep::Kind::prim_hit || s.kind == VisitStep::Kind::prim_miss) {
              s.id = static_cast<std::uint32_t>(inst.first_prim + s.id);
              if (std::isfinite(s.t_entry)) s.t_entry = ir.world_t(s.t_entry);  // a hit's t, in world units
              c.trace->steps.push_back(s);
            }
        if (h.valid()) h.t = ir.world_t(h.t);
        if (h.valid() && h.t <= tmax) {
          tmax = h.t;
          h.prim = static_cast<std::uint32_t>(inst.first_prim + h.prim);
          h.instance = id;
          const glm::vec3 n = inst.normal_to_world * h.ng;
          const float len = glm::length(n);
          h.ng = len > 0.0f ? n / len : glm::vec3(0.0f);
          best = h;
        }
      }
    }
  }
  return best;
}

Hit Tlas::closest_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats, VisitTrace* trace) const {
  const Counters c{stats, nullptr, trace};
  return c.any() ? traverse_two_level<false, true>(*this, tlas_nodes_, tlas_prims_, ray, opts, c)
                 : traverse_two_level<false, false>(*this, tlas_nodes_, tlas_prims_, ray, opts, c);
}

bool Tlas::any_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats) const {
  const Counters c{stats, nullptr, nullptr};
  return (c.any() ? traverse_two_level<true, true>(*this, tlas_nodes_, tlas_prims_, ray, opts, c)
                  : traverse_two_level<true, false>(*this, tlas_nodes_, tlas_prims_, ray, opts, c))
      .valid();
}

Hit Tlas::closest_hit_two_level(const Ray& ray, const QueryOptions& opts, TwoLevelRayStats* stats) const {
  const Counters c{nullptr, stats, nullptr};
  return c.any() ? traverse_two_level<false, true>(*this, tlas_nodes_, tlas_prims_, ray, opts, c)
                 : traverse_two_level<false, false>(*this, tlas_nodes_, tlas_prims_, ray, opts, c);
}

TlasUpdateStats Tlas::update_transforms(std::span<const glm::mat4> to_world) {
  if (to_world.size() != instances_.size())
    throw std::invalid_argument("tlas: " + std::to_string(to_world.size()) + " transforms for " +
                                std::to_string(instances_.size()) + " instances");
  // All checked first: a refused frame leaves every instance where it was.
  for (std::size_t i = 0; i < instances_.size(); ++i)
    if (const std::string problem = instance_problem(i, to_world[i]); !problem.empty())
      throw std::invalid_argument(problem);
  for (std::size_t i = 0; i < instances_.size(); ++i) set_instance_transform(instances_[i], to_world[i]);
  TlasUpdateStats s;
  s.tlas_rebuild_ms = build_top();
  return s;
}

TlasUpdateStats Tlas::refit_blas(std::size_t b, std::span<const Triangle> tris) {
  if (b >= blas_.size()) throw std::invalid_argument("tlas: no BLAS " + std::to_string(b));
  TlasUpdateStats s;
  Bvh& blas = own_blas(b);  // before the clock: the copy is not part of the refit
  const auto t0 = Clock::now();
  blas.refit(tris);
  s.blas_refit_ms = ms_since(t0);
  for (TlasInstance& inst : instances_)
    if (inst.blas == b) update_world_bounds(inst);
  s.tlas_rebuild_ms = build_top();
  update_memory_stats();
  return s;
}

TlasUpdateStats Tlas::replace_blas(std::size_t b, Bvh fresh) {
  if (b >= blas_.size()) throw std::invalid_argument("tlas: no BLAS " + std::to_string(b));
  if (fresh.triangle_count() != blas_[b]->triangle_count())
    throw std::invalid_argument("tlas: replacement BLAS " + std::to_string(b) + " has " +
                                std::to_string(fresh.triangle_count()) + " triangles, built with " +
                                std::to_string(blas_[b]->triangle_count()));
  blas_[b] = std::make_shared<Bvh>(std::move(fresh));
  for (TlasInstance& inst : instances_)
    if (inst.blas == b) update_world_bounds(inst);
  TlasUpdateStats s;
  s.tlas_rebuild_ms = build_top();
  update_memory_stats();
  return s;
}

TlasUpdateStats Tlas::rebuild_blas(std::size_t b, std::span<const Triangle> tris) {
  if (b >= blas_.size()) throw std::invalid_argument("tlas: no BLAS " + std::to_string(b));
  if (tris.size() != blas_[b]->triangle_count())
    throw std::invalid_argument("tlas: rebuild of BLAS " + std::to_string(b) + " with " + std::to_string(tris.size()) +
                                " triangles, built with " + std::to_string(blas_[b]->triangle_count()));
  TlasUpdateStats s;
  const auto t0 = Clock::now();
  blas_[b] = std::make_shared<Bvh>(tris, quiet(opts_.blas));
  s.blas_rebuild_ms = ms_since(t0);
  for (TlasInstance& inst : instances_)
    if (inst.blas == b) update_world_bounds(inst);
  s.tlas_rebuild_ms = build_top();
  update_memory_stats();
  return s;
}

}  // namespace accelviz
