#pragma once
// Per-node visit attribution over a view's rays ("hot nodes"): every ray's
// traversal is traced (VisitTrace), and the nodes it entered and the
// primitives it tested are kept per pixel, so that one can ask how often each
// node was entered, which nodes were the hottest, which pixels' rays entered
// a given node, and which nodes and primitives a region of the image touched.
// Works for any structure that records traces (node ids are its own: BVH
// node index, grid cell, ...).
#include <cstdint>
#include <span>
#include <vector>

#include "core/accel/accel.h"
#include "core/query/camera.h"

namespace accelviz {

/// What each pixel's ray did, in compressed rows: pixel p entered
/// nodes[node_offsets[p] .. node_offsets[p+1]) in traversal order and tested
/// prims[prim_offsets[p] .. prim_offsets[p+1]) (scene primitive ids, in test order).
struct VisitRecord {
  int width = 0;
  int height = 0;
  std::vector<std::uint32_t> node_offsets;  ///< width*height + 1 entries
  std::vector<std::uint32_t> nodes;
  std::vector<std::uint32_t> prim_offsets;  ///< width*height + 1 entries
  std::vector<std::uint32_t> prims;
  std::vector<RayStats> stats;          ///< per pixel
  std::vector<std::uint32_t> hit_prim;  ///< per pixel: scene id of the closest hit, kNoHitPrim on a miss

  static constexpr std::uint32_t kNoHitPrim = 0xffffffffu;
  std::size_t pixel_count() const { return static_cast<std::size_t>(width) * static_cast<std::size_t>(height); }
  std::span<const std::uint32_t> nodes_of(std::size_t pixel) const {
    return std::span<const std::uint32_t>(nodes).subspan(node_offsets[pixel],
                                                         node_offsets[pixel + 1] - node_offsets[pixel]);
  }
  std::span<const std::uint32_t> prims_of(std::size_t pixel) const {
    return std::span<const std::uint32_t>(prims).subspan(prim_offsets[pixel],
                                                         prim_offsets[pixel + 1] - prim_offsets[pixel]);
  }
};

/// Traces `rays` (row-major, width*height of them) with traces on and keeps
/// what each entered and tested. Throws std::invalid_argument when the sizes
/// disagree, BuildCancelled when `progress` returns false.
VisitRecord record_visits(const Accelerator& accel, std::span<const Ray> rays, int width, int height,
                          const QueryOptions& query, unsigned threads = 0, const ProgressCallback& progress = {});

/// The same over the camera's primary rays (one per pixel).
VisitRecord record_view_visits(const Accelerator& accel, const Camera& camera, int width, int height,
                               const QueryOptions& query, unsigned threads = 0, const ProgressCallback& progress = {});

/// Entries per node over all rays (ids >= node_count are ignored). In a BVH a
/// ray enters a node at most once, so this is the number of rays that entered it.
std::vector<std::uint64_t> node_visit_counts(const VisitRecord& rec, std::size_t node_count);

struct HotNode {
  std::uint32_t node = 0;
  std::uint64_t visits = 0;
};
/// The `n` most visited nodes, most visited first (ties: lower id first); nodes never visited are left out.
std::vector<HotNode> top_hot_nodes(std::span<const std::uint64_t> counts, std::size_t n);

/// One byte per pixel: 1 where that pixel's ray entered `node`.
std::vector<std::uint8_t> pixels_visiting(const VisitRecord& rec, std::uint32_t node);

/// What the rays of a rectangle of pixels touched.
struct RegionTouch {
  std::uint64_t rays = 0;                ///< pixels in the (clamped) rectangle
  std::vector<std::uint32_t> nodes;      ///< distinct nodes entered, ascending
  std::vector<std::uint32_t> prims;      ///< distinct primitives tested, ascending
  std::vector<std::uint32_t> hit_prims;  ///< distinct primitives hit (closest), ascending
};
/// Pixels x in [x0, x1), y in [y0, y1), clamped to the image (empty when nothing remains).
RegionTouch region_touch(const VisitRecord& rec, int x0, int y0, int x1, int y1);

}  // namespace accelviz
