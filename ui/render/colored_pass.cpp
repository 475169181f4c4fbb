#include "ui/render/colored_pass.h"

#include <cstddef>

namespace accelviz {

void ColoredGeometry::add_line(const glm::vec3& a, const glm::vec3& b, const glm::vec4& color) {
  lines.push_back({a, color});
  lines.push_back({b, color});
}

void ColoredGeometry::add_quad(const TranslucentQuad& q) {
  for (int i : {0, 1, 2, 0, 2, 3}) triangles.push_back({q.corners[i], q.fill});
  if (q.outline.w > 0.0f) {
    for (int i = 0; i < 4; ++i) add_line(q.corners[i], q.corners[(i + 1) % 4], q.outline);
  }
}

ColoredPass::ColoredPass()
    : vao_(GlObject::create(GlObject::Kind::vertex_array)), vbo_(GlObject::create(GlObject::Kind::buffer)) {
  const GLuint vao = vao_.id();
  glVertexArrayVertexBuffer(vao, 0, vbo_.id(), 0, sizeof(ColoredVertex));
  glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, offsetof(ColoredVertex, position));
  glVertexArrayAttribFormat(vao, 1, 4, GL_FLOAT, GL_FALSE, offsetof(ColoredVertex, color));
  for (GLuint a : {0u, 1u}) {
    glVertexArrayAttribBinding(vao, a, 0);
    glEnableVertexArrayAttrib(vao, a);
  }
}

void ColoredPass::upload(const ColoredGeometry& g) {
  std::vector<ColoredVertex> all;
  all.reserve(g.lines.size() + g.points.size() + g.triangles.size());
  all.insert(all.end(), g.lines.begin(), g.lines.end());
  all.insert(all.end(), g.points.begin(), g.points.end());
  all.insert(all.end(), g.triangles.begin(), g.triangles.end());
  bounds_ = Aabb::empty();
  for (const ColoredVertex& v : all) bounds_.extend(v.position);
  glNamedBufferData(vbo_.id(), static_cast<GLsizeiptr>(all.size() * sizeof(ColoredVertex)), all.data(),
                    GL_DYNAMIC_DRAW);
  lines_ = static_cast<GLsizei>(g.lines.size());
  points_ = static_cast<GLsizei>(g.points.size());
  triangles_ = static_cast<GLsizei>(g.triangles.size());
  check_gl_errors("coloured geometry upload");
}

void ColoredPass::draw(const ShaderProgram& program, const CameraMatrices& m, const DrawOptions& o) const {
  if (empty()) return;
  program.use();
  program.set("u_view_proj", m.view_projection);
  program.set("u_point_size", o.point_px);
  glBindVertexArray(vao_.id());
  if (!o.depth_test) glDisable(GL_DEPTH_TEST);
  if (!o.depth_write) glDepthMask(GL_FALSE);
  // Surfaces first, so that lines (outlines, paths) are drawn over them.
  if (triangles_ > 0) glDrawArrays(GL_TRIANGLES, lines_ + points_, triangles_);
  if (lines_ > 0) glDrawArrays(GL_LINES, 0, lines_);
  if (points_ > 0) glDrawArrays(GL_POINTS, lines_, points_);
  if (!o.depth_write) glDepthMask(GL_TRUE);
  if (!o.depth_test) glEnable(GL_DEPTH_TEST);
}

}  // namespace accelviz
