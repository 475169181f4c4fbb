#pragma once
// Every file the tool writes for the user (PNGs, ray and hit files, glTF
// exports, CSV/JSON results, screenshots' side-cars, settings) goes through
// write_output_file, so that nothing the user had is lost:
//  - the bytes go to a new temporary file beside the target (created
//    exclusively under a fresh name, so no link, FIFO or file already there
//    is followed, waited on or overwritten), are flushed to disk, and only
//    then take the target's name: a failed write (a full disk, a size limit)
//    leaves the target as it was and no temporary behind;
//  - without `overwrite` the target's name is taken with link(2), which
//    fails when anything has that name, even something created after the
//    caller's own check; with it, with rename(2), which replaces the file in
//    one step (a symbolic link is followed: the file it names is replaced);
//  - a target that is a directory, FIFO, device or socket is refused.
#include <initializer_list>
#include <string>
#include <string_view>

namespace accelviz {

struct OutputWrite {
  std::string problem;  ///< "" on success, else one line without the path ("exists", "write failed: ...")
  bool exists = false;  ///< refused because the path exists and overwrite was false
  bool ok() const { return problem.empty(); }
};

/// Writes the concatenation of `parts` to `path` (see above). Never throws
/// for I/O problems: the caller words them as its own error type.
OutputWrite write_output_file(const std::string& path, std::initializer_list<std::string_view> parts, bool overwrite);

/// Whether something has the name `path` (a file, folder, or symbolic link: a dangling link too),
/// as write_output_file without `overwrite` sees it. For callers choosing a free name: a plain
/// exists() is false for a dangling link, which the write then refuses.
bool name_taken(const std::string& path);

}  // namespace accelviz
