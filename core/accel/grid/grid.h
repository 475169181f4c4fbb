#pragma once
// Uniform grid: the scene's bounds cut into nx·ny·nz equal cells, each cell
// listing the triangles that overlap it, walked by a 3D-DDA (Amanatides &
// Woo, "A Fast Voxel Traversal Algorithm for Ray Tracing", Eurographics
// 1987). Cells hold compressed-row (CSR) lists: cell_start[ncells + 1] and
// one refs[] array, built in two passes (count, then fill) without per-cell
// vectors, as in Wald et al. 2006 ("Ray Tracing Animated Scenes using
// Coherent Grid Traversal") and Lagae & Dutré 2008 ("Compact, Fast and
// Robust Grids for Ray Tracing").
#include "core/accel/accel.h"
#include "core/math/aabb.h"

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace accelviz {

struct GridOptions {
  std::array<int, 3> resolution{0, 0, 0};  ///< cells per axis; {0,0,0} = auto from lambda (else each >= 1)
  float lambda = 3.0f;                     ///< auto: about lambda·N cells, shaped to the bounds: n_i = extent_i·cbrt(lambda·N / volume) (> 0)
  bool exact_overlap = true;               ///< reference a triangle in the cells it really overlaps (Akenine-Möller test), else in every cell of its bounds
  bool mailboxing = true;                  ///< skip primitives this ray already tested (a 16-entry hashed mailbox)
};

/// Most cells a grid may have (4 bytes each in cell_start).
inline constexpr std::uint64_t kGridMaxCells = std::uint64_t{1} << 26;

/// Throws std::invalid_argument naming the offending option.
void validate(const GridOptions& opts);

/// The resolution a grid over `bounds` with `n` primitives gets for
/// `opts` (the manual one, or the automatic one). Axes of zero extent get 1
/// cell, and their share of the cell budget goes to the others; the product
/// never exceeds kGridMaxCells.
std::array<int, 3> grid_resolution(const Aabb& bounds, std::size_t n, const GridOptions& opts);

class Grid final : public Accelerator {
 public:
  /// Builds over `triangles` (copied; primitive ids are indices into this
  /// span); triangles with non-finite coordinates are left out. Throws
  /// std::invalid_argument for bad options, BuildCancelled when `progress`
  /// returns false.
  Grid(std::span<const Triangle> triangles, const GridOptions& opts = {}, const ProgressCallback& progress = {});

  std::string name() const override { return "grid"; }
  /// RayStats: nodes_visited = cells entered, empty_cells = empty ones among
  /// them, prim_tests, repeated_prim_tests, box_tests = 1 (the grid's box).
  /// Ordering does not apply (a DDA is front to back by construction).
  Hit closest_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr,
                  VisitTrace* trace = nullptr) const override;
  bool any_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr) const override;
  /// node_count = leaf_count = cells, memory_bytes (cell_start + refs);
  /// extra: "cells", "empty_cells", "references", "res_x", "res_y", "res_z",
  /// "refs_per_nonempty_cell".
  const BuildStats& build_stats() const override { return stats_; }

  std::array<int, 3> resolution() const { return res_; }
  const Aabb& bounds() const { return bounds_; }
  /// Cell c = x + nx·(y + ny·z) lists refs()[cell_start()[c] .. cell_start()[c+1]).
  std::span<const std::uint32_t> cell_start() const { return cell_start_; }
  std::span<const std::uint32_t> refs() const { return refs_; }
  /// Position of the i-th cell boundary on `axis` (0..res); the last is bounds().hi exactly.
  float plane(int axis, int i) const { return i >= res_[axis] ? bounds_.hi[axis] : bounds_.lo[axis] + static_cast<float>(i) * cell_size_[axis]; }
  Aabb cell_box(int x, int y, int z) const {
    return {{plane(0, x), plane(1, y), plane(2, z)}, {plane(0, x + 1), plane(1, y + 1), plane(2, z + 1)}};
  }
  const GridOptions& options() const { return opts_; }

 private:
  template <bool kCollect, bool kAnyHit>
  Hit traverse(const Ray& ray, const QueryOptions& qo, RayStats* stats, VisitTrace* trace) const;
  int cell_of(float p, int axis) const;

  std::vector<Triangle> tris_;
  std::array<int, 3> res_{1, 1, 1};
  Aabb bounds_;
  glm::vec3 cell_size_{0.0f}, inv_cell_size_{0.0f};
  std::vector<std::uint32_t> cell_start_;
  std::vector<std::uint32_t> refs_;
  GridOptions opts_;
  BuildStats stats_;
};

}  // namespace accelviz
