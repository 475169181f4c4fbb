#pragma once
// The framebuffer object every frame is drawn into, in a window and
// headless alike: colour RGBA8 + depth 24/stencil 8, optionally multisampled
// (then resolved into a single-sampled twin). Reading pixels back and
// showing them in a window both start from the resolved colour buffer, so a
// screenshot is exactly what was drawn.
#include "ui/gl/gl_object.h"
#include "ui/render/image.h"

namespace accelviz {

class RenderTarget {
 public:
  /// (Re)allocates when size or sample count changed. samples <= 1: no MSAA.
  void resize(int width, int height, int samples);
  /// Binds the framebuffer to draw into and sets the viewport to cover it.
  void bind_for_drawing() const;
  /// Multisampled: resolves into the single-sampled buffer. Else nothing.
  void resolve() const;
  /// The resolved colour buffer, rows flipped to top-down.
  Rgba8Image read_pixels() const;
  /// Copies the resolved colour buffer into the default framebuffer of the
  /// current context (the window), scaled to dst_width × dst_height.
  void blit_to_default(int dst_width, int dst_height) const;

  int width() const { return width_; }
  int height() const { return height_; }
  int samples() const { return samples_; }

 private:
  int width_ = 0;
  int height_ = 0;
  int samples_ = 0;
  GlObject resolved_fbo_;
  GlObject resolved_color_;  // texture, so a later pass may sample the frame
  GlObject resolved_depth_;  // renderbuffer; only drawn into without MSAA
  GlObject msaa_fbo_;
  GlObject msaa_color_;
  GlObject msaa_depth_;
};

}  // namespace accelviz
