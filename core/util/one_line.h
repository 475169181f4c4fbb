#pragma once
// Error and warning messages that stay on one line, whatever the thrower put
// in them: the loaders keep a message's first non-blank line (tinygltf and
// tinyobjloader can quote a whole data URI or several warnings joined), the
// app joins a multi-line exception text into one line.
#include <algorithm>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace accelviz {

/// Long messages are cut to this many characters (plus "...").
inline constexpr std::size_t kMaxMessageChars = 300;

/// First non-blank line of `text`, trimmed of spaces and tabs and cut to
/// `max_chars` (kMaxMessageChars unless said), with every other control byte
/// (a NUL from a decoded URI, say, which would end the message where what() is
/// read) shown as '?'; "unknown error" when there is none.
inline std::string first_line(const std::string& text, std::size_t max_chars = kMaxMessageChars) {
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find_first_of("\r\n", start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    const auto first = line.find_first_not_of(" \t");
    if (first != std::string::npos) {
      line = line.substr(first, line.find_last_not_of(" \t") - first + 1);
      if (line.size() > max_chars) line = line.substr(0, max_chars) + "...";
      for (char& c : line)
        if ((static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7F) c = '?';
      return line;
    }
    start = end + 1;
  }
  return "unknown error";
}

/// "1 mesh", "8 meshes", "2 instances": `n` and the English plural of `word`
/// when n != 1 (-es after -s, -x, -ch, -sh).
inline std::string count_of(std::size_t n, std::string_view word) {
  std::string out = std::to_string(n) + " " + std::string(word);
  if (n == 1) return out;
  const bool es = word.ends_with("sh") || word.ends_with("ch") || word.ends_with('s') || word.ends_with('x');
  return out + (es ? "es" : "s");
}

/// `text` with every newline (and CR, tab) made a space and every other
/// control byte shown as '?' (nothing is dropped): the one line `accelviz:`
/// prints, whatever a file name held.
inline std::string joined_line(std::string text) {
  for (std::size_t i = 0; i < text.size();) {
    char& c = text[i];
    const auto u = static_cast<unsigned char>(c);
    if (c == '\n' || c == '\r' || c == '\t') {
      c = ' ';
    } else if (u < 0x20 || u == 0x7F) {
      c = '?';  // an ESC in a file name recoloured the terminal
    } else if (u >= 0x80) {
      // UTF-8 (a file name in any language) is kept; a byte that starts no well-formed sequence
      // (a binary file's bytes quoted in a JSON error) is '?', not sent to the terminal raw.
      const std::size_t len = u >= 0xC2 && u <= 0xDF ? 2 : u >= 0xE0 && u <= 0xEF ? 3 : u >= 0xF0 && u <= 0xF4 ? 4 : 0;
      bool ok = len > 0 && i + len <= text.size();
      for (std::size_t k = 1; ok && k < len; ++k) ok = (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
      if (ok && len == 3) {
        const auto b1 = static_cast<unsigned char>(text[i + 1]);
        ok = !(u == 0xE0 && b1 < 0xA0) && !(u == 0xED && b1 >= 0xA0);  // overlong, surrogate
      } else if (ok && len == 4) {
        const auto b1 = static_cast<unsigned char>(text[i + 1]);
        ok = !(u == 0xF0 && b1 < 0x90) && !(u == 0xF4 && b1 >= 0x90);  // overlong, beyond U+10FFFF
      }
      if (ok) {
        i += len;
        continue;
      }
      c = '?';
    }
    ++i;
  }
  return text;
}

}  // namespace accelviz
