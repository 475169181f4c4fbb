// Dear ImGui's OpenGL 3 renderer backend (imgui_impl_opengl3.cpp from
// Debian's libimgui-dev examples), compiled against accelviz's glad loader.
// With IMGUI_IMPL_OPENGL_LOADER_CUSTOM the backend uses whatever GL
// declarations are in scope: glad's, which call through the function table
// the current context loaded (GLFW's libGL or OSMesa). The copy inside
// libimgui.a has its own loader that dlopens libGL and so fails under OSMesa;
// our definitions of the ImGui_ImplOpenGL3_* symbols are linked first, so
// that archive member is never pulled in.
#include "ui/gl/gl.h"

#define IMGUI_IMPL_OPENGL_LOADER_CUSTOM
#include <imgui_impl_opengl3.cpp>
