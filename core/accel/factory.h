#pragma once
// The one place that turns a structure name ("bvh", "brute", "embree", ...)
// and its options into a built accelerator, for the command line, the
// benchmarks and the GUI alike.
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/accel/accel.h"
#include "core/accel/brute_force.h"
#include "core/accel/bvh/bvh.h"
#include "core/accel/embree_backend.h"
#include "core/accel/grid/grid.h"
#include "core/accel/kdtree/kdtree.h"
#include "core/accel/octree/octree.h"
#include "core/accel/tlas/tlas.h"
#include "core/accel/voxels/voxels.h"

namespace accelviz {

/// Options of every structure the factory can build; each structure reads its own.
struct StructureOptions {
  BvhOptions bvh;            ///< "bvh"
  BruteForceOptions brute;   ///< "brute" (bbox_early_out is forced on for "brute-bbox")
  KdTreeOptions kdtree;      ///< "kdtree"
  GridOptions grid;          ///< "grid"
  OctreeOptions octree;      ///< "octree"
  VoxelOptions voxels;       ///< "voxels" (hits are voxels, not triangles: see voxels.h)
  EmbreeOptions embree;      ///< "embree"
  unsigned threads = 0;      ///< build threads for structures whose own option is 0 (0: all hardware threads)
  /// "tlas": the scene whose meshes and instances make the two levels (both
  /// levels use `bvh`'s options). Used when `triangles` is this scene's
  /// flattened list (or empty: a scene too large to flatten); otherwise
  /// "tlas" wraps the triangles as one identity instance.
  const Scene* scene = nullptr;
};

/// Names build_accelerator accepts, in the order `--help` lists them
/// ("embree" only when this build has the Embree backend).
const std::vector<std::string>& structure_names();

/// "brute, brute-bbox, bvh, kdtree, ...": for messages and help texts.
std::string structure_names_joined();

/// The cost constants (C_trav, C_isect) the structure's SAH cost
/// (BuildStats::sah_cost) is computed with: its options' for "bvh", "tlas"
/// and "kdtree" (whose C_isect defaults to 1.5), 1 and 1 for "octree",
/// "brute" and "brute-bbox"; none for the structures without an SAH cost.
/// SAH costs of two structures compare only under the same constants.
std::optional<std::pair<float, float>> sah_constants(std::string_view name, const StructureOptions& opts);

/// "C_trav 1, C_isect 1.5" for sah_constants, or "" where there are none.
std::string sah_constants_text(std::string_view name, const StructureOptions& opts);

/// Builds the structure `name` over `triangles` (which must outlive it).
/// Throws std::invalid_argument listing the valid names for an unknown name,
/// and whatever the builder throws (std::invalid_argument for bad options,
/// BuildCancelled when `progress` returns false).
std::unique_ptr<Accelerator> build_accelerator(std::string_view name, std::span<const Triangle> triangles,
                                               const StructureOptions& opts, const ProgressCallback& progress = {});

}  // namespace accelviz
