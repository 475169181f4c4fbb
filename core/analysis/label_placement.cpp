#include "core/analysis/label_placement.h"

#include <numeric>

namespace accelviz {

std::vector<std::optional<LabelRect>> place_point_labels(std::span<const LabelRequest> requests,
                                                         const LabelLayout& layout,
                                                         std::span<const std::size_t> priority) {
  std::vector<std::optional<LabelRect>> out(requests.size());
  std::vector<std::size_t> order(priority.begin(), priority.end());
  if (order.empty()) {
    order.resize(requests.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
  }
  const float m = layout.marker;
  std::vector<LabelRect> blocked(layout.taken.begin(), layout.taken.end());
  std::vector<LabelRect> markers;
  for (const LabelRequest& r : requests) markers.push_back({r.x - m, r.y - m, r.x + m, r.y + m});
  for (const std::size_t i : order) {
    if (i >= requests.size() || out[i]) continue;
    const LabelRequest& r = requests[i];
    if (!(r.w > 0.0f) || !(r.h > 0.0f)) continue;
    const float d = m + layout.gap;
    const float right = r.x + d, left = r.x - d - r.w, above = r.y - d - r.h, below = r.y + d;
    const float middle = r.y - 0.5f * r.h, centre = r.x - 0.5f * r.w;
    for (const auto& [x, y] : {std::pair{right, above}, {right, below}, {left, above}, {left, below}, {right, middle},
                               {left, middle}, {centre, above}, {centre, below}}) {
      const LabelRect box{x, y, x + r.w, y + r.h};
      if (!box.inside(layout.bounds)) continue;
      bool free = true;
      for (const LabelRect& b : blocked) free = free && !box.overlaps(b);
      for (std::size_t k = 0; k < markers.size() && free; ++k) free = k == i || !box.overlaps(markers[k]);
      if (!free) continue;
      out[i] = box;
      blocked.push_back(box);
      break;
    }
  }
  return out;
}

}  // namespace accelviz
