#include "ui/render/mesh_pass.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace accelviz {
namespace {
struct MeshVertex {
  glm::vec3 position;
  glm::vec3 normal;
};
}  // namespace

MeshPass::MeshPass()
    : vao_(GlObject::create(GlObject::Kind::vertex_array)),
      vbo_(GlObject::create(GlObject::Kind::buffer)),
      colors_(GlObject::create(GlObject::Kind::buffer)) {
  const GLuint vao = vao_.id();
  glVertexArrayVertexBuffer(vao, 0, vbo_.id(), 0, sizeof(MeshVertex));
  glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, offsetof(MeshVertex, position));
  glVertexArrayAttribFormat(vao, 1, 3, GL_FLOAT, GL_FALSE, offsetof(MeshVertex, normal));
  for (GLuint a : {0u, 1u}) {
    glVertexArrayAttribBinding(vao, a, 0);
    glEnableVertexArrayAttrib(vao, a);
  }
  // Per-vertex colours (attribute 2) from their own buffer; off until upload_colors.
  glVertexArrayVertexBuffer(vao, 1, colors_.id(), 0, 4);
  glVertexArrayAttribFormat(vao, 2, 4, GL_UNSIGNED_BYTE, GL_TRUE, 0);
  glVertexArrayAttribBinding(vao, 2, 1);
}

void MeshPass::upload_colors(std::span<const glm::vec3> per_triangle) {
  if (per_triangle.empty()) {
    glDisableVertexArrayAttrib(vao_.id(), 2);
    has_colors_ = false;
    return;
  }
  if (per_triangle.size() != triangle_count_)
    throw std::invalid_argument("mesh colours: " + std::to_string(per_triangle.size()) + " colours for " +
                                std::to_string(triangle_count_) + " triangles");
  std::vector<std::uint8_t> rgba;
  rgba.reserve(per_triangle.size() * 12);
  const auto byte = [](float v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); };
  for (const glm::vec3& c : per_triangle)
    for (int v = 0; v < 3; ++v) rgba.insert(rgba.end(), {byte(c.x), byte(c.y), byte(c.z), 255});
  glNamedBufferData(colors_.id(), static_cast<GLsizeiptr>(rgba.size()), rgba.data(), GL_STATIC_DRAW);
  glEnableVertexArrayAttrib(vao_.id(), 2);
  has_colors_ = true;
  check_gl_errors("mesh colour upload");
}

void MeshPass::upload(std::span<const Triangle> triangles) {
  std::vector<MeshVertex> vertices;
  vertices.reserve(triangles.size() * 3);
  bounds_ = Aabb::empty();
  for (const Triangle& t : triangles) {
    const glm::vec3 n = triangle_normal(t);
    for (const glm::vec3& p : {t.v0, t.v1, t.v2}) vertices.push_back({p, n});
    bounds_.extend(t.bounds());
  }
  glNamedBufferData(vbo_.id(), static_cast<GLsizeiptr>(vertices.size() * sizeof(MeshVertex)), vertices.data(),
                    GL_STATIC_DRAW);
  triangle_count_ = triangles.size();
  upload_colors({});  // colours were per triangle of the old mesh
  check_gl_errors("mesh upload");
}

void MeshPass::bind(const ShaderProgram& program, const CameraMatrices& m, const glm::vec4& color, bool shaded,
                    bool vertex_colors) const {
  program.use();
  program.set("u_view_proj", m.view_projection);
  program.set("u_eye", m.eye);
  program.set("u_color", color);
  program.set("u_shaded", shaded ? 1 : 0);
  program.set("u_vertex_colors", vertex_colors && has_colors_ ? 1 : 0);
  glBindVertexArray(vao_.id());
}

void MeshPass::draw_shaded(const ShaderProgram& program, const CameraMatrices& m, const glm::vec4& color) const {
  if (triangle_count_ == 0) return;
  bind(program, m, color, true, true);
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1.0f, 1.0f);
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(triangle_count_ * 3));
  glDisable(GL_POLYGON_OFFSET_FILL);
}

void MeshPass::draw_depth_only(const ShaderProgram& program, const CameraMatrices& m) const {
  if (triangle_count_ == 0) return;
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  draw_shaded(program, m, glm::vec4(0.0f));
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
}

void MeshPass::draw_wireframe(const ShaderProgram& program, const CameraMatrices& m, const glm::vec4& color) const {
  if (triangle_count_ == 0) return;
  bind(program, m, color, false);
  glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(triangle_count_ * 3));
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
}

void MeshPass::draw_primitives(const ShaderProgram& program, const CameraMatrices& m,
                               std::span<const std::uint32_t> ids, const glm::vec4& color) const {
  std::vector<GLint> firsts;
  for (std::uint32_t id : ids) {
    if (id < triangle_count_) firsts.push_back(static_cast<GLint>(id) * 3);
  }
  if (firsts.empty()) return;
  const std::vector<GLsizei> counts(firsts.size(), 3);
  bind(program, m, color, false);
  // The shaded mesh is offset by +1; these are not, so they win where they coincide.
  glMultiDrawArrays(GL_TRIANGLES, firsts.data(), counts.data(), static_cast<GLsizei>(firsts.size()));
}

}  // namespace accelviz
