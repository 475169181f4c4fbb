#pragma once
// A GLFW window with an OpenGL 4.5 core context. GLFW loads libGL itself
// (dlopen) when the window is created, so nothing links libGL.
#include "ui/gl/context.h"

#include <string>

struct GLFWwindow;

namespace accelviz {

struct WindowOptions {
  int width = 1280;  ///< initial size in screen coordinates
  int height = 800;
  std::string title = "accelviz";
  bool visible = true;  ///< false: an offscreen window (still needs a display)
  bool vsync = true;    ///< swap interval 1
};

class GlfwContext final : public GlContext {
 public:
  /// Opens the window and makes its context current; throws GlError with
  /// GLFW's own message when there is no display or no 4.5 core context.
  explicit GlfwContext(const WindowOptions& options = {});
  ~GlfwContext() override;

  /// Framebuffer size in pixels (differs from the window size on HiDPI).
  int width() const override;
  int height() const override;
  void swap_buffers() override;
  std::string_view kind() const override { return "glfw"; }

  GLFWwindow* window() const { return window_; }
  bool should_close() const;

 private:
  void make_native_current(bool after_other_kind) override;
  GLADloadfunc proc_loader() const override;

  GLFWwindow* window_ = nullptr;
};

}  // namespace accelviz
