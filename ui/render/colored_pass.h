#pragma once
// Coloured world-space geometry in three ranges of one buffer: lines,
// points (drawn as squares of a given pixel size) and triangles. The ray
// path uses lines and points; translucent quads use triangles and lines.
#include "ui/gl/gl_object.h"
#include "ui/gl/shader.h"
#include "ui/render/camera_view.h"
#include "ui/render/overlays.h"

#include <span>
#include <vector>

namespace accelviz {

struct ColoredGeometry {
  std::vector<ColoredVertex> lines;  ///< pairs
  std::vector<ColoredVertex> points;
  std::vector<ColoredVertex> triangles;  ///< triples

  bool empty() const { return lines.empty() && points.empty() && triangles.empty(); }
  void add_line(const glm::vec3& a, const glm::vec3& b, const glm::vec4& color);
  /// Two triangles and, when outline.w > 0, four edges.
  void add_quad(const TranslucentQuad& quad);
};

class ColoredPass {
 public:
  ColoredPass();
  void upload(const ColoredGeometry& geometry);
  bool empty() const { return lines_ + points_ + triangles_ == 0; }
  const Aabb& bounds() const { return bounds_; }

  struct DrawOptions {
    bool depth_test = true;
    bool depth_write = true;  ///< false for translucent surfaces
    float point_px = 7.0f;
  };
  void draw(const ShaderProgram& program, const CameraMatrices& m, const DrawOptions& options) const;

 private:
  GlObject vao_;
  GlObject vbo_;
  GLsizei lines_ = 0, points_ = 0, triangles_ = 0;
  Aabb bounds_;
};

}  // namespace accelviz
