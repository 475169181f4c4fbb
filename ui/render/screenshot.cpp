#include "ui/render/screenshot.h"

#include <cstdio>
#include <stdexcept>

namespace accelviz {

RgbImage to_rgb(const Rgba8Image& frame) {
  RgbImage out(frame.width, frame.height);
  for (std::size_t i = 0, n = static_cast<std::size_t>(frame.width) * frame.height; i < n; ++i)
    for (int c = 0; c < 3; ++c) out.pixels[3 * i + c] = frame.pixels[4 * i + c];
  return out;
}

SaveResult write_screenshot_png(const std::filesystem::path& path, const Rgba8Image& image, bool overwrite,
                                std::span<const PngText> text) {
  const std::string name = path.string();
  if (image.empty() || image.pixels.size() != static_cast<std::size_t>(image.width) * image.height * 4) {
    return {false, name + ": nothing to write (empty image)"};
  }
  const RgbImage rgb = to_rgb(image);
  // core's writer (the one every PNG of the project goes through); its
  // refusal of an existing file is said this function's way.
  try {
    write_png(name, rgb, overwrite, text);
  } catch (const FileExistsError&) {
    return {false, name + ": exists (not overwritten)"};
  } catch (const std::runtime_error& e) {
    return {false, e.what()};
  }
  return {true, {}};
}

std::filesystem::path next_screenshot_path(const std::filesystem::path& dir, const std::string& stem) {
  for (int i = 1;; ++i) {
    char suffix[16];
    std::snprintf(suffix, sizeof suffix, "-%03d.png", i);
    std::filesystem::path p = dir / (stem + suffix);
    std::error_code ec;
    if (!std::filesystem::exists(p, ec)) return p;
  }
}

}  // namespace accelviz
