#include "ui/gl/egl_context.h"

// EGL's headers bring no GL declarations of their own (GL comes from glad).
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <string_view>
#include <vector>

#include "ui/gl/gl.h"

#ifndef EGL_DRM_RENDER_NODE_FILE_EXT
#define EGL_DRM_RENDER_NODE_FILE_EXT 0x3377  // EGL_EXT_device_drm_render_node
#endif

namespace accelviz {
namespace {

bool has_extension(const char* list, std::string_view name) {
  if (list == nullptr) return false;
  std::string_view rest(list);
  while (!rest.empty()) {
    const std::size_t end = rest.find(' ');
    if (rest.substr(0, end) == name) return true;
    if (end == std::string_view::npos) break;
    rest.remove_prefix(end + 1);
  }
  return false;
}

std::string egl_error_name(EGLint e) {
  switch (e) {
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    default:
      return "EGL error " + std::to_string(e);
  }
}

/// A 4.5 core context on `display` (initialised), or nullptr with `why` set.
EGLContext create_core_context(EGLDisplay display, std::string& why) {
  const char* ext = eglQueryString(display, EGL_EXTENSIONS);
  if (!has_extension(ext, "EGL_KHR_surfaceless_context")) {
    why = "the device has no surfaceless contexts (EGL_KHR_surfaceless_context)";
    return nullptr;
  }
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) {
    why = "the device's EGL has no desktop OpenGL (eglBindAPI)";
    return nullptr;
  }
  EGLConfig config = EGL_NO_CONFIG_KHR;
  if (!has_extension(ext, "EGL_KHR_no_config_context")) {
    // Any surface type: eglChooseConfig's default asks for window surfaces,
    // which a device's display (no window system) may have none of.
    const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
    EGLint found = 0;
    if (eglChooseConfig(display, want, &config, 1, &found) != EGL_TRUE || found < 1) {
      why = "the device has no OpenGL config";
      return nullptr;
    }
  }
  // One attribute and its value per line.
  // clang-format off
  const EGLint attribs[] = {
      EGL_CONTEXT_MAJOR_VERSION, 4,
      EGL_CONTEXT_MINOR_VERSION, 5,
      EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
      EGL_NONE,
  };
  // clang-format on
  EGLContext ctx = eglCreateContext(display, config, EGL_NO_CONTEXT, attribs);
  if (ctx == EGL_NO_CONTEXT) why = "no OpenGL 4.5 core context (" + egl_error_name(eglGetError()) + ")";
  return ctx;
}

}  // namespace

EglContext::EglContext(int width, int height, Devices devices) : width_(width), height_(height) {
  if (width <= 0 || height <= 0) throw GlError("EGL context: image size must be positive");
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  const auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  const auto device_string =
      reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
  const auto platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  // EGL_EXT_device_base is EGL_EXT_device_enumeration and _query in one:
  // NVIDIA's driver names only it, Mesa names all three.
  const bool enumeration =
      has_extension(client, "EGL_EXT_device_enumeration") || has_extension(client, "EGL_EXT_device_base");
  if (!enumeration || !has_extension(client, "EGL_EXT_platform_device") || query_devices == nullptr ||
      device_string == nullptr || platform_display == nullptr)
    throw GlError(
        "EGL has no device enumeration (EGL_EXT_device_enumeration or EGL_EXT_device_base, and "
        "EGL_EXT_platform_device)");

  EGLint count = 0;
  if (query_devices(0, nullptr, &count) != EGL_TRUE || count <= 0) throw GlError("EGL lists no devices");
  std::vector<EGLDeviceEXT> all(static_cast<std::size_t>(count));
  query_devices(count, all.data(), &count);
  all.resize(static_cast<std::size_t>(count));
  // Hardware devices first, then (when allowed) software ones, each in EGL's order.
  std::vector<std::pair<EGLDeviceEXT, bool>> candidates;
  for (bool soft : {false, true})
    for (EGLDeviceEXT d : all)
      if (has_extension(device_string(d, EGL_EXTENSIONS), "EGL_MESA_device_software") == soft &&
          (!soft || devices == Devices::any))
        candidates.emplace_back(d, soft);
  if (candidates.empty())
    throw GlError("EGL lists " + std::to_string(count) + " device(s), none of them a GPU (software devices only)");

  std::string why;
  for (const auto& [device, soft] : candidates) {
    // The display stays initialised for the life of the process (no
    // eglTerminate): eglGetPlatformDisplayEXT hands out one EGLDisplay per
    // device, shared by every context on it, so terminating it would pull it
    // from under the others; and Mesa unloads its driver at eglTerminate,
    // after which LeakSanitizer can neither name nor suppress the driver's
    // per-process allocations. eglInitialize on an initialised display does
    // nothing.
    EGLDisplay display = platform_display(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
    if (display == EGL_NO_DISPLAY || eglInitialize(display, nullptr, nullptr) != EGL_TRUE) {
      why = "a device's display did not initialise (" + egl_error_name(eglGetError()) + ")";
      continue;
    }
    EGLContext ctx = create_core_context(display, why);
    if (ctx == EGL_NO_CONTEXT) continue;
    display_ = display;
    context_ = ctx;
    software_ = soft;
    const char* file = device_string(device, EGL_DRM_DEVICE_FILE_EXT);
    if (file == nullptr) file = device_string(device, EGL_DRM_RENDER_NODE_FILE_EXT);
    eglGetError();  // a device without a DRM node reports EGL_BAD_PARAMETER: not an error here
    device_file_ = file != nullptr ? file : "";
    break;
  }
  if (context_ == nullptr) throw GlError("EGL: " + why);
  try {
    initialise();
  } catch (...) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    throw;
  }
}

EglContext::~EglContext() {
  if (eglGetCurrentContext() == context_) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(display_, context_);
}

void EglContext::make_native_current(bool after_other_kind) {
  // As GlfwContext: Mesa's EGL returns early when asked for the context it
  // believes is current, but an OSMesa context made current meanwhile has
  // taken over the shared dispatch (libglapi). Releasing first forces a real
  // rebind.
  if (after_other_kind) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) != EGL_TRUE)
    throw GlError("eglMakeCurrent failed (" + egl_error_name(eglGetError()) + ")");
}

GLADloadfunc EglContext::proc_loader() const {
  // eglGetProcAddress returns `void (*)(void)`, as GLADapiproc; core GL entry
  // points too (EGL 1.5, EGL_KHR_get_all_proc_addresses).
  return reinterpret_cast<GLADloadfunc>(&eglGetProcAddress);
}

}  // namespace accelviz
