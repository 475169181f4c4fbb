#include "ui/render/render_target.h"

#include <cstring>
#include <string>

namespace accelviz {
namespace {

void check_complete(GLuint fbo, const char* what) {
  const GLenum status = glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw GlError(std::string(what) + " framebuffer incomplete (glCheckFramebufferStatus " + std::to_string(status) +
                  ")");
  }
}

}  // namespace

void RenderTarget::resize(int width, int height, int samples) {
  if (width <= 0 || height <= 0) throw GlError("render target size must be positive");
  samples = samples > 1 ? samples : 1;
  if (samples > 1) {
    GLint max_samples = 1;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    samples = samples < max_samples ? samples : max_samples;
  }
  if (width == width_ && height == height_ && samples == samples_ && resolved_fbo_) return;
  width_ = width;
  height_ = height;
  samples_ = samples;

  resolved_color_ = GlObject::create_texture(GL_TEXTURE_2D);
  glTextureStorage2D(resolved_color_.id(), 1, GL_RGBA8, width, height);
  glTextureParameteri(resolved_color_.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(resolved_color_.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  resolved_depth_ = GlObject::create(GlObject::Kind::renderbuffer);
  glNamedRenderbufferStorage(resolved_depth_.id(), GL_DEPTH24_STENCIL8, width, height);
  resolved_fbo_ = GlObject::create(GlObject::Kind::framebuffer);
  glNamedFramebufferTexture(resolved_fbo_.id(), GL_COLOR_ATTACHMENT0, resolved_color_.id(), 0);
  glNamedFramebufferRenderbuffer(resolved_fbo_.id(), GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER,
                                 resolved_depth_.id());
  check_complete(resolved_fbo_.id(), "render target");

  if (samples > 1) {
    msaa_color_ = GlObject::create(GlObject::Kind::renderbuffer);
    glNamedRenderbufferStorageMultisample(msaa_color_.id(), samples, GL_RGBA8, width, height);
    msaa_depth_ = GlObject::create(GlObject::Kind::renderbuffer);
    glNamedRenderbufferStorageMultisample(msaa_depth_.id(), samples, GL_DEPTH24_STENCIL8, width, height);
    msaa_fbo_ = GlObject::create(GlObject::Kind::framebuffer);
    glNamedFramebufferRenderbuffer(msaa_fbo_.id(), GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, msaa_color_.id());
    glNamedFramebufferRenderbuffer(msaa_fbo_.id(), GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, msaa_depth_.id());
    check_complete(msaa_fbo_.id(), "multisampled render target");
  } else {
    msaa_fbo_.reset();
    msaa_color_.reset();
    msaa_depth_.reset();
  }
  check_gl_errors("render target allocation");
}

void RenderTarget::bind_for_drawing() const {
  glBindFramebuffer(GL_FRAMEBUFFER, samples_ > 1 ? msaa_fbo_.id() : resolved_fbo_.id());
  glViewport(0, 0, width_, height_);
}

void RenderTarget::resolve() const {
  if (samples_ <= 1) return;
  glBlitNamedFramebuffer(msaa_fbo_.id(), resolved_fbo_.id(), 0, 0, width_, height_, 0, 0, width_, height_,
                         GL_COLOR_BUFFER_BIT, GL_NEAREST);
  check_gl_errors("multisample resolve");
}

Rgba8Image RenderTarget::read_pixels() const {
  Rgba8Image image(width_, height_);
  if (image.empty()) return image;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, resolved_fbo_.id());
  glNamedFramebufferReadBuffer(resolved_fbo_.id(), GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  std::vector<std::uint8_t> bottom_up(image.pixels.size());
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  check_gl_errors("pixel readback");
  // GL's window origin is the bottom-left corner; images start at the top.
  const std::size_t row = static_cast<std::size_t>(width_) * 4;
  for (int y = 0; y < height_; ++y) {
    std::memcpy(image.pixels.data() + static_cast<std::size_t>(y) * row,
                bottom_up.data() + static_cast<std::size_t>(height_ - 1 - y) * row, row);
  }
  return image;
}

void RenderTarget::blit_to_default(int dst_width, int dst_height) const {
  if (!resolved_fbo_) return;  // nothing rendered yet
  const GLenum filter = (dst_width == width_ && dst_height == height_) ? GL_NEAREST : GL_LINEAR;
  glBlitNamedFramebuffer(resolved_fbo_.id(), 0, 0, 0, width_, height_, 0, 0, dst_width, dst_height, GL_COLOR_BUFFER_BIT,
                         filter);
  check_gl_errors("present (blit to the window)");
}

}  // namespace accelviz
