// Uniform grid construction: resolution from the cell density lambda, then
// two passes over the triangles (count per cell, then fill the CSR arrays).
#include "core/accel/grid/grid.h"
#include "core/accel/kdtree/spatial_traversal.h"
#include "core/geometry/tri_box_overlap.h"
#include "core/util/timing.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace accelviz {

void validate(const GridOptions& o) {
  const bool all_zero = o.resolution[0] == 0 && o.resolution[1] == 0 && o.resolution[2] == 0;
  if (!all_zero) {
    std::uint64_t cells = 1;
    for (int a = 0; a < 3; ++a) {
      if (o.resolution[a] < 1)
        throw std::invalid_argument("grid: resolution must be {0,0,0} (auto) or >= 1 on every axis, got " +
                                    std::to_string(o.resolution[0]) + "x" + std::to_string(o.resolution[1]) + "x" +
                                    std::to_string(o.resolution[2]));
      cells *= static_cast<std::uint64_t>(o.resolution[a]);
      if (cells > kGridMaxCells)
        throw std::invalid_argument("grid: resolution " + std::to_string(o.resolution[0]) + "x" +
                                    std::to_string(o.resolution[1]) + "x" + std::to_string(o.resolution[2]) +
                                    " has more than 2^26 cells");
    }
  }
  if (!(std::isfinite(o.lambda) && o.lambda > 0.0f))
    throw std::invalid_argument("grid: lambda must be finite and > 0, got " + std::to_string(o.lambda));
}

std::array<int, 3> grid_resolution(const Aabb& bounds, std::size_t n, const GridOptions& opts) {
  validate(opts);
  if (opts.resolution[0] > 0) return opts.resolution;
  std::array<int, 3> res{1, 1, 1};
  if (n == 0 || bounds.is_empty()) return res;
  const glm::dvec3 ext = glm::dvec3(bounds.hi) - glm::dvec3(bounds.lo);
  const double target = std::min(static_cast<double>(opts.lambda) * static_cast<double>(n),
                                 static_cast<double>(kGridMaxCells));
  // n_i = extent_i · s with s = (target / volume)^(1/d) over the d axes that
  // get more than one cell (Wald et al. 2006). An axis whose share rounds
  // below one cell (zero or tiny extent) gets 1, and s is recomputed over
  // the others, so a flat wall gets a 2D grid of about target cells.
  bool active[3] = {ext.x > 0.0, ext.y > 0.0, ext.z > 0.0};
  double s = 0.0;
  for (int round = 0; round < 3; ++round) {
    int d = 0;
    double volume = 1.0;
    for (int a = 0; a < 3; ++a)
      if (active[a]) ++d, volume *= ext[a];
    if (d == 0) return res;
    s = std::pow(target / volume, 1.0 / d);
    bool changed = false;
    for (int a = 0; a < 3; ++a)
      if (active[a] && ext[a] * s < 1.0) active[a] = false, changed = true;
    if (!changed) break;
  }
  for (int a = 0; a < 3; ++a)
    res[a] = active[a] ? static_cast<int>(std::clamp(std::round(ext[a] * s), 1.0, static_cast<double>(kGridMaxCells))) : 1;
  // Rounding up on every axis can overshoot the cap: shrink the largest axis.
  while (static_cast<std::uint64_t>(res[0]) * res[1] * res[2] > kGridMaxCells) {
    const int a = res[0] >= res[1] && res[0] >= res[2] ? 0 : (res[1] >= res[2] ? 1 : 2);
    res[a] = std::max(1, res[a] - std::max(1, res[a] / 64));
  }
  return res;
}

int Grid::cell_of(float p, int axis) const {
  const float x = (p - bounds_.lo[axis]) * inv_cell_size_[axis];
  if (!(x >= 0.0f)) return 0;  // below, or NaN from a flat axis' 0·inf
  if (x >= static_cast<float>(res_[axis])) return res_[axis] - 1;
  return std::min(static_cast<int>(x), res_[axis] - 1);
}

