#pragma once
// Base64 (RFC 4648, with padding) for the tests that write glTF documents
// with their buffers embedded as data: URIs.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace accelviz::test {

inline std::string base64(std::string_view data) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto byte = [&](std::size_t i) { return std::uint32_t(static_cast<unsigned char>(data[i])); };
  std::string out;
  for (std::size_t i = 0; i < data.size(); i += 3) {
    std::uint32_t v = byte(i) << 16;
    if (i + 1 < data.size()) v |= byte(i + 1) << 8;
    if (i + 2 < data.size()) v |= byte(i + 2);
    out += t[v >> 18];
    out += t[(v >> 12) & 63];
    out += i + 1 < data.size() ? t[(v >> 6) & 63] : '=';
    out += i + 2 < data.size() ? t[v & 63] : '=';
  }
  return out;
}

inline std::string base64(const std::vector<unsigned char>& data) {
  return base64(std::string_view(reinterpret_cast<const char*>(data.data()), data.size()));
}

}  // namespace accelviz::test
