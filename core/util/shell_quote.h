#pragma once
// A word for a POSIX shell, for the command lines accelviz prints and records
// (captions, side-cars, the machine record): pasted back, they run as they
// were. Plain words stay as they are; anything else ('?' of a built-in
// scene's query, spaces, quotes) is single-quoted, a ' written as '\''.
#include <cctype>
#include <string>
#include <string_view>

namespace accelviz {

inline std::string shell_quote(const std::string& s) {
  bool plain = !s.empty();
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) ||
          std::string_view("-_./,:=+").find(c) != std::string_view::npos))
      plain = false;
  if (plain) return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace accelviz
