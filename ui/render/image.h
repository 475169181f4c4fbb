#pragma once
// An 8-bit RGBA image as the renderer reads it back and as screenshots
// store it: rows top-down (row 0 is the top of the picture, as in the CPU
// ray convention and in PNG files), 4 bytes per pixel, no padding.
#include <glm/glm.hpp>

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace accelviz {

struct Rgba8Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  ///< width*height*4 bytes, top row first

  Rgba8Image() = default;
  Rgba8Image(int w, int h) : width(w), height(h), pixels(static_cast<std::size_t>(w) * h * 4, 0) {}

  bool empty() const { return width <= 0 || height <= 0; }
  glm::u8vec4 at(int x, int y) const {
    assert(x >= 0 && y >= 0 && x < width && y < height);
    const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 4;
    return {pixels[i], pixels[i + 1], pixels[i + 2], pixels[i + 3]};
  }
  void set(int x, int y, glm::u8vec4 c) {
    assert(x >= 0 && y >= 0 && x < width && y < height);
    const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 4;
    pixels[i] = c.x;
    pixels[i + 1] = c.y;
    pixels[i + 2] = c.z;
    pixels[i + 3] = c.w;
  }
};

}  // namespace accelviz
