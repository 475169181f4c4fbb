#pragma once
// The nodes of any structure as boxes: one table per build, made on the
// build worker, that the 3D view selects from (one depth, a depth range,
// the leaves, a subtree) and that the ray inspector uses to turn a
// VisitTrace's node ids into boxes. BVH, K-D tree and octree nodes, the
// voxel octree's interior nodes and full blocks, the grid's cells; brute
// force and Embree have none.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/accel/accel.h"
#include "core/math/aabb.h"
#include "ui/app/app_config.h"

namespace accelviz {

struct StructureNode {
  Aabb bounds;
  std::uint32_t depth = 0;
  std::uint32_t parent = 0xFFFFFFFFu;  ///< none for the root
  std::uint32_t prims = 0;             ///< leaves: primitives referenced
  /// Primitives referenced by the leaves below (a leaf: its prims; one in two leaves counts twice).
  std::uint64_t prims_below = 0;
  bool leaf = false;
  float sah_share = 0.0f;                ///< this node's part of the SAH cost, all nodes summing to 1
  std::uint32_t instance = 0xFFFFFFFFu;  ///< two-level: the instance whose world box this leaf is (none otherwise)
};

/// Which nodes to show (ViewSettings' box_* fields).
struct NodeSelection {
  BoxMode mode = BoxMode::depth;
  std::uint32_t depth = 0;
  std::uint32_t depth_last = 0;
  std::uint32_t node = 0;
};

struct NodeBox {
  Aabb bounds;
  std::uint32_t id = 0;
  std::uint32_t depth = 0;
  bool leaf = false;
  float sah_share = 0.0f;
  std::uint32_t instance = 0xFFFFFFFFu;  ///< two-level: the instance the box belongs to (none otherwise)
};

class StructureNodes {
 public:
  StructureNodes() = default;
  /// The table of `accel` (BVH, K-D tree, octree, voxels, grid, two-level: TLAS nodes, then one leaf
  /// per instance under its TLAS leaf; empty for the others).
  static StructureNodes of(const Accelerator& accel);

  /// "bvh", "kdtree", "octree", "voxels", "grid", "tlas", or "" when the structure has no nodes to show.
  const std::string& kind() const { return kind_; }
  bool empty() const { return nodes_.empty() && !grid_; }
  /// Nodes in the table (for a grid: its cells).
  std::uint64_t size() const;
  std::uint32_t max_depth() const { return max_depth_; }

  /// The box of the node (cell) a VisitTrace names; empty for an unknown id.
  std::optional<Aabb> box(std::uint32_t id) const;
  /// A tree node (not for grids); null for an unknown id.
  const StructureNode* node(std::uint32_t id) const { return id < nodes_.size() ? &nodes_[id] : nullptr; }

  struct Selection {
    std::vector<NodeBox> boxes;  ///< parent before children
    bool truncated = false;      ///< more matched than `limit`
    std::uint64_t matched = 0;   ///< how many matched
  };
  /// The nodes `sel` names, at most `limit` of them: when more match, `limit`
  /// of them spread evenly over the selection's order (parents still before
  /// their children), so the overlay thins the whole structure out. A grid's
  /// cells are depth 1 under its bounding box (depth 0); every mode but depth
  /// 0 shows its non-empty cells (subtree: the one cell).
  Selection select(const NodeSelection& sel, std::size_t limit) const;

  /// The children of a tree node, in id order.
  std::span<const std::uint32_t> children(std::uint32_t id) const;

  /// What id names in this table, one line for the View panel's subtree
  /// mode: "node 57: depth 4, 2 children, 1234 primitives below", "node 9:
  /// a leaf at depth 6, 12 primitives", "cell 57 (x 3, y 1, z 0): 12
  /// primitives", "no node 5000: this bvh has nodes 0-4094".
  std::string describe(std::uint32_t id) const;

 private:
  void finish(float c_trav, float c_isect);
  /// Calls add(box) for every node `sel` names, parents before children.
  template <class F>
  void for_each_selected(const NodeSelection& sel, F&& add) const;

  std::string kind_;
  std::vector<StructureNode> nodes_;
  std::vector<std::uint32_t> child_start_;  ///< CSR over children_, by parent id
  std::vector<std::uint32_t> children_;
  std::uint32_t max_depth_ = 0;

  struct GridCells {
    std::array<int, 3> res{1, 1, 1};
    std::array<std::vector<float>, 3> planes;  ///< res + 1 boundaries per axis, as Grid::plane gives them
    std::vector<std::uint32_t> counts;         ///< triangles per cell
    Aabb bounds;
  };
  std::optional<GridCells> grid_;
};

class Tlas;

/// The bottom-level boxes of a two-level structure in world space: for
/// every instance (or only instance INSTANCE when it is >= 0), the nodes SEL
/// names in its BLAS (depths counted from the BLAS root; subtree: a BLAS
/// node id), each box's eight corners carried to world space by the
/// instance's transform (the box of those corners). Every box keeps its
/// BLAS node id, depth and SAH share and names its instance. Instances are
/// taken in id order and whole: when the next instance's boxes would pass
/// LIMIT, the list stops there (`truncated`; the first instance alone is cut
/// at LIMIT); `matched` counts every instance's. An INSTANCE out of range
/// selects nothing.
StructureNodes::Selection select_blas_boxes(const Tlas& tlas, const NodeSelection& sel, std::size_t limit,
                                            int instance = -1);

/// The deepest BLAS node depth of a two-level structure (the blas level's depth range).
std::uint32_t blas_max_depth(const Tlas& tlas);

}  // namespace accelviz
