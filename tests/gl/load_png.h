#pragma once
// A PNG file read back as RGBA8 pixels (stb_image), for the tests that check
// written pictures: screenshots and golden images.
#include <stb_image.h>

#include <algorithm>
#include <filesystem>

#include "ui/render/image.h"

namespace accelviz::test {

/// The PNG at `p` as RGBA8; an empty image when it cannot be read.
inline Rgba8Image load_png(const std::filesystem::path& p) {
  int w = 0, h = 0, n = 0;
  unsigned char* data = stbi_load(p.string().c_str(), &w, &h, &n, 4);
  if (!data) return {};
  Rgba8Image img(w, h);
  std::copy(data, data + static_cast<std::size_t>(w) * h * 4, img.pixels.begin());
  stbi_image_free(data);
  return img;
}

}  // namespace accelviz::test