Grid::Grid(std::span<const Triangle> triangles, const GridOptions& opts, const ProgressCallback& progress)
    : tris_(triangles.begin(), triangles.end()), opts_(opts) {
  validate(opts_);
  const auto t_start = std::chrono::steady_clock::now();
  if (tris_.size() >= (1ull << 32) - 1) throw std::length_error("grid: more than 2^32-2 triangles");

  std::vector<std::uint32_t> prims;
  prims.reserve(tris_.size());
  for (std::size_t i = 0; i < tris_.size(); ++i) {
    if (!is_finite_triangle(tris_[i])) continue;
    prims.push_back(static_cast<std::uint32_t>(i));
    bounds_.extend(tris_[i].bounds());
  }

  if (!prims.empty()) {
    res_ = grid_resolution(bounds_, prims.size(), opts_);
    for (int a = 0; a < 3; ++a) {
      const float ext = bounds_.hi[a] - bounds_.lo[a];
      cell_size_[a] = ext / static_cast<float>(res_[a]);
      // A flat axis has one cell of size 0: its index is always 0.
      inv_cell_size_[a] = ext > 0.0f ? static_cast<float>(res_[a]) / ext : 0.0f;
    }
    const std::size_t ncells = static_cast<std::size_t>(res_[0]) * res_[1] * res_[2];
    const float pad = spatial::cell_padding(bounds_.lo, bounds_.hi);

    // Visits every cell a triangle is referenced by: the cells of its padded
    // bounds, filtered by the exact overlap test with the padded cell box.
    const auto for_each_cell = [&](std::uint32_t prim, auto&& fn) {
      const Triangle& tri = tris_[prim];
      const Aabb b = padded_box(tri.bounds(), pad);
      int lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        lo[a] = cell_of(b.lo[a], a);
        hi[a] = cell_of(b.hi[a], a);
      }
      const bool single = lo[0] == hi[0] && lo[1] == hi[1] && lo[2] == hi[2];
      for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
          for (int x = lo[0]; x <= hi[0]; ++x) {
            // One candidate cell contains the whole padded bounds: no test needed.
            if (opts_.exact_overlap && !single && !triangle_box_overlap(tri, padded_box(cell_box(x, y, z), pad)))
              continue;
            fn(static_cast<std::size_t>(x) + static_cast<std::size_t>(res_[0]) * (y + static_cast<std::size_t>(res_[1]) * z));
          }
    };
    std::size_t reported = 0;
    const auto report = [&](std::size_t done_units) {
      if (progress && done_units - reported >= 4096) {
        reported = done_units;
        if (!progress(0.5 * static_cast<double>(done_units) / static_cast<double>(prims.size())))
          throw BuildCancelled();
      }
    };

    // Pass 1: count references per cell; the running sum turns the counts
    // into each cell's end position.
    cell_start_.assign(ncells + 1, 0);
    for (std::size_t k = 0; k < prims.size(); ++k) {
      for_each_cell(prims[k], [&](std::size_t c) { ++cell_start_[c]; });
      report(k + 1);
    }
    std::uint64_t total = 0;
    for (std::size_t c = 0; c < ncells; ++c) {
      total += cell_start_[c];
      if (total > 0xFFFFFFFFull) throw std::length_error("grid: more than 2^32-1 references");
      cell_start_[c] = static_cast<std::uint32_t>(total);
    }
    cell_start_[ncells] = static_cast<std::uint32_t>(total);

    // Pass 2: fill backwards from each cell's end; walking the triangles in
    // reverse leaves every cell's list in ascending id order and every
    // cell_start[c] at the cell's beginning.
    refs_.resize(total);
    reported = 0;
    for (std::size_t k = prims.size(); k-- > 0;) {
      for_each_cell(prims[k], [&](std::size_t c) { refs_[--cell_start_[c]] = prims[k]; });
      report(prims.size() + (prims.size() - k));
    }
  }

  std::uint64_t empty = 0;
  const std::size_t ncells = cell_start_.empty() ? 0 : cell_start_.size() - 1;
  for (std::size_t c = 0; c < ncells; ++c) empty += cell_start_[c] == cell_start_[c + 1];
  stats_.build_ms = ms_since(t_start);
  stats_.node_count = ncells;
  stats_.leaf_count = ncells;
  // The cells are the grid's leaves, one level below its bounds (the box
  // views draw the bounds at depth 0 and the cells at depth 1).
  stats_.max_depth = ncells > 0 ? 1 : 0;
  stats_.avg_leaf_depth = ncells > 0 ? 1.0 : 0.0;
  // The triangles it copies count, as the BVH's triangle blocks and Embree's buffers do.
  stats_.memory_bytes = (cell_start_.size() + refs_.size()) * sizeof(std::uint32_t) + tris_.size() * sizeof(Triangle);
  stats_.extra["memory_triangles"] = static_cast<double>(tris_.size() * sizeof(Triangle));
  stats_.extra["cells"] = static_cast<double>(ncells);
  stats_.extra["empty_cells"] = static_cast<double>(empty);
  stats_.extra["references"] = static_cast<double>(refs_.size());
  stats_.extra["res_x"] = res_[0];
  stats_.extra["res_y"] = res_[1];
  stats_.extra["res_z"] = res_[2];
  stats_.extra["refs_per_nonempty_cell"] =
      ncells > empty ? static_cast<double>(refs_.size()) / static_cast<double>(ncells - empty) : 0.0;
  if (progress && !progress(1.0)) throw BuildCancelled();
}

}  // namespace accelviz
