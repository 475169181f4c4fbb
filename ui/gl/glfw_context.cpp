#include "ui/gl/glfw_context.h"

#define GLFW_INCLUDE_NONE  // GL comes from glad, never from GLFW's headers
#include <GLFW/glfw3.h>

#include <string>

namespace accelviz {
namespace {

// glfwInit/glfwTerminate are global; several windows share one init.
int g_glfw_users = 0;
std::string g_last_glfw_error;

void record_glfw_error(int /*code*/, const char* description) {
  g_last_glfw_error = description ? description : "";
}

void acquire_glfw() {
  if (g_glfw_users == 0) {
    glfwSetErrorCallback(record_glfw_error);
    if (!glfwInit()) throw GlError("GLFW could not initialise: " + g_last_glfw_error);
  }
  ++g_glfw_users;
}

void release_glfw() {
  if (--g_glfw_users == 0) glfwTerminate();
}

}  // namespace

GlfwContext::GlfwContext(const WindowOptions& options) {
  acquire_glfw();
  glfwDefaultWindowHints();
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, options.visible ? GLFW_TRUE : GLFW_FALSE);
  // The renderer draws into its own FBO and blits; the window needs no depth.
  glfwWindowHint(GLFW_DEPTH_BITS, 0);
  glfwWindowHint(GLFW_STENCIL_BITS, 0);
#ifndef NDEBUG
  glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, GLFW_TRUE);
#endif
  g_last_glfw_error.clear();
  window_ = glfwCreateWindow(options.width, options.height, options.title.c_str(), nullptr, nullptr);
  if (!window_) {
    release_glfw();
    throw GlError("GLFW could not open an OpenGL 4.5 core window: " + g_last_glfw_error);
  }
  try {
    initialise();
    glfwSwapInterval(options.vsync ? 1 : 0);
  } catch (...) {
    glfwDestroyWindow(window_);
    release_glfw();
    throw;
  }
}

GlfwContext::~GlfwContext() {
  glfwDestroyWindow(window_);
  release_glfw();
}

int GlfwContext::width() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  return w;
}

int GlfwContext::height() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  return h;
}

void GlfwContext::swap_buffers() {
  glfwSwapBuffers(window_);
}

bool GlfwContext::should_close() const {
  return glfwWindowShouldClose(window_) != 0;
}

void GlfwContext::make_native_current(bool after_other_kind) {
  // Mesa's glXMakeCurrent returns early when asked for the context it
  // believes is current, but an OSMesa context made current meanwhile has
  // taken over the shared dispatch (libglapi). Releasing first forces a real
  // rebind.
  if (after_other_kind) glfwMakeContextCurrent(nullptr);
  glfwMakeContextCurrent(window_);
}

GLADloadfunc GlfwContext::proc_loader() const {
  // GLFWglproc and GLADapiproc are both `void (*)(void)`.
  return reinterpret_cast<GLADloadfunc>(&glfwGetProcAddress);
}

}  // namespace accelviz
