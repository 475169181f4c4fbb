#pragma once
// Dear ImGui set up on a GLFW window: the GLFW platform backend (input,
// from libimgui.a) and the OpenGL 3 renderer backend (compiled against glad,
// imgui_impl_opengl3_glad.cpp). One per window; the window's GL context must
// be current for the whole life of the object.
//
// The layout (imgui.ini) is loaded and saved by the app, not by ImGui, so it
// goes under $XDG_CONFIG_HOME/accelviz/ and is written atomically, and runs
// without settings (tests, scripts) write nothing.
#include <filesystem>
#include <optional>
#include <string>

struct GLFWwindow;

namespace accelviz {

class ImGuiContextGuard {
 public:
  /// Creates the ImGui context and both backends; `ini` is the layout file
  /// to read now and write on save_layout() (none: no layout persistence).
  /// Fonts and sizes are scaled by the window's content scale (HiDPI).
  ImGuiContextGuard(GLFWwindow* window, std::optional<std::filesystem::path> ini);
  ~ImGuiContextGuard();
  ImGuiContextGuard(const ImGuiContextGuard&) = delete;
  ImGuiContextGuard& operator=(const ImGuiContextGuard&) = delete;

  void new_frame();
  /// Draws the frame's UI into the current framebuffer (call after Renderer::present).
  void render();
  /// Writes the layout when ImGui asks for it (or `force`); "" or an error line.
  std::string save_layout(bool force = false);

  /// The content scale the UI was sized for.
  float scale() const { return scale_; }
  /// Why the layout file was not read ("" when it was, or is absent).
  const std::string& load_problem() const { return load_problem_; }

 private:
  std::optional<std::filesystem::path> ini_;
  std::string load_problem_;
  float scale_ = 1.0f;
};

}  // namespace accelviz
