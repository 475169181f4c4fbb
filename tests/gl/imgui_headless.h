#pragma once
// A headless Dear ImGui context for panel tests: no window, no GL; the font
// atlas is built so frames can be laid out, and frames are driven by hand
// (mouse position and button per frame). Shared by the panel tests in tests/gl.
#include <imgui.h>

namespace accelviz::test {

class HeadlessImGuiContext {
 public:
  explicit HeadlessImGuiContext(ImVec2 display = ImVec2(1280, 800)) {
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.DisplaySize = display;
    io.IniFilename = nullptr;
    io.MouseDoubleClickTime = 0.0f;  // scripted clicks never pair into a double click
    unsigned char* px = nullptr;
    int w = 0, h = 0;
    io.Fonts->GetTexDataAsRGBA32(&px, &w, &h);
  }
  ~HeadlessImGuiContext() { ImGui::DestroyContext(); }
  HeadlessImGuiContext(const HeadlessImGuiContext&) = delete;
  HeadlessImGuiContext& operator=(const HeadlessImGuiContext&) = delete;

  /// Starts a frame with the mouse at `at`, the left button `down`.
  static void begin_frame(ImVec2 at, bool down) {
    ImGuiIO& io = ImGui::GetIO();
    io.DeltaTime = 1.0f / 60.0f;
    io.MousePos = at;
    io.MouseDown[0] = down;
    ImGui::NewFrame();
  }
};

}  // namespace accelviz::test
