#pragma once
// Which boxes of a BVH to draw, and in which colours. Pure functions over
// the flat node array (no GL), so the GUI can re-select when a slider moves
// and the tests can check selections without a context.
#include "core/accel/bvh/bvh.h"
#include "core/analysis/colormap.h"
#include "core/math/aabb.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace accelviz {

/// One box overlay entry. Exactly the per-instance vertex layout of
/// shaders/box.vert (lo, hi, rgba), so a list uploads without conversion.
struct ColoredBox {
  Aabb box;
  glm::vec4 color{1.0f};
};
static_assert(sizeof(ColoredBox) == 40, "ColoredBox is uploaded as is: lo(12) hi(12) rgba(16)");

struct BoxSelection {
  enum class Mode {
    depth,        ///< every node at depth `depth` (root = 0)
    depth_range,  ///< every node with depth in [depth, depth_last]
    leaves,       ///< every leaf
    subtree,      ///< node `node` and all its descendants
  };
  Mode mode = Mode::depth;
  std::uint32_t depth = 0;       ///< depth, depth_range: (first) depth
  std::uint32_t depth_last = 0;  ///< depth_range: last depth, inclusive
  std::uint32_t node = 0;        ///< subtree: its root's index
};

struct SelectedBox {
  Aabb bounds;
  std::uint32_t node = 0;   ///< index in the node array
  std::uint32_t depth = 0;  ///< root = 0
  bool leaf = false;
};

/// The selected nodes in depth-first order (parent before children, child
/// `index` before `index + 1`). Throws std::invalid_argument naming the node
/// when the array is malformed (a child index out of range, or a cycle), and
/// for a subtree root out of range. An empty array selects nothing.
std::vector<SelectedBox> select_bvh_boxes(std::span<const BvhNode> nodes, const BoxSelection& selection);

/// The deepest depth in the tree (0 for a lone root; 0 for an empty array).
std::uint32_t bvh_max_depth(std::span<const BvhNode> nodes);

/// Paul Tol's "bright" qualitative scheme (colour-blind safe, 7 colours,
/// https://personal.sron.nl/~pault/), cycled: neighbouring depths always differ.
glm::vec3 qualitative_color(std::uint32_t i);

struct BoxColoring {
  enum class Kind {
    depth_qualitative,  ///< one qualitative colour per depth
    depth_sequential,   ///< depth mapped through `map`, shallow to deep over [min depth, max depth] of the selection
    uniform,            ///< `color` for every box
  };
  Kind kind = Kind::depth_qualitative;
  ColorMap map = ColorMap::viridis;   ///< depth_sequential
  glm::vec3 color{1.0f, 0.8f, 0.2f};  ///< uniform
  float alpha = 1.0f;                 ///< every box's opacity
};

/// Colours a selection for the box pass.
std::vector<ColoredBox> color_boxes(std::span<const SelectedBox> boxes, const BoxColoring& coloring);

/// Boxes in visiting order (e.g. the nodes a ray entered), coloured from
/// `first` to `last` by position in the list, so the order reads as a fade.
std::vector<ColoredBox> fade_boxes(std::span<const Aabb> boxes, const glm::vec4& first, const glm::vec4& last);

}  // namespace accelviz
