#include "ui/render/screenshot.h"

// Debian's libstb ships the compiled implementation: no STB_IMAGE_WRITE_IMPLEMENTATION here.
#include <stb_image_write.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

namespace accelviz {
namespace {

struct PngSink {
  std::FILE* file;
  bool failed = false;
};

void write_chunk(void* context, void* data, int size) {
  auto* sink = static_cast<PngSink*>(context);
  if (size > 0 && std::fwrite(data, 1, static_cast<std::size_t>(size), sink->file) != static_cast<std::size_t>(size)) {
    sink->failed = true;
  }
}

}  // namespace

SaveResult write_screenshot_png(const std::filesystem::path& path, const Rgba8Image& image, bool overwrite) {
  const std::string name = path.string();
  if (image.empty() || image.pixels.size() != static_cast<std::size_t>(image.width) * image.height * 4) {
    return {false, name + ": nothing to write (empty image)"};
  }
  // "x" (C11, glibc): create exclusively, fail with EEXIST if the file exists.
  std::FILE* f = std::fopen(name.c_str(), overwrite ? "wb" : "wbx");
  if (!f) {
    if (errno == EEXIST) return {false, name + ": exists (not overwritten)"};
    return {false, name + ": " + std::strerror(errno)};
  }
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(image.width) * image.height * 3);
  for (std::size_t i = 0, n = rgb.size() / 3; i < n; ++i) {
    rgb[i * 3 + 0] = image.pixels[i * 4 + 0];
    rgb[i * 3 + 1] = image.pixels[i * 4 + 1];
    rgb[i * 3 + 2] = image.pixels[i * 4 + 2];
  }
  PngSink sink{f};
  const int encoded =
      stbi_write_png_to_func(write_chunk, &sink, image.width, image.height, 3, rgb.data(), image.width * 3);
  const bool closed = std::fclose(f) == 0;
  if (!encoded || sink.failed || !closed) {
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
    return {false, name + ": could not write PNG data"};
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
