#pragma once
// Files are read and written only when they are regular files. An input (a
// scene, a file a scene names, a ray file) that is a FIFO blocks its reader
// and one that is a directory or a device reads as garbage or without end; an
// output that is a FIFO blocks its writer, and a failed write or a rename
// would remove or replace a device node.
#include <limits.h>    // NAME_MAX
#include <sys/stat.h>  // stat, fstat
#include <unistd.h>    // pathconf

#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace accelviz {

/// "" when `path` names a regular file (a symbolic link counts as what it
/// names) of at most `max_bytes`, its size then in `size`; else the problem,
/// without the path: "no such file", "cannot be read: ..." (a loop of
/// symbolic links, a folder without permission), "is a directory, not a
/// file", "is not a regular file", "cannot read its size: ...", and for a larger file
/// `too_large` (a reader's own words for its limit), by default "is larger
/// than N bytes".
inline std::string input_file_problem(const std::string& path, std::uintmax_t max_bytes, std::uintmax_t& size,
                                      std::string_view too_large = {}) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  // A loop of symbolic links or a folder without search permission read as "no such file".
  if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory)
    return "cannot be read: " + ec.message();
  if (ec || !std::filesystem::exists(st)) return "no such file";
  if (std::filesystem::is_directory(st)) return "is a directory, not a file";
  if (!std::filesystem::is_regular_file(st)) return "is not a regular file";
  size = std::filesystem::file_size(path, ec);
  if (ec) return "cannot read its size: " + ec.message();
  if (size > max_bytes)
    return too_large.empty() ? "is larger than " + std::to_string(max_bytes) + " bytes" : std::string(too_large);
  return {};
}

/// Reads a small text file the app keeps or is given (settings, the panel
/// layout, a shader, a script) into `text`: "" on success, else the problem
/// without the path, as input_file_problem words it ("no such file", "is
/// not a regular file" for a FIFO, which would block the reader, "is
/// larger than N bytes", ...) or "read error".
inline std::string read_text_file(const std::string& path, std::uintmax_t max_bytes, std::string& text) {
  std::uintmax_t size = 0;
  if (std::string problem = input_file_problem(path, max_bytes, size); !problem.empty()) return problem;
  std::ifstream in(path, std::ios::binary);
  if (!in) return "cannot be opened for reading";
  text.assign(static_cast<std::size_t>(size), '\0');
  if (size > 0 && !in.read(text.data(), static_cast<std::streamsize>(size))) return "read error";
  return {};
}

/// The extension of `path`'s file name in lower case, with its dot (".glb");
/// "" when it has none, as for a name that is only an extension (".glb").
/// What the loaders dispatch on and the writers check output names with.
inline std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

/// The extension, in lower case, when `path`'s file name is nothing else (".png", ".GLB": a hidden
/// file's name, which has no extension of its own, so the name before the extension is missing);
/// else "".
inline std::string bare_extension(const std::string& path) {
  std::string probe(1, 'x');  // appended, not "x" + name: GCC 12's -Wrestrict false positive
  probe += std::filesystem::path(path).filename().string();
  const std::string ext = lower_extension(probe);
  return ext.size() + 1 == probe.size() ? ext : std::string();
}

/// "" when every name along `path` fits the file system, else the problem,
/// without the path: "a name in it is N bytes long; the file system takes at
/// most M (NAME_MAX)". The limit is that of the nearest folder on the path
/// that exists (pathconf). Checked before long work: creating the file
/// failed with "File name too long" only after it.
inline std::string name_length_problem(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  std::error_code ec;
  fs::path dir = p.parent_path();
  while (!dir.empty() && !fs::is_directory(dir, ec) && dir != dir.parent_path()) dir = dir.parent_path();
  long max = ::pathconf(dir.empty() ? "." : dir.c_str(), _PC_NAME_MAX);
  if (max <= 0) max = NAME_MAX;  // no limit said: the usual one
  for (const fs::path& part : p)
    if (part.native().size() > static_cast<std::size_t>(max))
      return "a name in it is " + std::to_string(part.native().size()) + " bytes long; the file system takes at most " +
             std::to_string(max);
  return {};
}

/// "" when `path` may be created or overwritten as a file: nothing is there,
/// or a regular file is (a symbolic link counts as what it names); else the
/// problem, without the path: name_length_problem's, "is a directory", "is
/// not a regular file (a FIFO, device or socket)", or, for the regular file
/// this process's standard output or error goes to (`-o /dev/stdout -f >
/// out.hits`, or the file's own name), "is this program's standard output":
/// the rename replaced that file, and what the program printed there before
/// and after went to the old one, lost.
inline std::string output_path_problem(const std::string& path) {
  if (std::string problem = name_length_problem(path); !problem.empty()) return problem;
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st)) return {};
  if (std::filesystem::is_regular_file(st)) {
    struct stat file {
    }, stream{};
    if (::stat(path.c_str(), &file) == 0)
      for (const int fd : {1, 2})
        if (::fstat(fd, &stream) == 0 && stream.st_dev == file.st_dev && stream.st_ino == file.st_ino)
          return fd == 1 ? "is this program's standard output (name a file of its own)"
                         : "is this program's standard error (name a file of its own)";
    return {};
  }
  if (std::filesystem::is_directory(st)) return "is a directory";
  return "is not a regular file (a FIFO, device or socket)";
}

}  // namespace accelviz
