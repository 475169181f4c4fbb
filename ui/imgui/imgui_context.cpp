#include "ui/imgui/imgui_context.h"

#include "core/util/file_checks.h"
#include "ui/app/settings.h"
#include "ui/gl/gl.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>

namespace accelviz {

ImGuiContextGuard::ImGuiContextGuard(GLFWwindow* window, std::optional<std::filesystem::path> ini)
    : ini_(std::move(ini)) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // the app persists the layout itself (see header)
  // No keyboard navigation: with it, any focused panel would claim the
  // keyboard (WantCaptureKeyboard) and the view shortcuts would stop working
  // after a click on a panel.
  if (ini_) {
    // A regular file of at most 1 MiB (a layout is a few KB): a FIFO blocked
    // the start, and ImGui took half a minute over 10 MB of sections.
    std::string s;
    if (const std::string problem = read_text_file(ini_->string(), std::uintmax_t{1} << 20, s); problem.empty())
      ImGui::LoadIniSettingsFromMemory(s.c_str(), s.size());
    else if (problem != "no such file")
      load_problem_ = ini_->string() + ": " + problem + " (the default layout is used)";
  }
  // HiDPI: GLFW reports the monitor's content scale (2 on a "Retina" or
  // 200 % display). The framebuffer is already in pixels; ImGui's sizes are
  // in window coordinates, so scale fonts and paddings by it.
  float sx = 1.0f, sy = 1.0f;
  glfwGetWindowContentScale(window, &sx, &sy);
  scale_ = std::clamp(std::max(sx, sy), 1.0f, 4.0f);
  ImGui::StyleColorsDark();
  ImGui::GetStyle().ScaleAllSizes(scale_);
  io.FontGlobalScale = scale_;
  ImGui_ImplGlfw_InitForOpenGL(window, /*install_callbacks=*/true);
  if (!ImGui_ImplOpenGL3_Init("#version 450 core")) {
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    throw GlError("ImGui's OpenGL 3 backend could not initialise");
  }
}

ImGuiContextGuard::~ImGuiContextGuard() {
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
}

void ImGuiContextGuard::new_frame() {
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
}

void ImGuiContextGuard::render() {
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

std::string ImGuiContextGuard::save_layout(bool force) {
  ImGuiIO& io = ImGui::GetIO();
  if (!ini_ || (!io.WantSaveIniSettings && !force)) return {};
  io.WantSaveIniSettings = false;
  std::size_t size = 0;
  const char* data = ImGui::SaveIniSettingsToMemory(&size);
  return write_file_atomic(*ini_, std::string_view(data, size));
}

}  // namespace accelviz
