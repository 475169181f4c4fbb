#pragma once
// Two-level acceleration structure: one bottom-level BVH (BLAS) per unique
// mesh, built once in object space, and a top-level BVH (TLAS) over the
// instances' world bounds. A ray reaching a TLAS leaf is carried into each
// instance's object space by the instance's inverse transform: the origin as
// a point, the direction as a vector, NOT renormalised, so the ray parameter
// t means the same point in both spaces and hits compare in world units.
// Scale, rotation and mirroring (negative determinant) need nothing more;
// the hit normal is brought back by the inverse transpose and flipped when
// the transform mirrors, so it matches the flattened world triangle's.
//
// Hits report the world primitive id the scene's flattened triangle list
// uses (instance.first_triangle + the triangle's index in its mesh), so the
// two-level structure compares one-to-one with every single-level one, and
// the instance id in Hit::instance.
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/accel/accel.h"
#include "core/accel/bvh/bvh.h"
#include "core/scene/scene.h"

namespace accelviz {

struct TlasOptions {
  BvhOptions blas;  ///< bottom-level BVHs (one per unique mesh)
  BvhOptions tlas;  ///< top-level BVH over instance boxes
};

/// Per-ray figures only a two-level structure has.
struct TwoLevelRayStats {
  std::uint32_t instances_visited = 0;  ///< instances whose BLAS the ray entered (object-space traversals)
  std::uint32_t tlas_nodes = 0;         ///< TLAS nodes entered
  std::uint32_t blas_nodes = 0;         ///< BLAS nodes entered, summed over instances
  std::uint32_t prim_tests = 0;         ///< ray-triangle tests, summed over instances
};

/// The box of BOX's eight corners under the affine M (an empty box stays
/// empty): an instance's or a BLAS node's box in world space.
Aabb corners_box(const Aabb& box, const glm::mat4& m);

/// One placement of a BLAS.
struct TlasInstance {
  std::uint32_t blas = 0;           ///< index into the BLAS list
  std::uint32_t mesh = 0;           ///< scene mesh index
  glm::mat4 to_world{1.0f};         ///< object to world
  glm::mat4 to_object{1.0f};        ///< world to object (inverse of to_world)
  glm::mat3 normal_to_world{1.0f};  ///< inverse transpose, times -1 when the transform mirrors
  std::uint64_t first_prim = 0;     ///< world primitive id of the mesh's first triangle
  Aabb world_bounds;
  bool mirrored = false;  ///< determinant < 0
};

/// Timings of one dynamic update (see update_transforms, refit_blas, rebuild_blas).
struct TlasUpdateStats {
  double tlas_rebuild_ms = 0.0;
  double blas_refit_ms = 0.0;
  double blas_rebuild_ms = 0.0;
};

class Tlas final : public Accelerator {
 public:
  /// One BLAS per mesh that some instance references (built once, whatever
  /// the number of instances), one instance per scene instance. Works on
  /// scenes whose triangle list was not flattened (primitive ids are then
  /// those flattening would give). Throws std::invalid_argument for bad
  /// options or an instance whose transform is not invertible.
  Tlas(const Scene& scene, const TlasOptions& opts = {}, const ProgressCallback& progress = {});
  /// A single identity instance over `triangles` (the factory's fallback
  /// when no scene is given): the same answers as a BVH, one level deeper.
  Tlas(std::span<const Triangle> triangles, const TlasOptions& opts = {}, const ProgressCallback& progress = {});
  ~Tlas() override;

  /// A frozen copy of the structure as it stands: TLAS nodes, instances and
  /// figures copied, every BLAS shared (not copied). Later updates of this
  /// structure never change the copy: refit_blas refits a private copy of a
  /// shared BLAS, replace_blas and rebuild_blas put a new one in its place.
  /// How the GUI shows the animator's own per-frame tree while the animator
  /// moves on (ui/app/dynamics.h). Not thread-safe against a concurrent
  /// update of this structure: take it on the thread that updates.
  std::shared_ptr<const Tlas> snapshot() const;

  std::string name() const override { return "tlas"; }
  Hit closest_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr,
                  VisitTrace* trace = nullptr) const override;
  bool any_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr) const override;
  const BuildStats& build_stats() const override { return stats_; }

  /// Closest hit with the two-level breakdown (stats may be null).
  Hit closest_hit_two_level(const Ray& ray, const QueryOptions& opts, TwoLevelRayStats* stats) const;

  std::size_t blas_count() const { return blas_.size(); }
  const Bvh& blas(std::size_t i) const { return *blas_[i]; }
  std::span<const TlasInstance> instances() const { return instances_; }
  std::span<const BvhNode> tlas_nodes() const { return tlas_nodes_; }
  /// Instance ids in TLAS leaf order (TLAS leaves index this array).
  std::span<const std::uint32_t> tlas_instance_order() const { return tlas_prims_; }
  /// BLAS index of scene mesh `mesh`, or -1 when no instance references it.
  int blas_of_mesh(std::uint32_t mesh) const;

  /// Bytes of the two-level structure: every BLAS once, the TLAS, the instance records.
  std::uint64_t memory_two_level() const { return static_cast<std::uint64_t>(stats_.extra.at("memory_two_level")); }
  /// Bytes a flattened single BVH would take: each instance's BLAS counted
  /// once per instance (its nodes, indices and world-space triangles).
  std::uint64_t memory_flattened_estimate() const {
    return static_cast<std::uint64_t>(stats_.extra.at("memory_flattened_estimate"));
  }
  /// World triangles the instances stand for.
  std::uint64_t instanced_triangles() const { return instanced_triangles_; }

  /// Rigid motion: new object-to-world transforms (one per instance, same
  /// order). Recomputes inverses and world boxes and rebuilds the TLAS only.
  /// Throws std::invalid_argument on a count mismatch or a singular transform.
  TlasUpdateStats update_transforms(std::span<const glm::mat4> to_world);
  /// Deforming mesh: refits BLAS `blas` to moved object-space triangles
  /// (same count and order as built), then rebuilds the TLAS (instance boxes
  /// change). Returns the timings; the BLAS's build_stats().sah_cost is the refit SAH.
  TlasUpdateStats refit_blas(std::size_t blas, std::span<const Triangle> object_triangles);
  /// Replaces BLAS `blas` by FRESH (built elsewhere over the same triangle
  /// count and order), then rebuilds the TLAS.
  TlasUpdateStats replace_blas(std::size_t blas, Bvh fresh);
  /// Same as refit_blas, but builds BLAS `blas` afresh.
  TlasUpdateStats rebuild_blas(std::size_t blas, std::span<const Triangle> object_triangles);

 private:
  void build_blas_list(const Scene& scene, const ProgressCallback& progress);
  void set_instance_transform(TlasInstance& inst, const glm::mat4& to_world);
  void update_world_bounds(TlasInstance& inst) const;
  double build_top();
  void update_memory_stats();

  TlasOptions opts_;
  Tlas(const Tlas&) = default;  ///< snapshot(): shares the BLASes
  /// The BLAS about to be changed in place: copied first when a snapshot shares it.
  Bvh& own_blas(std::size_t b);

  std::vector<std::shared_ptr<Bvh>> blas_;
  std::vector<std::uint32_t> blas_mesh_;  ///< scene mesh of each BLAS
  std::vector<TlasInstance> instances_;
  HugePageVector<BvhNode> tlas_nodes_;
  std::vector<std::uint32_t> tlas_prims_;  ///< instance ids in TLAS leaf order
  std::uint64_t instanced_triangles_ = 0;
  BuildStats stats_;
};

}  // namespace accelviz
