#include "ui/gl/context.h"

#include <string>

namespace accelviz {
namespace {
// The loader whose entry points glad's table holds now. glad 2 (without
// --mx) keeps one global table, so switching between a GLFW and an OSMesa
// context must refill it; contexts of the same kind share entry points
// (OSMesa and GLX dispatch through the current context).
GLADloadfunc g_loaded_with = nullptr;
}  // namespace

GlContext::~GlContext() = default;

void GlContext::make_current() {
  const bool switching = g_loaded_with != proc_loader();
  make_native_current(switching);
  if (switching) {
    load_gl(proc_loader());
    g_loaded_with = proc_loader();
  }
}

void GlContext::initialise() {
  make_native_current(g_loaded_with != nullptr && g_loaded_with != proc_loader());
  info_ = load_gl(proc_loader());
  g_loaded_with = proc_loader();
#ifndef NDEBUG
  enable_gl_debug_output();
#endif
  check_gl_errors(std::string(kind()) + " context creation");
}

}  // namespace accelviz
