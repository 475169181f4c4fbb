#pragma once
// The "flatten" what-if of a two-level scene: what it would cost if some
// instances were merged into one BLAS (their world triangles in one mesh
// under the identity transform) while the others stay instances, measured
// before committing to it. Both structures are built with the same options
// and traced with the same primary rays; the figures compare one-to-one.
#include <cstdint>
#include <span>
#include <vector>

#include "core/accel/tlas/tlas.h"
#include "core/scene/scene.h"

namespace accelviz {

struct TwoLevelFigures {
  double sah_cost = 0.0;  ///< build_stats().sah_cost (TLAS + instance-weighted BLAS SAH)
  std::uint64_t memory_bytes = 0;
  double build_ms = 0.0;
  std::uint64_t instances = 0, blas = 0;
  double mean_nodes = 0.0;      ///< per primary ray: TLAS + BLAS nodes entered
  double mean_prims = 0.0;      ///< per primary ray: triangle tests
  double mean_instances = 0.0;  ///< per primary ray: instances entered
  std::uint64_t rays = 0, hits = 0;
  double trace_ms = 0.0;  ///< wall time of tracing the rays (closest hit, counters on, one thread)
};

struct FlattenWhatIf {
  TwoLevelFigures two_level;  ///< the scene as it is
  TwoLevelFigures flattened;  ///< the selected instances merged into one BLAS
  std::uint64_t merged_instances = 0;
  std::uint64_t merged_triangles = 0;  ///< world triangles of the merged BLAS
};

struct FlattenedScene {
  Scene scene;
  std::uint64_t merged_triangles = 0;  ///< world triangles in the merged mesh (0: nothing merged)
};

/// SCENE with the instances listed in SELECTED (indices into
/// scene.instances; duplicates and out-of-range ids are refused with
/// std::invalid_argument) merged into one new mesh of their world
/// triangles, placed once under the identity transform; the other instances
/// keep their meshes and transforms. Instance order: the kept ones first,
/// then the merged one (absent when the selected instances have no finite
/// triangle). The result is flattened when SCENE was.
FlattenedScene flatten_instances(const Scene& scene, std::span<const std::uint32_t> selected);

/// Builds the two-level structure of SCENE and of flatten_instances(SCENE,
/// SELECTED) with OPTS and traces the WIDTH x HEIGHT primary rays of CAMERA
/// through both (closest hit, counters on). PROGRESS (optional) gets the
/// fraction done over both builds and traces; when it returns false the
/// what-if stops and throws BuildCancelled.
FlattenWhatIf flatten_what_if(const Scene& scene, std::span<const std::uint32_t> selected, const Camera& camera,
                              int width, int height, const TlasOptions& opts = {},
                              const ProgressCallback& progress = {});

}  // namespace accelviz
