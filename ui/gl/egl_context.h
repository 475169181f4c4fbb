#pragma once
// Headless OpenGL 4.5 core through EGL on a device (EGL_EXT_platform_device),
// without a window or a display server: the way to reach a real GPU on a
// machine without X (a GPU server, a CI runner with a GPU). Mesa's EGL also
// offers its software device (llvmpipe), so the same code runs in CI without
// a GPU. The renderer and the GPU trace draw into their own framebuffer
// objects and storage buffers, so the context has no surface at all
// (EGL_KHR_surfaceless_context).
#include <string>

#include "ui/gl/context.h"

namespace accelviz {

class EglContext final : public GlContext {
 public:
  /// Which EGL devices the constructor may take.
  enum class Devices {
    hardware_only,  ///< a GPU: devices that are not EGL_MESA_device_software
    any,            ///< a GPU if there is one, else a software device (llvmpipe)
  };

  /// Creates a 4.5 core context on the first device that `devices` allows
  /// (hardware devices first) and makes it current; throws GlError naming
  /// what is missing (no EGL device extensions, no suitable device, no 4.5
  /// core context, no surfaceless contexts). `width`×`height` is the image
  /// size headless renders use.
  EglContext(int width, int height, Devices devices = Devices::any);
  ~EglContext() override;

  int width() const override { return width_; }
  int height() const override { return height_; }
  std::string_view kind() const override { return "egl"; }

  /// Whether the device is a software one (EGL_MESA_device_software).
  bool software() const { return software_; }
  /// The device's DRM node (EGL_DRM_DEVICE_FILE_EXT or its render node), or
  /// "" when the driver names none: recorded beside the GL renderer string.
  std::string device_file() const override { return device_file_; }

 private:
  void make_native_current(bool after_other_kind) override;
  GLADloadfunc proc_loader() const override;

  void* display_ = nullptr;  // EGLDisplay (kept opaque: egl.h defines macros we do not want everywhere)
  void* context_ = nullptr;  // EGLContext
  int width_;
  int height_;
  bool software_ = false;
  std::string device_file_;
};

}  // namespace accelviz
