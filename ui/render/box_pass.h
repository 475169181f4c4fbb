#pragma once
// Box overlays as lines: the 12 edges of a unit cube (24 vertices) drawn
// once per box with instancing, each instance stretching the cube to its
// box and carrying its colour. A million BVH nodes cost 40 MB, not 700.
#include "ui/gl/gl_object.h"
#include "ui/gl/shader.h"
#include "ui/render/box_selection.h"
#include "ui/render/camera_view.h"

#include <span>

namespace accelviz {

class BoxPass {
 public:
  BoxPass();
  /// Replaces the list; empty boxes (Aabb::empty()) are dropped.
  void upload(std::span<const ColoredBox> boxes);
  std::size_t box_count() const { return count_; }
  const Aabb& bounds() const { return bounds_; }

  /// depth_test false: boxes show through the mesh.
  void draw(const ShaderProgram& program, const CameraMatrices& m, bool depth_test) const;

 private:
  GlObject vao_;
  GlObject cube_edges_;
  GlObject instances_;
  std::size_t count_ = 0;
  Aabb bounds_;
};

}  // namespace accelviz
