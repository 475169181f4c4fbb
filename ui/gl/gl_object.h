#pragma once
// Move-only owners of GL object names, so that every buffer, vertex array,
// texture and framebuffer the renderer creates is deleted exactly once, in
// the context that is current when its owner dies.
#include "ui/gl/gl.h"

#include <utility>

namespace accelviz {

class GlObject {
 public:
  enum class Kind { buffer, vertex_array, texture, framebuffer, renderbuffer };

  GlObject() = default;
  ~GlObject() { reset(); }
  GlObject(GlObject&& o) noexcept : kind_(o.kind_), id_(std::exchange(o.id_, 0)) {}
  GlObject& operator=(GlObject&& o) noexcept {
    if (this != &o) {
      reset();
      kind_ = o.kind_;
      id_ = std::exchange(o.id_, 0);
    }
    return *this;
  }
  GlObject(const GlObject&) = delete;
  GlObject& operator=(const GlObject&) = delete;

  /// Creates a named object with the 4.5 direct-state-access entry points
  /// (glCreate*), so it exists without being bound.
  static GlObject create(Kind kind);
  /// Textures need their target at creation (GL_TEXTURE_2D, ...).
  static GlObject create_texture(GLenum target);

  GLuint id() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  void reset();

 private:
  GlObject(Kind kind, GLuint id) : kind_(kind), id_(id) {}
  Kind kind_ = Kind::buffer;
  GLuint id_ = 0;
};

}  // namespace accelviz
