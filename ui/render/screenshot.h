#pragma once
// Screenshots: what the renderer drew (legend included), read back from its
// framebuffer and written as PNG.
#include "core/analysis/heatmap.h"
#include "ui/render/image.h"

#include <filesystem>
#include <string>

namespace accelviz {

struct [[nodiscard]] SaveResult {
  bool ok = false;
  std::string error;  ///< one line, "<file>: <problem>", when !ok
  explicit operator bool() const { return ok; }
};

/// The frame without its alpha channel (the frame is opaque).
RgbImage to_rgb(const Rgba8Image& frame);

/// Writes `image` as an 8-bit RGB PNG (the frame is opaque; alpha is
/// dropped). Never replaces an existing file unless `overwrite`: the file is
/// created exclusively, so a file that appears meanwhile is not clobbered
/// either. The error for an existing file is "<file>: exists (not overwritten)".
SaveResult write_screenshot_png(const std::filesystem::path& path, const Rgba8Image& image, bool overwrite = false,
                                std::span<const PngText> text = {});

/// A free name "<stem>-NNN.png" in `dir` (first unused number from 1), for
/// F12-style screenshots that must never overwrite.
std::filesystem::path next_screenshot_path(const std::filesystem::path& dir, const std::string& stem = "accelviz");

}  // namespace accelviz
