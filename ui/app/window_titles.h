#pragma once
// The titles of the app's panels (ui/panels: begin_panel and
// begin_stacked_panel), for the script's `window open|close TITLE`. The
// layout test (tests/gl/test_layout_panel.cpp) checks that each is drawn.
#include <array>
#include <string_view>

namespace accelviz {

inline constexpr std::array<std::string_view, 15> kPanelTitles = {"Scene",
                                                                  "Structure",
                                                                  "Screenshot",
                                                                  "Stats",
                                                                  "View",
                                                                  "Ray",
                                                                  "A/B compare",
                                                                  "Predicted vs measured",
                                                                  "SAH explainer",
                                                                  "Tree",
                                                                  "Cost of accuracy",
                                                                  "Robustness",
                                                                  "Scenarios",
                                                                  "Flatten what-if",
                                                                  "Dynamics"};

}  // namespace accelviz
