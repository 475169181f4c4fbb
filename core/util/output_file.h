#pragma once
// Outputs are regular files: a name that is already a FIFO, a device or a
// socket is refused before anything is opened (writing to a FIFO blocks until
// a reader comes; a failed write would remove the node; a rename would replace
// it).
#include <filesystem>
#include <string>

namespace accelviz {

/// "" when `path` may be created or overwritten as a file: nothing is there,
/// or a regular file is (a symbolic link counts as what it names); else
/// "PATH: is a directory" or "PATH: is not a regular file (a FIFO, device or
/// socket)".
inline std::string output_path_problem(const std::string& path) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st) || std::filesystem::is_regular_file(st)) return {};
  if (std::filesystem::is_directory(st)) return path + ": is a directory";
  return path + ": is not a regular file (a FIFO, device or socket)";
}

}  // namespace accelviz
