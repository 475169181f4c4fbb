#pragma once
// A 4-wide copy of a binary BVH, used only by the uninstrumented (fast)
// traversal.
//
// Why: single-ray traversal of a binary BVH is latency-bound. Every step
// loads a child pair, runs a slab test and takes a data-dependent branch;
// mispredicted branches cost the whole test latency. Collapsing the tree so
// that each node holds up to four children (Dammertz et al., "Shallow
// Bounding Volume Hierarchies for Fast SIMD Ray Tracing of Incoherent Rays",
// EGSR 2008; Wald et al. 2008; the layout Embree uses) halves the number of
// sequential steps and tests four boxes with one set of SIMD instructions.
//
// The binary node array stays the structure that is built, shown, counted
// and refitted: the statistics/trace path traverses it, and every wide slot
// records the binary node it copies, so a refit updates both. Leaves are the
// binary tree's leaves (the same primitive ranges).
#include <cstdint>
#include <span>
#include <vector>

#include "core/accel/bvh/bvh.h"
#include "core/accel/bvh/bvh_tri4.h"

namespace accelviz::bvh_detail {

/// 128 bytes: four child boxes in structure-of-arrays order, then the
/// children. meta = 0: inner wide node `child`; 1..255: leaf of `meta`
/// primitives starting at leaf position `child`; kWideEmpty: unused slot.
struct alignas(64) WideNode {
  float bounds[6][4];  ///< [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z][slot]
  std::uint32_t child[4];
  std::uint32_t meta[4];
};
static_assert(sizeof(WideNode) == 128);

inline constexpr std::uint32_t kWideEmpty = 0xFFFFFFFFu;

struct WideBvh {
  std::vector<WideNode> nodes;        ///< root at 0; empty when the binary tree is
  std::vector<std::uint32_t> source;  ///< 4 per wide node: the binary node each slot copies (kWideEmpty if unused)
  /// The leaves' triangles as blocks of four (bvh_tri4.h), for the fast
  /// path: once build_tri4_blocks has run, a leaf slot's `child` is the
  /// index of its first block (ceil(meta / 4) consecutive blocks, in the
  /// order the slots are laid out), no longer its first leaf position.
  std::vector<TriBlock4> tri_blocks;
};

/// Fills wide.tri_blocks from the leaf-order triangles and points every
/// leaf slot at its first block (collapse_to_wide's leaf slots name leaf
/// positions; afterwards they name blocks).
void build_tri4_blocks(WideBvh& wide, std::span<const Triangle> leaf_tris);

/// Collapses a binary node array: each wide node takes a binary inner node's
/// children and keeps opening the child with the largest surface area until
/// it has four (or only leaves are left). Deterministic; wide children are
/// stored after their parent.
WideBvh collapse_to_wide(std::span<const BvhNode> binary);

/// Copies the binary boxes into the wide nodes again (after a refit).
void refit_wide(WideBvh& wide, std::span<const BvhNode> binary);

/// Scalar twin of the four-box test: core/math/aabb.h's robust slab test per
/// slot. Bit i of the result: slot i hit; t_entry[i]/t_exit[i] its interval.
int wide_slab_test_scalar(const WideNode& node, const Ray& ray, float tmin, float tmax, float t_entry[4],
                          float t_exit[4]);

}  // namespace accelviz::bvh_detail
