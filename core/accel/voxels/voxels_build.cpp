// Sparse voxel octree construction: top-down over the domain, each octant
// keeping the triangles that overlap it, down to single voxels; bottom-up
// on the way back, octants that came back all full collapse into their
// parent, and only octants that are neither empty nor full get a node.
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/accel/voxels/voxels.h"
#include "core/util/timing.h"

namespace accelviz {

void validate(const VoxelOptions& o) {
  if (o.level < 0 || o.level > kVoxelMaxLevel)
    throw std::invalid_argument("voxels: level must lie in 0.." + std::to_string(kVoxelMaxLevel) + ", got " +
                                std::to_string(o.level));
}

namespace {

struct Octant {
  enum Kind { empty, full, interior } kind = empty;
  VoxelNode node;  // interior only
};

class VoxelBuilder {
 public:
  VoxelBuilder(std::span<const Triangle> tris, const VoxelDomain& d, const ProgressCallback& progress,
               std::vector<VoxelNode>& nodes)
      : tris_(tris), d_(d), progress_(progress), nodes_(nodes) {}

  // The size³ block at (x, y, z) holding `prims` (which overlap the block).
  Octant build(std::uint32_t x, std::uint32_t y, std::uint32_t z, std::uint32_t size,
               std::vector<std::uint32_t>& prims) {
    if (prims.empty()) {
      report(size);
      return {};
    }
    if (size == 1) {  // a voxel: prims passed the voxel-level predicate
      ++occupied_;
      report(1);
      return {Octant::full, {}};
    }
    const std::uint32_t half = size / 2;
    // Blocks above voxel size are tested with twice the padding, so a
    // triangle that overlaps a voxel can never be filtered out by one of the
    // voxel's ancestors through rounding: the occupancy is exactly that of
    // voxel_overlap() at the voxel level, as in voxelize_dense().
    const float pad = half == 1 ? d_.pad : 2.0f * d_.pad;
    std::array<Octant, 8> kids;
    for (int o = 0; o < 8; ++o) {
      const std::uint32_t cx = x + ((o & 1) ? half : 0), cy = y + ((o & 2) ? half : 0), cz = z + ((o & 4) ? half : 0);
      const Aabb box = d_.block_box(cx, cy, cz, half);
      std::vector<std::uint32_t> sub;
      for (std::uint32_t id : prims)
        if (voxel_overlap(tris_[id], box, pad)) sub.push_back(id);
      kids[o] = build(cx, cy, cz, half, sub);
    }
    int full = 0, empty = 0;
    for (const Octant& k : kids) {
      full += k.kind == Octant::full;
      empty += k.kind == Octant::empty;
    }
    if (full == 8) return {Octant::full, {}};  // collapse: the whole block is occupied
    if (empty == 8) return {};
    VoxelNode n;
    n.first_child = static_cast<std::uint32_t>(nodes_.size());
    for (int o = 0; o < 8; ++o) {
      if (kids[o].kind == Octant::empty) continue;
      n.valid |= static_cast<std::uint8_t>(1u << o);
      if (kids[o].kind == Octant::full) {
        n.full |= static_cast<std::uint8_t>(1u << o);
        ++full_octants_;
        if (half > 1) ++full_blocks_;
        // Its depth: the root (size = resolution) is at 0, a voxel at the level.
        full_depth_sum_ += static_cast<double>(d_.level - std::countr_zero(half));
      } else {
        nodes_.push_back(kids[o].node);
      }
    }
    if (nodes_.size() >= 0xFFFFFFF0ull) throw std::length_error("voxels: more than 2^32 nodes");
    return {Octant::interior, n};
  }

  std::uint64_t occupied_ = 0, full_octants_ = 0, full_blocks_ = 0;
  double full_depth_sum_ = 0.0;  ///< the depths of the full octants, summed

 private:
  void report(std::uint32_t size) {
    const double r = d_.resolution;
    done_ += (static_cast<double>(size) / r) * (static_cast<double>(size) / r) * (static_cast<double>(size) / r);
    if (progress_ && done_ - reported_ >= 0.01) {
      reported_ = done_;
      if (!progress_(std::min(done_, 1.0))) throw BuildCancelled();
    }
  }

