#pragma once
// Per-pixel metric images on screen: the values as an R32F texture, mapped
// through a 256-entry colour-map texture in the fragment shader, either over
// the whole viewport or blended over the mesh.
#include "core/analysis/colormap.h"
#include "core/analysis/heatmap.h"
#include "ui/gl/gl_object.h"
#include "ui/gl/shader.h"

#include <glm/glm.hpp>

#include <span>

namespace accelviz {

/// The colour-map table a LUT texture holds: `map` sampled at i/255 for
/// i = 0..255. For the published tables this is exactly their 256 entries,
/// so linear filtering in the shader reproduces colormap() (which
/// interpolates linearly between entries).
std::vector<glm::vec3> colormap_lut(ColorMap map);

class HeatmapPass {
 public:
  HeatmapPass();

  /// Replaces the image (values row-major from the top row; NaN = no value).
  void upload(const MetricImage& image);
  bool has_image() const { return width_ > 0; }
  int width() const { return width_; }
  int height() const { return height_; }
  HeatMetric metric() const { return metric_; }
  /// Top of the automatic scale: the image's maximum, 1 for an all-zero
  /// image (core's heatmap_scale_max, so GL and CPU heatmaps agree).
  float auto_max() const { return heatmap_scale_max(values_range_, 0.0f); }
  /// The image's smallest and largest value (a locked range may leave some
  /// outside: they are drawn in its end colours).
  ValueRange value_range() const { return values_range_; }

  /// Replaces the colour map: exactly 256 entries (throws std::invalid_argument otherwise).
  void set_lut(std::span<const glm::vec3> lut);
  /// The texture legends sample: the user LUT, or the grey ramp for the shaded metric.
  GLuint lut_texture() const;

  /// Full-viewport triangle: value v is drawn as lut((v - range.x) / (range.y - range.x))
  /// with alpha `opacity`.
  void draw(const ShaderProgram& program, const glm::vec2& range, float opacity) const;

 private:
  GlObject vao_;  // empty: the full-screen triangle comes from gl_VertexID
  GlObject values_;
  GlObject lut_;
  GlObject grey_lut_;
  int width_ = 0;
  int height_ = 0;
  HeatMetric metric_ = HeatMetric::nodes;
  ValueRange values_range_;
};

}  // namespace accelviz
