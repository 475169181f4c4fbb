#pragma once
// Every mouse and key binding of the 3D view, as data: the Help panel lists
// this table and docs/gui.md documents the same rows, so the two cannot
// drift apart silently (tests/core/test_app_shortcuts.cpp checks the docs).
#include <span>
#include <string_view>

namespace accelviz {

struct Shortcut {
  std::string_view keys;    ///< "Left drag", "Ctrl+Q"
  std::string_view action;  ///< one line
};

inline constexpr Shortcut kShortcuts[] = {
    {"Left drag", "orbit around the pivot"},
    {"Right drag, middle drag, Shift+left drag", "pan (moves the pivot)"},
    {"Wheel", "zoom towards the pivot"},
    {"Left click (no drag)", "cast the pixel's ray: Ray panel, path and traversal in the view; selects the hit's leaf"},
    {"Double click", "set the pivot to the surface under the cursor"},
    {"Ctrl+left drag", "select a heatmap region: the nodes and primitives its rays touched (Predicted vs measured)"},
    {"F", "frame the selected node (subtree mode) or the scene"},
    {"R, Home", "reset the view (the scene's first camera, else the framing view)"},
    {"Left, Right", "step the ray replay back / forward"},
    {"F5",
     "reload the shaders, the GPU heatmap's included (files in ACCELVIZ_SHADER_DIR win over the built-in ones; on "
     "an error the old ones stay)"},
    {"F12", "screenshot (PNG + JSON side-car) into the screenshot folder"},
    {"H, F1", "show or hide this help"},
    {"Ctrl+Q", "quit"},
    {"Drop a .gltf/.glb/.obj file", "open it"},
};

inline std::span<const Shortcut> shortcuts() {
  return kShortcuts;
}

}  // namespace accelviz
