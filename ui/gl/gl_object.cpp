#include "ui/gl/gl_object.h"

namespace accelviz {

GlObject GlObject::create(Kind kind) {
  GLuint id = 0;
  switch (kind) {
    case Kind::buffer:
      glCreateBuffers(1, &id);
      break;
    case Kind::vertex_array:
      glCreateVertexArrays(1, &id);
      break;
    case Kind::framebuffer:
      glCreateFramebuffers(1, &id);
      break;
    case Kind::renderbuffer:
      glCreateRenderbuffers(1, &id);
      break;
    case Kind::texture:
      throw GlError("GlObject::create: textures need a target, use create_texture");
  }
  if (id == 0) throw GlError("glCreate* returned no object (is a context current?)");
  return GlObject(kind, id);
}

GlObject GlObject::create_texture(GLenum target) {
  GLuint id = 0;
  glCreateTextures(target, 1, &id);
  if (id == 0) throw GlError("glCreateTextures returned no object (is a context current?)");
  return GlObject(Kind::texture, id);
}

void GlObject::reset() {
  if (id_ == 0) return;
  switch (kind_) {
    case Kind::buffer:
      glDeleteBuffers(1, &id_);
      break;
    case Kind::vertex_array:
      glDeleteVertexArrays(1, &id_);
      break;
    case Kind::texture:
      glDeleteTextures(1, &id_);
      break;
    case Kind::framebuffer:
      glDeleteFramebuffers(1, &id_);
      break;
    case Kind::renderbuffer:
      glDeleteRenderbuffers(1, &id_);
      break;
  }
  id_ = 0;
}

}  // namespace accelviz
