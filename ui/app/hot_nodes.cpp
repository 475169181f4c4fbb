#include "ui/app/hot_nodes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace accelviz {

float visit_ramp(std::uint64_t visits, std::uint64_t max) {
  if (max == 0) return 0.0f;
  const double t = std::log1p(static_cast<double>(std::min(visits, max))) / std::log1p(static_cast<double>(max));
  return static_cast<float>(std::clamp(t, 0.0, 1.0));
}

namespace {
std::uint64_t visit_count(std::span<const std::uint64_t> visits, std::uint32_t id) {
  return id < visits.size() ? visits[id] : std::uint64_t{0};
}
}  // namespace

std::uint64_t max_visit_count(std::span<const NodeBox> boxes, std::span<const std::uint64_t> visits) {
  std::uint64_t max = 0;
  for (const NodeBox& b : boxes) max = std::max(max, visit_count(visits, b.id));
  return max;
}

std::vector<glm::vec4> visit_colors(std::span<const NodeBox> boxes, std::span<const std::uint64_t> visits,
                                    ColorMap map) {
  const std::uint64_t max = max_visit_count(boxes, visits);
  std::vector<glm::vec4> out;
  out.reserve(boxes.size());
  for (const NodeBox& b : boxes) out.emplace_back(colormap(map, visit_ramp(visit_count(visits, b.id), max)), 1.0f);
  return out;
}

std::vector<NodeLabel> node_labels(const StructureNodes& nodes, std::span<const std::uint64_t> visits,
                                   std::span<const HotNode> hot, std::size_t top_n,
                                   std::optional<std::uint32_t> selected) {
  std::vector<NodeLabel> out;
  const auto add = [&](std::uint32_t id, bool is_selected) {
    const StructureNode* n = nodes.node(id);
    if (!n || n->bounds.is_empty()) return;
    NodeLabel l;
    l.node = id;
    l.selected = is_selected;
    const glm::vec3 c = n->bounds.center();
    l.anchor = glm::vec3(c.x, n->bounds.hi.y, c.z);
    char text[96];
    std::snprintf(text, sizeof text, "#%u d%u p%llu v%llu", id, n->depth,
                  static_cast<unsigned long long>(n->prims_below),
                  static_cast<unsigned long long>(id < visits.size() ? visits[id] : 0));
    l.text = text;
    out.push_back(std::move(l));
  };
  if (selected) add(*selected, true);
  std::size_t taken = 0;
  for (const HotNode& h : hot) {
    if (taken >= top_n) break;
    if (selected && h.node == *selected) continue;
    add(h.node, false);
    ++taken;
  }
  return out;
}

std::optional<glm::vec2> project_to_pixel(const Camera& cam, const glm::vec3& p, int width, int height) {
  if (width <= 0 || height <= 0) return std::nullopt;
  const glm::vec3 d = p - cam.position;
  const float z = glm::dot(d, cam.forward);
  if (!(z > 0.0f)) return std::nullopt;
  const float tan_half = std::tan(0.5f * cam.yfov);
  const float aspect = camera_aspect(cam, width, height);
  const glm::vec3 right = glm::cross(cam.forward, cam.up);
  const float sx = glm::dot(d, right) / (z * tan_half * aspect);
  const float sy = glm::dot(d, cam.up) / (z * tan_half);
  // camera_ray: sx = (2u - 1), sy = (1 - 2v); u = x / width.
  return glm::vec2(0.5f * (sx + 1.0f) * static_cast<float>(width), 0.5f * (1.0f - sy) * static_cast<float>(height));
}

std::optional<std::uint32_t> hit_leaf(const VisitTrace& trace, const Hit& hit, const StructureNodes& nodes) {
  if (!hit.valid()) return std::nullopt;
  std::optional<std::uint32_t> last_entered, found;
  for (const VisitStep& s : trace.steps) {
    if (s.kind == VisitStep::Kind::node_entered) last_entered = s.id;
    if (s.kind == VisitStep::Kind::prim_hit && s.id == hit.prim && last_entered) found = last_entered;
  }
  if (!found) return std::nullopt;
  if (nodes.kind() == "grid") {  // cells have boxes but no node entries
    if (!nodes.box(*last_entered)) return std::nullopt;
    return last_entered;
  }
  const StructureNode* n = nodes.node(*found);
  if (!n || !n->leaf) return std::nullopt;
  return found;
}

std::vector<std::uint32_t> path_to(const StructureNodes& nodes, std::uint32_t node) {
  std::vector<std::uint32_t> path;
  std::uint32_t id = node;
  for (std::size_t guard = 0; guard <= nodes.max_depth() + 1; ++guard) {
    const StructureNode* n = nodes.node(id);
    if (!n) return {};
    path.push_back(id);
    if (n->parent == 0xFFFFFFFFu) {
      std::reverse(path.begin(), path.end());
      return path;
    }
    id = n->parent;
  }
  return {};  // a cycle: not a tree
}

PixelRect view_rect_to_record(int ax, int ay, int bx, int by, int view_w, int view_h, int rec_w, int rec_h) {
  PixelRect r;
  if (view_w <= 0 || view_h <= 0 || rec_w <= 0 || rec_h <= 0) return r;
  const int vx0 = std::clamp(std::min(ax, bx), 0, view_w), vx1 = std::clamp(std::max(ax, bx), 0, view_w);
  const int vy0 = std::clamp(std::min(ay, by), 0, view_h), vy1 = std::clamp(std::max(ay, by), 0, view_h);
  if (vx1 <= vx0 && vy1 <= vy0) return r;
  const auto lo = [](int v, int from, int to) { return static_cast<int>(static_cast<long long>(v) * to / from); };
  const auto hi = [](int v, int from, int to) {
    return static_cast<int>((static_cast<long long>(v) * to + from - 1) / from);
  };
  r.x0 = lo(vx0, view_w, rec_w);
  r.y0 = lo(vy0, view_h, rec_h);
  r.x1 = std::clamp(std::max(hi(vx1, view_w, rec_w), r.x0 + 1), 0, rec_w);
  r.y1 = std::clamp(std::max(hi(vy1, view_h, rec_h), r.y0 + 1), 0, rec_h);
  if (r.x0 >= rec_w || r.y0 >= rec_h) return PixelRect{};
  return r;
}

}  // namespace accelviz
