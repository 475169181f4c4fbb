#pragma once
// The colour legend of a heatmap, drawn by GL into the frame (so screenshots
// contain it): a panel at the right edge with the metric's title, a vertical
// gradient bar through the same LUT texture the heatmap uses, five ticks and
// their numbers. Text uses the project's 5×7 bitmap font (core/analysis/
// heatmap.h draw_text), rasterised once into a glyph-atlas texture, so the
// GL legend and the CPU-written heatmap PNGs use the same glyphs and the
// same number format (format_tick).
#include "ui/gl/gl_object.h"
#include "ui/gl/shader.h"

#include <glm/glm.hpp>

#include <string>
#include <string_view>
#include <vector>

namespace accelviz {

/// Where everything of a legend goes, in image pixels (origin top-left, y
/// down; rectangles are [x0, x1) × [y0, y1)).
struct LegendLayout {
  struct Rect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  };
  struct Label {
    std::string text;
    int x = 0, y = 0;  ///< top-left corner of the first glyph
  };
  bool visible = false;  ///< false when the viewport is too small for it
  int scale = 1;         ///< glyph scale: 2 when the image is at least 480 pixels wide or tall
  Rect panel;
  Rect bar;  ///< bottom row shows the range's low end, top row the high end
  std::vector<Rect> ticks;
  std::vector<Label> labels;  ///< title first, then the tick numbers from low to high
};

/// Lays out a legend for `range` (low, high) in a width × height viewport;
/// `above_top`: the image has values above the range, and the top number
/// says so ("20+", core's legend_labels); `below_bottom`: values below it,
/// and the bottom number says so ("<=5").
LegendLayout layout_legend(int width, int height, const glm::vec2& range, std::string_view title, bool whole = false,
                           bool above_top = false, bool below_bottom = false);

class LegendPass {
 public:
  LegendPass();
  void draw(const ShaderProgram& program, const LegendLayout& layout, GLuint lut_texture, int width, int height) const;

 private:
  GlObject vao_;
  GlObject vbo_;
  GlObject font_;
};

}  // namespace accelviz
