#pragma once
// GL-free helpers for the insight views in the 3D view: node boxes coloured
// by hot-node visits, the labels of the selected and hottest nodes (and
// where they project on screen), the leaf a clicked ray's hit lies in, and
// mapping a rectangle of the 3D view onto the insight record's pixels.
#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/accel/accel.h"
#include "core/analysis/colormap.h"
#include "core/analysis/insight/visit_attribution.h"
#include "core/geometry/hit.h"
#include "core/query/camera.h"
#include "ui/app/structure_nodes.h"

namespace accelviz {

/// Where a visit count falls on the colour ramp: log(1 + v) / log(1 + max),
/// so counts spanning orders of magnitude (the root against a leaf) stay
/// apart; 0 for max == 0. Monotone; `visits == max` gives 1.
float visit_ramp(std::uint64_t visits, std::uint64_t max);

/// The largest visit count among `boxes` (ids past `visits` count as 0): the
/// count that visit_colors() puts at the top of the ramp.
std::uint64_t max_visit_count(std::span<const NodeBox> boxes, std::span<const std::uint64_t> visits);

/// One colour per box (same order), from its node's visit count through
/// `map` (core/analysis/colormap.h) on visit_ramp() over max_visit_count():
/// the hottest box gets colormap(map, 1), unvisited ones colormap(map, 0).
/// Ids past `visits` count as 0.
std::vector<glm::vec4> visit_colors(std::span<const NodeBox> boxes, std::span<const std::uint64_t> visits,
                                    ColorMap map);

struct NodeLabel {
  std::uint32_t node = 0;
  glm::vec3 anchor{0.0f};  ///< world space: the top (max y) centre of the node's box
  std::string text;        ///< "#12 d3 p8 v340": id, depth, primitives (leaves; inner: under it), visits
  bool selected = false;
};
/// Labels for `selected` (first, when it is a node) and the first `top_n`
/// of `hot` (skipping the selected one). Unknown ids are left out.
std::vector<NodeLabel> node_labels(const StructureNodes& nodes, std::span<const std::uint64_t> visits,
                                   std::span<const HotNode> hot, std::size_t top_n,
                                   std::optional<std::uint32_t> selected);

/// The pixel (continuous, row 0 at the top, as primary_ray() uses) where the
/// world point `p` appears in a width × height image of `cam`; empty behind
/// the camera. primary_ray(cam, x, y, ...) at any t > 0 projects to (x + 0.5, y + 0.5).
std::optional<glm::vec2> project_to_pixel(const Camera& cam, const glm::vec3& p, int width, int height);

/// The leaf the traced ray's closest hit was found in: the last node entered
/// before the last prim_hit step of `hit.prim`; for a grid, the last cell the
/// walk entered (a 3D-DDA ends in the cell that holds its closest hit, while
/// the hit's triangle may have been tested in an earlier cell it overlaps).
/// Empty on a miss, when the trace has no prim_hit step of `hit.prim`, or when
/// that node is not a leaf (a cell) of `nodes`.
std::optional<std::uint32_t> hit_leaf(const VisitTrace& trace, const Hit& hit, const StructureNodes& nodes);

/// The nodes from the root down to `node` (inclusive); empty for an unknown id.
std::vector<std::uint32_t> path_to(const StructureNodes& nodes, std::uint32_t node);

struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  ///< [x0, x1) × [y0, y1)
  bool empty() const { return x1 <= x0 || y1 <= y0; }
};
/// A rectangle of the view (corners in either order, view_w × view_h
/// pixels) as the record's pixels (rec_w × rec_h over the same camera),
/// rounded outwards and clamped; at least one record pixel when the rectangle
/// overlaps the view.
PixelRect view_rect_to_record(int ax, int ay, int bx, int by, int view_w, int view_h, int rec_w, int rec_h);

}  // namespace accelviz
