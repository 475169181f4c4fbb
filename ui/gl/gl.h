#pragma once
// The one include for OpenGL in accelviz: the glad 2 loader generated at
// build time (GL 4.5 core + KHR_debug), plus error checking that every pass
// uses. Never include <GL/gl.h> elsewhere: entry points come from the
// current context's GetProcAddress, not from a linked libGL.
#include <glad/gl.h>

#include <stdexcept>
#include <string>
#include <string_view>

namespace accelviz {

/// A GL failure: an error flag after a pass, a context that is not 4.5 core,
/// an incomplete framebuffer. The message is one line naming where it happened.
class GlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Name of a glGetError code ("GL_INVALID_OPERATION").
std::string_view gl_error_name(GLenum error);

/// Drains the GL error flags; throws GlError "GL_... after <where>" when any
/// was set. Called after each render pass in every build type, so a broken
/// pass is reported where it happens rather than as a wrong picture.
void check_gl_errors(std::string_view where);

/// What the current context is: version string, renderer, profile.
struct GlInfo {
  int major = 0;
  int minor = 0;
  bool core_profile = false;
  std::string version;   ///< GL_VERSION
  std::string renderer;  ///< GL_RENDERER ("llvmpipe (LLVM 15.0.6, 256 bits)")
};
GlInfo query_gl_info();

/// Loads every GL entry point through `get_proc` (glfwGetProcAddress or
/// OSMesaGetProcAddress) for the context current now, then checks that it is
/// a 4.5 core context; throws GlError otherwise.
GlInfo load_gl(GLADloadfunc get_proc);

/// Routes KHR_debug messages to stderr (errors and high severity always,
/// the rest when ACCELVIZ_GL_DEBUG is set). Installed in debug builds by the
/// contexts; harmless to call in release builds too.
void enable_gl_debug_output();

}  // namespace accelviz
