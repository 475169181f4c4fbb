#pragma once
// Colour maps for metric images (heatmaps, difference images). Perceptual
// sequential maps as 256-entry lookup tables with linear interpolation between
// entries, plus a diverging map for signed differences.
#include <glm/glm.hpp>

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace accelviz {

enum class ColorMap {
  viridis,   ///< default: perceptually uniform, readable in grey and by colour-blind viewers
  inferno,   ///< perceptually uniform, black to yellow: strong contrast for hot spots
  turbo,     ///< rainbow-like but smooth; most distinguishable steps, not uniform in lightness
  diverging, ///< blue - white - red, for signed differences (0.5 = no change)
};

/// Colour of `map` at t in [0, 1] (clamped; NaN maps to 0) as RGB in [0, 1].
/// The tables hold sRGB-encoded values as published; they are returned as is,
/// ready to be scaled to an 8-bit image without gamma conversion.
glm::vec3 colormap(ColorMap map, float t);

/// The 256 published entries of a table map (viridis, inferno, turbo), each an
/// RGB triple in [0, 1]. Empty for the diverging map, which is computed.
std::span<const float[3]> colormap_table(ColorMap map);

/// Command-line names: "viridis", "inferno", "turbo", "diverging".
std::string_view colormap_name(ColorMap map);
std::optional<ColorMap> parse_colormap(std::string_view name);

}  // namespace accelviz
