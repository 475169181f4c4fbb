#include "ui/render/box_pass.h"

#include <cstddef>
#include <vector>

namespace accelviz {

BoxPass::BoxPass()
    : vao_(GlObject::create(GlObject::Kind::vertex_array)),
      cube_edges_(GlObject::create(GlObject::Kind::buffer)),
      instances_(GlObject::create(GlObject::Kind::buffer)) {
  // The 12 edges of the unit cube: 4 along each axis.
  std::vector<glm::vec3> edges;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int k = 0; k < 4; ++k) {
      glm::vec3 a(0.0f);
      a[u] = static_cast<float>(k & 1);
      a[v] = static_cast<float>((k >> 1) & 1);
      glm::vec3 b = a;
      b[axis] = 1.0f;
      edges.push_back(a);
      edges.push_back(b);
    }
  }
  glNamedBufferStorage(cube_edges_.id(), static_cast<GLsizeiptr>(edges.size() * sizeof(glm::vec3)), edges.data(), 0);

  const GLuint vao = vao_.id();
  glVertexArrayVertexBuffer(vao, 0, cube_edges_.id(), 0, sizeof(glm::vec3));
  glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(vao, 0, 0);
  glEnableVertexArrayAttrib(vao, 0);

  glVertexArrayVertexBuffer(vao, 1, instances_.id(), 0, sizeof(ColoredBox));
  glVertexArrayBindingDivisor(vao, 1, 1);
  glVertexArrayAttribFormat(vao, 1, 3, GL_FLOAT, GL_FALSE, offsetof(ColoredBox, box) + offsetof(Aabb, lo));
  glVertexArrayAttribFormat(vao, 2, 3, GL_FLOAT, GL_FALSE, offsetof(ColoredBox, box) + offsetof(Aabb, hi));
  glVertexArrayAttribFormat(vao, 3, 4, GL_FLOAT, GL_FALSE, offsetof(ColoredBox, color));
  for (GLuint a : {1u, 2u, 3u}) {
    glVertexArrayAttribBinding(vao, a, 1);
    glEnableVertexArrayAttrib(vao, a);
  }
  check_gl_errors("box pass setup");
}

void BoxPass::upload(std::span<const ColoredBox> boxes) {
  std::vector<ColoredBox> kept;
  kept.reserve(boxes.size());
  bounds_ = Aabb::empty();
  for (const ColoredBox& b : boxes) {
    if (b.box.is_empty()) continue;
    kept.push_back(b);
    bounds_.extend(b.box);
  }
  glNamedBufferData(instances_.id(), static_cast<GLsizeiptr>(kept.size() * sizeof(ColoredBox)), kept.data(),
                    GL_DYNAMIC_DRAW);
  count_ = kept.size();
  check_gl_errors("box upload");
}

void BoxPass::draw(const ShaderProgram& program, const CameraMatrices& m, bool depth_test) const {
  if (count_ == 0) return;
  program.use();
  program.set("u_view_proj", m.view_projection);
  glBindVertexArray(vao_.id());
  if (!depth_test) glDisable(GL_DEPTH_TEST);
  glDrawArraysInstanced(GL_LINES, 0, 24, static_cast<GLsizei>(count_));
  if (!depth_test) glEnable(GL_DEPTH_TEST);
}

}  // namespace accelviz
