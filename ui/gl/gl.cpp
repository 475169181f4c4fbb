#include "ui/gl/gl.h"

#include <cstdio>
#include <cstdlib>
#include <string>

namespace accelviz {

std::string_view gl_error_name(GLenum error) {
  switch (error) {
    case GL_NO_ERROR:
      return "GL_NO_ERROR";
    case GL_INVALID_ENUM:
      return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE:
      return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION:
      return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION:
      return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY:
      return "GL_OUT_OF_MEMORY";
    case GL_STACK_UNDERFLOW:
      return "GL_STACK_UNDERFLOW";
    case GL_STACK_OVERFLOW:
      return "GL_STACK_OVERFLOW";
    default:
      return "GL_UNKNOWN_ERROR";
  }
}

void check_gl_errors(std::string_view where) {
  std::string names;
  // glGetError returns one flag per call; a lost context can keep returning
  // errors, so the loop is bounded.
  bool out_of_memory = false;
  for (int i = 0; i < 16; ++i) {
    const GLenum e = glGetError();
    if (e == GL_NO_ERROR) break;
    if (!names.empty()) names += ", ";
    names += gl_error_name(e);
    out_of_memory = out_of_memory || e == GL_OUT_OF_MEMORY;
  }
  // What to do about it, as the CPU's out-of-memory message says (a 16384x16384 GPU heatmap said only
  // "GL_OUT_OF_MEMORY after GPU trace setup").
  if (!names.empty())
    throw GlError(names + " after " + std::string(where) +
                  (out_of_memory ? " (the GPU ran out of memory: a smaller image size or scene needs less)" : ""));
}

GlInfo query_gl_info() {
  GlInfo info;
  glGetIntegerv(GL_MAJOR_VERSION, &info.major);
  glGetIntegerv(GL_MINOR_VERSION, &info.minor);
  GLint mask = 0;
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &mask);
  info.core_profile = (mask & GL_CONTEXT_CORE_PROFILE_BIT) != 0;
  auto str = [](GLenum name) {
    const auto* s = reinterpret_cast<const char*>(glGetString(name));
    return std::string(s ? s : "");
  };
  info.version = str(GL_VERSION);
  info.renderer = str(GL_RENDERER);
  return info;
}

GlInfo load_gl(GLADloadfunc get_proc) {
  const int version = gladLoadGL(get_proc);
  if (version == 0) throw GlError("could not load OpenGL entry points from the current context");
  GlInfo info = query_gl_info();
  if (info.major * 10 + info.minor < 45 || !info.core_profile) {
    throw GlError("need an OpenGL 4.5 core context, got \"" + info.version + "\" (" +
                  (info.core_profile ? "core" : "not core") + ") on " + info.renderer);
  }
  return info;
}

namespace {

const char* debug_source_name(GLenum source) {
  switch (source) {
    case GL_DEBUG_SOURCE_API:
      return "api";
    case GL_DEBUG_SOURCE_SHADER_COMPILER:
      return "shader compiler";
    case GL_DEBUG_SOURCE_WINDOW_SYSTEM:
      return "window system";
    case GL_DEBUG_SOURCE_THIRD_PARTY:
      return "third party";
    case GL_DEBUG_SOURCE_APPLICATION:
      return "application";
    default:
      return "other";
  }
}

void GLAD_API_PTR debug_callback(GLenum source, GLenum type, GLuint /*id*/, GLenum severity, GLsizei /*length*/,
                                 const GLchar* message, const void* user) {
  const bool verbose = user != nullptr;
  const bool important = type == GL_DEBUG_TYPE_ERROR || severity == GL_DEBUG_SEVERITY_HIGH;
  if (!important && !verbose) return;
  std::fprintf(stderr, "accelviz: GL debug (%s%s): %s\n", debug_source_name(source),
               type == GL_DEBUG_TYPE_ERROR ? ", error" : "", message);
}

}  // namespace

void enable_gl_debug_output() {
  // The callback cannot throw (it is called from inside the driver); errors
  // still surface as exceptions through check_gl_errors after the pass.
  const bool verbose = std::getenv("ACCELVIZ_GL_DEBUG") != nullptr;
  glEnable(GL_DEBUG_OUTPUT);
  glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
  static int verbose_tag = 1;
  glDebugMessageCallback(debug_callback, verbose ? &verbose_tag : nullptr);
}

}  // namespace accelviz
