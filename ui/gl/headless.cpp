#include "ui/gl/headless.h"

#include <stdexcept>
#include <string>

#include "ui/gl/egl_context.h"
#include "ui/gl/osmesa_context.h"

namespace accelviz {

std::unique_ptr<GlContext> make_headless_context(int width, int height, std::string_view which) {
  if (which == "osmesa") return std::make_unique<OsMesaContext>(width, height);
  if (which == "egl") return std::make_unique<EglContext>(width, height, EglContext::Devices::any);
  if (which == "auto") {
    try {
      return std::make_unique<EglContext>(width, height, EglContext::Devices::hardware_only);
    } catch (const GlError&) {
      return std::make_unique<OsMesaContext>(width, height);  // no GPU reachable through EGL
    }
  }
  throw std::invalid_argument("unknown GL context '" + std::string(which) + "': expected " +
                              std::string(kHeadlessContextNames));
}

}  // namespace accelviz
