#pragma once
// The render-context seam: one interface, two implementations (a GLFW
// window, an OSMesa headless context). The renderer only ever sees a current
// GL 4.5 core context; it draws into its own framebuffer object, so reading
// pixels back is the same code whichever context is underneath.
#include <string_view>

#include "ui/gl/gl.h"

namespace accelviz {

class GlContext {
 public:
  virtual ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  /// Makes this context current on the calling thread and, when the last
  /// context made current came from the other implementation, reloads the
  /// GL function table through this one's GetProcAddress (GLFW's libGL and
  /// OSMesa hand out different entry points). GL is used from one thread.
  void make_current();

  /// Size in pixels of what this context shows: the window's framebuffer
  /// (not its size in screen coordinates) or the headless image size.
  virtual int width() const = 0;
  virtual int height() const = 0;

  /// Shows the back buffer (window); nothing to do headless.
  virtual void swap_buffers() {}

  /// "glfw", "osmesa" or "egl".
  virtual std::string_view kind() const = 0;

  /// The device node the context draws on (an EGL device's DRM node), or ""
  /// when the context names none (OSMesa, GLFW, a driver that names none).
  virtual std::string device_file() const { return {}; }

  /// Version, renderer and profile as checked when the context was created.
  const GlInfo& info() const { return info_; }

 protected:
  GlContext() = default;
  /// For derived constructors, once the native context exists: make it
  /// current, load GL through it, check 4.5 core, and in debug builds route
  /// KHR_debug output to stderr.
  void initialise();

  /// Binds the native context to the calling thread. `after_other_kind` is
  /// true when the last context made current was of the other kind (its
  /// binding may be stale in the implementation's own bookkeeping).
  virtual void make_native_current(bool after_other_kind) = 0;
  virtual GLADloadfunc proc_loader() const = 0;

 private:
  GlInfo info_;
};

}  // namespace accelviz
