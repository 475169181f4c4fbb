#include "core/accel/factory.h"

#include <cstdio>
#include <stdexcept>

namespace accelviz {

const std::vector<std::string>& structure_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = {"brute", "brute-bbox", "bvh", "kdtree", "grid", "octree", "voxels", "tlas"};
    if (kHaveEmbree) n.push_back("embree");
    return n;
  }();
  return names;
}

std::string structure_names_joined() {
  std::string s;
  for (const std::string& n : structure_names()) s += (s.empty() ? "" : ", ") + n;
  return s;
}

std::optional<std::pair<float, float>> sah_constants(std::string_view name, const StructureOptions& opts) {
  if (name == "bvh" || name == "tlas") return std::pair{opts.bvh.cost_traversal, opts.bvh.cost_intersect};
  if (name == "kdtree") return std::pair{opts.kdtree.cost_traversal, opts.kdtree.cost_intersect};
  if (name == "octree" || name == "brute" || name == "brute-bbox") return std::pair{1.0f, 1.0f};
  return std::nullopt;
}

std::string sah_constants_text(std::string_view name, const StructureOptions& opts) {
  const auto c = sah_constants(name, opts);
  if (!c) return "";
  char text[96];
  std::snprintf(text, sizeof text, "C_trav %g, C_isect %g", static_cast<double>(c->first),
                static_cast<double>(c->second));
  return text;
}

std::unique_ptr<Accelerator> build_accelerator(std::string_view name, std::span<const Triangle> triangles,
                                               const StructureOptions& opts, const ProgressCallback& progress) {
  const bool unflattened = opts.scene != nullptr && triangles.empty() && opts.scene->triangles.empty() &&
                           !opts.scene->instances.empty();
  if (name == "tlas") {
    TlasOptions to;
    to.blas = opts.bvh;
    if (to.blas.threads == 0) to.blas.threads = opts.threads;
    to.tlas = to.blas;
    // The scene's own meshes and instances when `triangles` is its flattened
    // list (a scene without instances, e.g. hand-made triangles, is one instance).
    const bool same = opts.scene != nullptr && triangles.data() == opts.scene->triangles.data() &&
                      triangles.size() == opts.scene->triangles.size() && !triangles.empty() &&
                      !opts.scene->instances.empty();
    if (same || unflattened) return std::make_unique<Tlas>(*opts.scene, to, progress);
    return std::make_unique<Tlas>(triangles, to, progress);
  }
  if (unflattened)
    throw std::invalid_argument("structure '" + std::string(name) + "': " + opts.scene->source +
                                " is instanced and too large to flatten; only 'tlas' can hold it");
  if (name == "brute" || name == "brute-bbox") {
    BruteForceOptions bo = opts.brute;
    bo.bbox_early_out = name == "brute-bbox";
    if (progress && !progress(1.0)) throw BuildCancelled();
    return std::make_unique<BruteForce>(triangles, bo);
  }
  if (name == "bvh") {
    BvhOptions bo = opts.bvh;
    if (bo.threads == 0) bo.threads = opts.threads;
    return std::make_unique<Bvh>(triangles, bo, progress);
  }
  if (name == "kdtree") {
    KdTreeOptions ko = opts.kdtree;
    if (ko.threads == 0) ko.threads = opts.threads;
    return std::make_unique<KdTree>(triangles, ko, progress);
  }
  if (name == "grid") return std::make_unique<Grid>(triangles, opts.grid, progress);
  if (name == "octree") {
    OctreeOptions oo = opts.octree;
    if (oo.threads == 0) oo.threads = opts.threads;
    return std::make_unique<Octree>(triangles, oo, progress);
  }
  if (name == "voxels") return std::make_unique<Voxels>(triangles, opts.voxels, progress);
  if (name == "embree") {
#ifdef ACCELVIZ_HAVE_EMBREE
    EmbreeOptions eo = opts.embree;
    if (eo.threads == 0) eo.threads = opts.threads;
    // Embree's own build progress (its scene progress monitor) reaches `progress`; false cancels.
    return std::make_unique<EmbreeAccelerator>(triangles, eo, progress);
#else
    throw std::invalid_argument("structure 'embree': this build has no Embree backend (configure with "
                                "-DACCELVIZ_WITH_EMBREE=ON and libembree-dev installed)");
#endif
  }
  throw std::invalid_argument("unknown structure '" + std::string(name) + "' (valid: " + structure_names_joined() +
                              ")");
}

}  // namespace accelviz
