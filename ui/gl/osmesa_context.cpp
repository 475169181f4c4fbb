#include "ui/gl/osmesa_context.h"

// glad first: it defines __gl_h_, so the <GL/gl.h> that osmesa.h includes
// is skipped and the GL types come from glad.
#include "ui/gl/gl.h"

#include <GL/osmesa.h>

#include <string>

#if defined(ACCELVIZ_SANITIZE)
// Mesa's OSMesa keeps a few hundred bytes per process that it never frees
// (its framebuffer bookkeeping; a bare create / make current / destroy
// program shows the same), which LeakSanitizer reports at exit. The
// suppression names the library, so leaks in our code are still reported.
// Sanitizer builds only: it is the hook LSan looks up by this name.
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libOSMesa.so\n";
}
#endif

namespace accelviz {

OsMesaContext::OsMesaContext(int width, int height) : width_(width), height_(height) {
  if (width <= 0 || height <= 0) throw GlError("OSMesa context: image size must be positive");
  const int attribs[] = {
      OSMESA_FORMAT,
      OSMESA_RGBA,
      OSMESA_DEPTH_BITS,
      24,
      OSMESA_STENCIL_BITS,
      8,
      OSMESA_PROFILE,
      OSMESA_CORE_PROFILE,
      OSMESA_CONTEXT_MAJOR_VERSION,
      4,
      OSMESA_CONTEXT_MINOR_VERSION,
      5,
      0,
  };
  context_ = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!context_) {
    throw GlError("OSMesa could not create an OpenGL 4.5 core context (is Mesa's llvmpipe available?)");
  }
  try {
    initialise();
  } catch (...) {
    OSMesaDestroyContext(static_cast<OSMesaContext>(context_));
    throw;
  }
}

OsMesaContext::~OsMesaContext() {
  OSMesaDestroyContext(static_cast<OSMesaContext>(context_));
}

void OsMesaContext::resize(int width, int height) {
  if (width <= 0 || height <= 0) throw GlError("OSMesa context: image size must be positive");
  width_ = width;
  height_ = height;
}

void OsMesaContext::make_native_current(bool /*after_other_kind*/) {
  // OSMesaMakeCurrent always rebinds, so no special case is needed.
  if (!OSMesaMakeCurrent(static_cast<OSMesaContext>(context_), default_buffer_.data(), GL_UNSIGNED_BYTE, 1, 1)) {
    throw GlError("OSMesaMakeCurrent failed");
  }
}

GLADloadfunc OsMesaContext::proc_loader() const {
  // OSMESAproc and GLADapiproc are both `void (*)(void)`.
  return reinterpret_cast<GLADloadfunc>(&OSMesaGetProcAddress);
}

}  // namespace accelviz
