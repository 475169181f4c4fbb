#pragma once
// An image size written "WxH", as the command line, the GPU benchmark and
// the tests take it.
#include <charconv>
#include <optional>
#include <string_view>

namespace accelviz {

/// Largest width or height accepted (a 16384 x 16384 image of 4-byte
/// pixels is 1 GiB).
inline constexpr int kMaxImageSide = 16384;

struct ImageSize {
  int width = 800;
  int height = 600;
};

/// "800x600" (also "800X600"), each side a decimal integer in
/// 1..kMaxImageSide with nothing around it; nullopt otherwise.
inline std::optional<ImageSize> parse_image_size(std::string_view text) {
  const std::size_t x = text.find_first_of("xX");
  if (x == std::string_view::npos) return std::nullopt;
  auto side = [](std::string_view s, int& out) {
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return !s.empty() && ec == std::errc() && ptr == s.data() + s.size() && out >= 1 && out <= kMaxImageSide;
  };
  ImageSize size;
  if (!side(text.substr(0, x), size.width) || !side(text.substr(x + 1), size.height)) return std::nullopt;
  return size;
}

}  // namespace accelviz
