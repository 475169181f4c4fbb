#include "ui/render/box_selection.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace accelviz {
namespace {

// Calls visit(node, depth, in_subtree) for every node reachable from the
// root, depth first. A valid tree reaches each node once, so more visits
// than nodes means a cycle; every child index is range-checked.
template <class Visit>
void walk(std::span<const BvhNode> nodes, std::uint32_t subtree_root, Visit&& visit) {
  if (nodes.empty()) return;
  struct Entry {
    std::uint32_t node, depth;
    bool in_subtree;
  };
  std::vector<Entry> stack{{0, 0, subtree_root == 0}};
  std::size_t visits = 0;
  while (!stack.empty()) {
    const Entry e = stack.back();
    stack.pop_back();
    if (++visits > nodes.size()) {
      throw std::invalid_argument("BVH node array has a cycle (reached node " + std::to_string(e.node) +
                                  " after visiting every node once)");
    }
    const BvhNode& n = nodes[e.node];
    visit(e.node, e.depth, e.in_subtree);
    if (n.count != 0) continue;
    if (static_cast<std::size_t>(n.index) + 1 >= nodes.size()) {
      throw std::invalid_argument("BVH node " + std::to_string(e.node) + " has children " + std::to_string(n.index) +
                                  "," + std::to_string(static_cast<std::uint64_t>(n.index) + 1) + " beyond the " +
                                  std::to_string(nodes.size()) + " nodes");
    }
    // Push the second child first so that `index` is visited first.
    for (std::uint32_t c : {n.index + 1, n.index}) {
      stack.push_back({c, e.depth + 1, e.in_subtree || c == subtree_root});
    }
  }
}

}  // namespace

std::vector<SelectedBox> select_bvh_boxes(std::span<const BvhNode> nodes, const BoxSelection& sel) {
  std::vector<SelectedBox> out;
  if (nodes.empty()) return out;
  if (sel.mode == BoxSelection::Mode::subtree && sel.node >= nodes.size()) {
    throw std::invalid_argument("subtree root " + std::to_string(sel.node) + " is not one of the " +
                                std::to_string(nodes.size()) + " BVH nodes");
  }
  const std::uint32_t subtree_root = sel.mode == BoxSelection::Mode::subtree ? sel.node : 0;
  walk(nodes, subtree_root, [&](std::uint32_t i, std::uint32_t depth, bool in_subtree) {
    const BvhNode& n = nodes[i];
    bool take = false;
    switch (sel.mode) {
      case BoxSelection::Mode::depth:
        take = depth == sel.depth;
        break;
      case BoxSelection::Mode::depth_range:
        take = depth >= sel.depth && depth <= sel.depth_last;
        break;
      case BoxSelection::Mode::leaves:
        take = n.count > 0;
        break;
      case BoxSelection::Mode::subtree:
        take = in_subtree;
        break;
    }
    if (take) out.push_back({n.bounds, i, depth, n.count > 0});
  });
  return out;
}

std::uint32_t bvh_max_depth(std::span<const BvhNode> nodes) {
  std::uint32_t deepest = 0;
  walk(nodes, 0, [&](std::uint32_t, std::uint32_t depth, bool) { deepest = std::max(deepest, depth); });
  return deepest;
}

glm::vec3 qualitative_color(std::uint32_t i) {
  // Tol "bright": blue, red, green, yellow, cyan, purple, grey.
  static constexpr glm::vec3 kBright[] = {
      {0x44 / 255.0f, 0x77 / 255.0f, 0xAA / 255.0f}, {0xEE / 255.0f, 0x66 / 255.0f, 0x77 / 255.0f},
      {0x22 / 255.0f, 0x88 / 255.0f, 0x33 / 255.0f}, {0xCC / 255.0f, 0xBB / 255.0f, 0x44 / 255.0f},
      {0x66 / 255.0f, 0xCC / 255.0f, 0xEE / 255.0f}, {0xAA / 255.0f, 0x33 / 255.0f, 0x77 / 255.0f},
      {0xBB / 255.0f, 0xBB / 255.0f, 0xBB / 255.0f},
  };
  return kBright[i % std::size(kBright)];
}

std::vector<ColoredBox> color_boxes(std::span<const SelectedBox> boxes, const BoxColoring& coloring) {
  std::uint32_t lo = UINT32_MAX, hi = 0;
  for (const SelectedBox& b : boxes) {
    lo = std::min(lo, b.depth);
    hi = std::max(hi, b.depth);
  }
  std::vector<ColoredBox> out;
  out.reserve(boxes.size());
  for (const SelectedBox& b : boxes) {
    glm::vec3 c = coloring.color;
    switch (coloring.kind) {
      case BoxColoring::Kind::depth_qualitative:
        c = qualitative_color(b.depth);
        break;
      case BoxColoring::Kind::depth_sequential:
        c = colormap(coloring.map, hi > lo ? static_cast<float>(b.depth - lo) / static_cast<float>(hi - lo) : 0.0f);
        break;
      case BoxColoring::Kind::uniform:
        break;
    }
    out.push_back({b.bounds, glm::vec4(c, coloring.alpha)});
  }
  return out;
}

std::vector<ColoredBox> fade_boxes(std::span<const Aabb> boxes, const glm::vec4& first, const glm::vec4& last) {
  std::vector<ColoredBox> out;
  out.reserve(boxes.size());
  const float steps = boxes.size() > 1 ? static_cast<float>(boxes.size() - 1) : 1.0f;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    out.push_back({boxes[i], glm::mix(first, last, static_cast<float>(i) / steps)});
  }
  return out;
}

}  // namespace accelviz
