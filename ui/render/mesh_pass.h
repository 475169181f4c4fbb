#pragma once
// The scene's triangles: headlight flat shading, a wireframe overlay, a
// depth-only variant (so overlays stay occluded under a full-screen
// heatmap) and highlighted primitives.
#include "core/geometry/triangle.h"
#include "core/math/aabb.h"
#include "ui/gl/gl_object.h"
#include "ui/gl/shader.h"
#include "ui/render/camera_view.h"

#include <cstdint>
#include <glm/glm.hpp>
#include <span>

namespace accelviz {

class MeshPass {
 public:
  MeshPass();
  /// Replaces the mesh: three vertices per triangle, each with the triangle's
  /// geometric normal (no index buffer, so a primitive id p is vertices 3p..3p+2).
  void upload(std::span<const Triangle> triangles);
  /// One colour per triangle for the shaded mesh instead of the flat mesh
  /// colour (per-instance colours of a two-level view); empty: back to the
  /// flat colour. Throws std::invalid_argument unless there is exactly one
  /// colour per uploaded triangle. upload() clears them.
  void upload_colors(std::span<const glm::vec3> per_triangle);
  bool has_colors() const { return has_colors_; }
  std::size_t triangle_count() const { return triangle_count_; }
  const Aabb& bounds() const { return bounds_; }

  /// Filled and shaded, pushed back slightly in depth so that lines and
  /// highlights drawn on the surface win the depth test.
  void draw_shaded(const ShaderProgram& program, const CameraMatrices& m, const glm::vec4& color) const;
  /// Depth only: fills the depth buffer without touching colour.
  void draw_depth_only(const ShaderProgram& program, const CameraMatrices& m) const;
  /// Triangle edges as lines, in a flat colour.
  void draw_wireframe(const ShaderProgram& program, const CameraMatrices& m, const glm::vec4& color) const;
  /// The listed primitives, filled in a flat colour, in front of the shaded
  /// mesh (ids beyond the mesh are skipped).
  void draw_primitives(const ShaderProgram& program, const CameraMatrices& m, std::span<const std::uint32_t> ids,
                       const glm::vec4& color) const;

 private:
  void bind(const ShaderProgram& program, const CameraMatrices& m, const glm::vec4& color, bool shaded,
            bool vertex_colors = false) const;

  GlObject vao_;
  GlObject vbo_;
  GlObject colors_;  ///< RGBA8 per vertex, binding 1 (attribute 2 enabled only while has_colors_)
  bool has_colors_ = false;
  std::size_t triangle_count_ = 0;
  Aabb bounds_;
};

}  // namespace accelviz
