#pragma once
// Shared by the libFuzzer targets: the loaders read files, so each input is
// written to a file in a private temporary directory (external buffer URIs
// then resolve inside it, never to the user's files) and loaded from there.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace accelviz_fuzz {

inline const std::string& temp_dir() {
  static const std::string dir = [] {
    const char* base = std::getenv("TMPDIR");
    std::string tmpl = std::string(base && *base ? base : "/tmp") + "/accelviz-fuzz-XXXXXX";
    if (!mkdtemp(tmpl.data())) std::abort();
    return tmpl;
  }();
  return dir;
}

/// Writes the input to DIR/input.EXT and returns the path.
inline std::string write_input(const std::uint8_t* data, std::size_t size, const char* ext) {
  const std::string path = temp_dir() + "/input." + ext;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  return path;
}

}  // namespace accelviz_fuzz
