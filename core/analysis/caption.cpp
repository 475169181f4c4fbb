#include "core/analysis/caption.h"

#include <algorithm>

namespace accelviz {

std::vector<std::string> wrap_caption(const std::string& text, int max_chars, int max_lines) {
  std::vector<std::string> lines;
  if (max_chars <= 0 || max_lines <= 0) return lines;
  std::size_t at = 0;
  while (at < text.size()) {
    if (static_cast<int>(lines.size()) == max_lines - 1 && text.size() - at > static_cast<std::size_t>(max_chars)) {
      lines.push_back(text.substr(at, static_cast<std::size_t>(std::max(0, max_chars - 2))) + "..");
      break;
    }
    std::size_t len = std::min(text.size() - at, static_cast<std::size_t>(max_chars));
    if (at + len < text.size()) {
      // Break after the last ", " or " " that fits (its space ends the line), else mid-word.
      const std::size_t space = text.rfind(' ', at + len);
      if (space != std::string::npos && space > at) len = space - at + 1;
    }
    std::string line = text.substr(at, len);
    while (!line.empty() && line.back() == ' ') line.pop_back();
    lines.push_back(line);
    at += len;
  }
  return lines;
}

RgbImage add_caption(const RgbImage& frame, const std::string& caption) {
  const int scale = frame.width >= 1000 ? 2 : 1;
  const int pad = 4 * scale;
  const int max_chars = std::max(0, (frame.width - 2 * pad) / (kFontAdvance * scale));
  const std::vector<std::string> lines = wrap_caption(caption, max_chars, kCaptionMaxLines);
  const int line_height = (kFontGlyphRows + 1) * scale;  // 7 rows of glyph and 2 of descender, 1 of spacing
  // The last line without its spacing row, then the padding.
  const int strip = pad + std::max<int>(1, static_cast<int>(lines.size())) * line_height - scale + pad;
  RgbImage out(frame.width, frame.height + strip, glm::u8vec3(28, 30, 34));
  std::copy(frame.pixels.begin(), frame.pixels.end(), out.pixels.begin());
  for (std::size_t i = 0; i < lines.size(); ++i)
    draw_text(out, pad, frame.height + pad + static_cast<int>(i) * line_height, lines[i], glm::u8vec3(225, 228, 232),
              scale);
  return out;
}

}  // namespace accelviz
