#pragma once
// Labels beside the points of a chart without overlapping each other, the
// points' markers or what else the chart reserves (its legend): each label
// takes the first free spot of eight around its point, in priority order, or
// is left out (the chart's tooltip or table still names the point). Shared by
// the CLI's PNG charts (core/analysis/chart.cpp) and the GUI's Cost of
// accuracy chart (ui/panels/accuracy_panel.cpp).
#include <optional>
#include <span>
#include <vector>

namespace accelviz {

struct LabelRect {
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;  ///< y grows downwards (screen and image rows)
  bool overlaps(const LabelRect& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
  bool inside(const LabelRect& o) const { return x0 >= o.x0 && x1 <= o.x1 && y0 >= o.y0 && y1 <= o.y1; }
};

struct LabelRequest {
  float x = 0, y = 0;  ///< the labelled point
  float w = 0, h = 0;  ///< the label's size
};

struct LabelLayout {
  float gap = 3.0f;                  ///< between the point's marker and its label
  float marker = 3.0f;               ///< markers' half-size: no label covers another label's point
  LabelRect bounds;                  ///< every label stays inside
  std::span<const LabelRect> taken;  ///< already drawn (a legend): no label covers them
};

/// Top-left corners of the labels in `requests`, placed in the order of
/// `priority` (indices into requests; empty: in request order). A label tries
/// right-above, right-below, left-above, left-below of its point, then right
/// and left of it (centred on its row), then centred above and below, and takes
/// the first spot inside the bounds that overlaps no label placed before it,
/// no request's point marker and nothing in `taken`; std::nullopt when none is
/// free. Labels of size 0 are left out.
std::vector<std::optional<LabelRect>> place_point_labels(std::span<const LabelRequest> requests,
                                                         const LabelLayout& layout,
                                                         std::span<const std::size_t> priority = {});

}  // namespace accelviz
