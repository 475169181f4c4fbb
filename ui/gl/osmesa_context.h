#pragma once
// Headless OpenGL 4.5 core through OSMesa (llvmpipe). Used by `accelviz
// render`, by batch screenshots and by the pixel tests in tests/gl.
#include "ui/gl/context.h"

#include <cstdint>
#include <vector>

namespace accelviz {

class OsMesaContext final : public GlContext {
 public:
  /// Creates a 4.5 core context and makes it current; throws GlError when
  /// OSMesa cannot (e.g. a Mesa without llvmpipe). `width`×`height` is the
  /// image size headless renders use; drawing goes to the renderer's FBO.
  OsMesaContext(int width, int height);
  ~OsMesaContext() override;

  int width() const override { return width_; }
  int height() const override { return height_; }
  std::string_view kind() const override { return "osmesa"; }

  /// Changes the image size reported by width()/height().
  void resize(int width, int height);

 private:
  void make_native_current(bool after_other_kind) override;
  GLADloadfunc proc_loader() const override;

  void* context_ = nullptr;  // OSMesaContext (kept opaque: osmesa.h drags in gl.h)
  int width_;
  int height_;
  // OSMesa needs a client buffer for its default framebuffer. Nothing is
  // drawn into it (the renderer owns an FBO), so it stays one pixel.
  std::vector<std::uint8_t> default_buffer_ = std::vector<std::uint8_t>(4, 0);
};

}  // namespace accelviz
