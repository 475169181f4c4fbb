#pragma once
// Small CPU chart renderer for the sweep and refit outputs: axes with ticks
// and numbers, points, polylines and labelled points, drawn into an RgbImage
// with the heatmap legend's 5×7 bitmap font, so results need no plotting
// tool to be read. Text is lower-cased on drawing (the font has lowercase
// letters, digits, M and a few signs only).
#include "core/analysis/heatmap.h"

#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace accelviz {

struct ChartSeries {
  std::string name;                 ///< legend entry (empty: none)
  std::vector<double> x, y;         ///< same size; non-finite points are skipped
  /// Optional, one per point, drawn beside it where it covers no other label,
  /// point or the legend (label_placement.h; the last series' labels placed
  /// first), else left out.
  std::vector<std::string> labels;
  glm::u8vec3 color{31, 119, 180};
  bool lines = true;                ///< join consecutive points
  bool points = true;               ///< draw a marker per point
  int marker = 3;                   ///< marker half-size in pixels
};

struct ChartOptions {
  int width = 720;
  int height = 480;
  std::string title;
  std::string x_label;
  std::string y_label;
  bool log_x = false;  ///< logarithmic x axis (values must be > 0)
  bool log_y = false;  ///< logarithmic y axis (values must be > 0)
  bool y_from_zero = true;  ///< linear y axis starts at 0 when all values are positive
  /// When non-empty, the x axis is categorical: ticks at x = 0, 1, ... with these names.
  std::vector<std::string> x_categories;
};

/// About `target` "nice" tick values (1, 2, 5 × 10^k steps) covering [lo, hi].
std::vector<double> nice_ticks(double lo, double hi, int target);

/// Draws the chart. Throws std::invalid_argument for a series whose x and y
/// sizes differ, or a log axis with a non-positive value.
RgbImage draw_chart(const ChartOptions& opts, const std::vector<ChartSeries>& series);

}  // namespace accelviz
