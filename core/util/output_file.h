#pragma once
// Every file the tool writes for the user (PNGs, ray and hit files, glTF
// exports, CSV/JSON results, screenshots' side-cars, settings) goes through
// write_output_file or an OutputFileSet, so that nothing the user had is lost:
//  - the bytes go to a new temporary file beside the target (created
//    exclusively under a fresh name, so no link, FIFO or file already there
//    is followed, waited on or overwritten), are flushed to disk, and only
//    then take the target's name: a failed write (a full disk, a size limit)
//    leaves the target as it was and no temporary behind;
//  - the temporary's name, ".accelviz-XXXXXXXX.tmp", has a fixed length, so
//    any target name the file system takes can be written (a name made from
//    the target's own, longer than it, failed for names near NAME_MAX only
//    after all the work);
//  - without `overwrite` the target's name is taken with link(2), which
//    fails when anything has that name, even something created after the
//    caller's own check; with it, with rename(2), which replaces the file in
//    one step (a symbolic link is followed: the file it names is replaced);
//  - a file replaced keeps its permission bits (a private file stays
//    private) and, where the process may (root), its owner and group. A hard
//    link to the old file keeps the old content: rename gives the name a new
//    file, which is what makes the replacement atomic;
//  - a target that is a directory, FIFO, device or socket is refused.
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

namespace accelviz {

struct OutputWrite {
  std::string problem;  ///< "" on success, else one line without the path ("exists", "write failed: ...")
  std::string path;     ///< on failure, the file the problem is about (of several: the first that failed)
  bool exists = false;  ///< refused because the path exists and overwrite was false
  bool ok() const { return problem.empty(); }
};

/// Several files written all or nothing (the images of `render -s a,b`, a
/// sweep's results): add() writes each one's temporary beside it; commit()
/// gives them their names only once all were written, and undoes the names
/// already given when one fails (a file replaced comes back from a hard link
/// kept until the end). A set dropped or failed leaves no temporary behind.
class OutputFileSet {
 public:
  explicit OutputFileSet(bool overwrite) : overwrite_(overwrite) {}
  ~OutputFileSet() { discard(); }
  OutputFileSet(const OutputFileSet&) = delete;
  OutputFileSet& operator=(const OutputFileSet&) = delete;

  /// Writes the concatenation of `parts` to a temporary beside `path`. On
  /// failure nothing of this file is left; the files added before stay
  /// staged (commit or discard them).
  OutputWrite add(const std::string& path, std::initializer_list<std::string_view> parts);
  /// Gives every staged file its name, in the order added, or none of them.
  /// The set is empty afterwards either way.
  OutputWrite commit();
  /// Removes the staged temporaries (what the destructor does).
  void discard();
  std::size_t size() const { return staged_.size(); }

 private:
  struct Staged {
    std::string path;    ///< as given (messages)
    std::string target;  ///< the file whose name is taken (a symbolic link followed)
    std::string tmp;     ///< its temporary
  };
  bool overwrite_;
  std::vector<Staged> staged_;
};

/// Writes the concatenation of `parts` to `path` (see above): a set of one.
/// Never throws for I/O problems: the caller words them as its own error type.
OutputWrite write_output_file(const std::string& path, std::initializer_list<std::string_view> parts, bool overwrite);

/// Whether something has the name `path` (a file, folder, or symbolic link: a dangling link too),
/// as write_output_file without `overwrite` sees it. For callers choosing a free name: a plain
/// exists() is false for a dangling link, which the write then refuses.
bool name_taken(const std::string& path);

/// A file of a set: its path and its bytes.
struct OutputBytes {
  std::string path;
  std::string bytes;
};

/// Writes `files` all or nothing (an OutputFileSet).
OutputWrite write_output_files(const std::vector<OutputBytes>& files, bool overwrite);

/// A command's results in one folder (sweep, refit): files whose names come
/// from the command's naming scheme, `known` (every name any of its runs can
/// write). Only those names are ever refused, replaced or removed: a file of
/// the user's own in the folder (sweep-mynotes.png) is never touched.
/// open() checks the folder again (it may have changed during the work) and
/// creates it where missing; add() stages each file; commit() gives them
/// their names (all or nothing), then removes the files of `known` an earlier
/// run left that this run did not write (stale charts would mislead). A run
/// that fails leaves the folder as it was: no temporary, the old results,
/// and a folder open() created removed again.
class OutputFolder {
 public:
  OutputFolder(std::string dir, std::vector<std::string> known, bool overwrite);
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  /// "" or why `dir` cannot take the results, without the path: "exists and is
  /// not a directory", "<name>: is not a regular file ..." (not even
  /// overwriting replaces those), and without `overwrite`, when it holds one
  /// of `known`, "holds <name>" with `*holds` set. Changes nothing.
  static std::string problem(const std::string& dir, const std::vector<std::string>& known, bool overwrite,
                             bool* holds = nullptr);

  /// problem() again, then the folder is made where missing.
  OutputWrite open();
  /// `name` (one of `known`) in the folder; see OutputFileSet::add.
  OutputWrite add(const std::string& name, std::initializer_list<std::string_view> parts);
  /// The staged files take their names; then the stale ones are removed
  /// (those that could not be are listed in stale_left()).
  OutputWrite commit();
  const std::vector<std::string>& stale_left() const { return stale_left_; }

 private:
  void abandon();

  std::string dir_;
  std::vector<std::string> known_;
  bool overwrite_;
  OutputFileSet set_;
  std::vector<std::string> written_;     ///< names added
  std::vector<std::string> created_;     ///< folders open() made, innermost last
  std::vector<std::string> stale_left_;  ///< stale files that could not be removed
  bool committed_ = false;
};

}  // namespace accelviz