  std::span<const Triangle> tris_;
  const VoxelDomain& d_;
  const ProgressCallback& progress_;
  std::vector<VoxelNode>& nodes_;
  double done_ = 0.0, reported_ = 0.0;
};

}  // namespace

Voxels::Voxels(std::span<const Triangle> triangles, const VoxelOptions& opts, const ProgressCallback& progress) {
  validate(opts);
  const auto t_start = std::chrono::steady_clock::now();
  domain_ = make_voxel_domain(triangles, opts.level);
  if (triangles.size() >= 0xFFFFFFFFull) throw std::length_error("voxels: more than 2^32-2 triangles");

  std::vector<std::uint32_t> prims;
  const float root_pad = domain_.resolution == 1 ? domain_.pad : 2.0f * domain_.pad;
  for (std::size_t i = 0; i < triangles.size(); ++i)
    if (is_finite_triangle(triangles[i]) && voxel_overlap(triangles[i], domain_.box(), root_pad))
      prims.push_back(static_cast<std::uint32_t>(i));

  VoxelBuilder builder(triangles, domain_, progress, nodes_);
  const Octant root = builder.build(0, 0, 0, domain_.resolution, prims);
  if (root.kind == Octant::interior) {
    nodes_.push_back(root.node);
    root_ = Root::interior;
  } else {
    root_ = root.kind == Octant::full ? Root::full : Root::empty;
  }
  nodes_.shrink_to_fit();
  occupied_ = builder.occupied_;

  // The dense grid at this resolution: one bit per voxel, in 64-bit words.
  const std::uint64_t voxels = static_cast<std::uint64_t>(domain_.resolution) * domain_.resolution * domain_.resolution;
  const double dense_bytes = static_cast<double>((voxels + 63) / 64 * 8);
  stats_.build_ms = ms_since(t_start);
  stats_.node_count = nodes_.size();
  stats_.leaf_count = builder.full_octants_ + (root_ == Root::full ? 1 : 0);
  stats_.max_depth = static_cast<std::uint32_t>(domain_.level);
  // Leaves are the full octants (a full root is one leaf at depth 0).
  stats_.avg_leaf_depth =
      stats_.leaf_count > 0 ? builder.full_depth_sum_ / static_cast<double>(stats_.leaf_count) : 0.0;
  stats_.memory_bytes = nodes_.size() * sizeof(VoxelNode);
  stats_.extra["occupied_voxels"] = static_cast<double>(occupied_);
  stats_.extra["dense_bytes"] = dense_bytes;
  stats_.extra["level"] = domain_.level;
  stats_.extra["resolution"] = domain_.resolution;
  stats_.extra["voxel_size"] = domain_.voxel_size;
  stats_.extra["full_blocks"] = static_cast<double>(builder.full_blocks_ + (root_ == Root::full && domain_.resolution > 1));
  if (progress && !progress(1.0)) throw BuildCancelled();
}

bool Voxels::occupied(std::uint32_t x, std::uint32_t y, std::uint32_t z) const {
  const std::uint32_t r = domain_.resolution;
  if (x >= r || y >= r || z >= r || root_ == Root::empty) return false;
  if (root_ == Root::full) return true;
  const VoxelNode* n = &nodes_.back();
  for (std::uint32_t half = r / 2; half > 0; half /= 2) {
    // Blocks are aligned to their size, so bit `half` of each coordinate
    // names the octant.
    const int o = ((x & half) ? 1 : 0) | ((y & half) ? 2 : 0) | ((z & half) ? 4 : 0);
    if (!((n->valid >> o) & 1u)) return false;
    if ((n->full >> o) & 1u) return true;
    n = &nodes_[n->child(o)];
  }
  return false;  // not reached: voxel-level octants are always empty or full
}

bool Voxels::occupied_at(const glm::vec3& p) const {
  std::uint32_t v[3];
  return domain_.voxel_of(p, v) && occupied(v[0], v[1], v[2]);
}

DenseVoxelGrid Voxels::to_dense() const {
  DenseVoxelGrid g(domain_);
  const auto fill = [&](std::uint32_t x, std::uint32_t y, std::uint32_t z, std::uint32_t size) {
    for (std::uint32_t k = z; k < z + size; ++k)
      for (std::uint32_t j = y; j < y + size; ++j)
        for (std::uint32_t i = x; i < x + size; ++i) g.set(i, j, k);
  };
  const auto walk = [&](auto&& self, const VoxelNode& n, std::uint32_t x, std::uint32_t y, std::uint32_t z,
                        std::uint32_t size) -> void {
    const std::uint32_t half = size / 2;
    for (int o = 0; o < 8; ++o) {
      if (!((n.valid >> o) & 1u)) continue;
      const std::uint32_t cx = x + ((o & 1) ? half : 0), cy = y + ((o & 2) ? half : 0), cz = z + ((o & 4) ? half : 0);
      if ((n.full >> o) & 1u) fill(cx, cy, cz, half);
      else self(self, nodes_[n.child(o)], cx, cy, cz, half);
    }
  };
  if (root_ == Root::full) fill(0, 0, 0, domain_.resolution);
  if (root_ == Root::interior) walk(walk, nodes_.back(), 0, 0, 0, domain_.resolution);
  return g;
}

}  // namespace accelviz
