#include "core/util/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>

#include "core/util/file_checks.h"

namespace accelviz {

namespace {

namespace fs = std::filesystem;

/// Writes all of `bytes` to fd; 0 or the errno of the failure.
int write_all(int fd, std::string_view bytes) {
  const char* p = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  return 0;
}

std::string errno_text(const char* what, int err) {
  return std::string(what) + std::strerror(err);
}

/// A fresh name ".accelviz-XXXXXXXX.tmp" in `dir`: 22 characters whatever the
/// target's name, so that it fits wherever the target's name fits. The
/// process id, a counter and the clock, mixed (splitmix64), make a clash rare;
/// O_EXCL makes one harmless.
fs::path fresh_name(const fs::path& dir) {
  static std::atomic<std::uint64_t> counter{0};
  std::uint64_t x = (static_cast<std::uint64_t>(::getpid()) << 32) ^ counter.fetch_add(1, std::memory_order_relaxed) ^
                    static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  x ^= x >> 31;
  static const char hex[] = "0123456789abcdef";
  std::string name = ".accelviz-";
  for (int i = 0; i < 8; ++i) name += hex[(x >> (4 * i)) & 15u];
  name += ".tmp";
  return dir / name;
}

/// Whether link(2) failed because the file system has no hard links (then a
/// check and a rename stand in for it).
bool no_hard_links(int err) {
  return err == EPERM || err == ENOTSUP || err == EOPNOTSUPP || err == EMLINK;
}

}  // namespace

OutputWrite OutputFileSet::add(const std::string& path, std::initializer_list<std::string_view> parts) {
  OutputWrite r;
  const auto fail = [&](const std::string& problem) {
    r.problem = problem;
    r.path = path;
    return r;
  };
  const auto refuse_existing = [&] {
    r.exists = true;
    return fail("exists");
  };
  if (path.empty()) return fail("an output file needs a name");
  if (const std::string problem = output_path_problem(path); !problem.empty()) return fail(problem);
  std::error_code ec;
  const fs::file_status link_status = fs::symlink_status(path, ec);
  const bool present = fs::exists(link_status);  // a dangling link counts: something has the name
  if (present && !overwrite_) return refuse_existing();

  // The file whose name is taken: the one a symbolic link names, so that the
  // temporary lies in its folder (rename stays in one file system).
  fs::path target = path;
  if (present && fs::is_symlink(link_status)) {
    // Through the link's own text: weakly_canonical of a dangling link stops at the link itself, and
    // the rename replaced the link with a file.
    fs::path dest = fs::read_symlink(path, ec);
    if (ec) return fail("cannot follow the link: " + ec.message());
    if (dest.is_relative()) dest = fs::path(path).parent_path() / dest;
    target = fs::weakly_canonical(dest, ec);
    if (ec) return fail("cannot follow the link: " + ec.message());
  }
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");

  // A fresh name: O_EXCL never opens what is there (a link, a FIFO, an
  // earlier run's leftover).
  fs::path tmp;
  int fd = -1;
  for (int attempt = 0; attempt < 64 && fd < 0; ++attempt) {
    tmp = fresh_name(dir);
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0666);
    if (fd < 0 && errno != EEXIST) return fail(errno_text("cannot create: ", errno));
  }
  if (fd < 0) return fail("cannot create a temporary file beside it");

  int err = 0;
  for (const std::string_view part : parts)
    if (err == 0) err = write_all(fd, part);
  // A file replaced keeps who may read it: its permission bits (rename gave the
  // name a new file of mode 0666 & ~umask, so a private 0600 file became
  // world-readable) and, where the process may change them (root), its owner
  // and group. The owner first: chown clears set-user-ID bits.
  struct stat old {};
  if (err == 0 && overwrite_ && ::stat(target.c_str(), &old) == 0 && S_ISREG(old.st_mode)) {
    if (::geteuid() == 0) (void)!::fchown(fd, old.st_uid, old.st_gid);  // best effort
    if (::fchmod(fd, old.st_mode & 07777) != 0) err = errno;
  }
  // Flushed before the name moves: after a crash the name never points at
  // a file whose data did not reach the disk.
  if (err == 0 && ::fsync(fd) != 0) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err != 0) {
    ::unlink(tmp.c_str());
    return fail(errno_text("write failed: ", err));
  }
  staged_.push_back({path, target.string(), tmp.string()});
  return r;
}

void OutputFileSet::discard() {
  for (const Staged& s : staged_) ::unlink(s.tmp.c_str());
  staged_.clear();
}

OutputWrite OutputFileSet::commit() {
  OutputWrite r;
  // What each name held before, to undo: the old file's hard link (backup), or
  // nothing (the name is unlinked again).
  struct Undo {
    std::string backup;    ///< "" where there was no file, or no hard link could be made
    bool placed = false;   ///< the name was given
    bool existed = false;  ///< a file had the name before
  };
  std::vector<Undo> undo(staged_.size());
  const auto drop_backups = [&] {
    for (const Undo& u : undo)
      if (!u.backup.empty()) ::unlink(u.backup.c_str());
  };
  const auto fail = [&](const Staged& s, const std::string& problem, bool exists = false) {
    // Back to how it was: each name given returns to its old file or to nothing.
    for (std::size_t i = 0; i < staged_.size(); ++i) {
      if (!undo[i].placed) continue;
      if (!undo[i].backup.empty()) {
        if (::rename(undo[i].backup.c_str(), staged_[i].target.c_str()) == 0) undo[i].backup.clear();
      } else if (!undo[i].existed) {
        ::unlink(staged_[i].target.c_str());
      }
    }
    drop_backups();
    r.problem = problem;
    r.path = s.path;
    r.exists = exists;
    discard();
    return r;
  };

  // 1. With overwrite, a second name (a hard link) for each file to be
  //    replaced, so that a later failure can put it back. A file system
  //    without hard links replaces without one (nothing to put back).
  if (overwrite_ && staged_.size() > 1)
    for (std::size_t i = 0; i < staged_.size(); ++i) {
      struct stat st {};
      if (::lstat(staged_[i].target.c_str(), &st) != 0) continue;
      undo[i].existed = true;
      for (int attempt = 0; attempt < 64; ++attempt) {
        const std::string backup = fresh_name(fs::path(staged_[i].target).parent_path()).string();
        if (::link(staged_[i].target.c_str(), backup.c_str()) == 0) {
          undo[i].backup = backup;
          break;
        }
        if (errno == EEXIST) continue;
        if (no_hard_links(errno)) break;
        return fail(staged_[i], errno_text("cannot keep the old file while replacing it: ", errno));
      }
    }

  // 2. The names, in order.
  for (std::size_t i = 0; i < staged_.size(); ++i) {
    const Staged& s = staged_[i];
    if (overwrite_) {
      if (::rename(s.tmp.c_str(), s.target.c_str()) != 0) return fail(s, errno_text("cannot replace it: ", errno));
      undo[i].placed = true;
      continue;
    }
    // Without overwrite: link() fails with EEXIST when anything has the name,
    // however late it appeared. A file system without hard links falls back
    // to a check and a rename.
    if (::link(s.tmp.c_str(), s.target.c_str()) == 0) {
      undo[i].placed = true;
      ::unlink(s.tmp.c_str());
      continue;
    }
    const int err = errno;
    if (err == EEXIST) return fail(s, "exists", true);
    if (!no_hard_links(err)) return fail(s, errno_text("cannot create: ", err));
    if (name_taken(s.target)) return fail(s, "exists", true);
    if (::rename(s.tmp.c_str(), s.target.c_str()) != 0) return fail(s, errno_text("cannot create: ", errno));
    undo[i].placed = true;
  }
  drop_backups();
  staged_.clear();
  return r;
}

OutputWrite write_output_file(const std::string& path, std::initializer_list<std::string_view> parts, bool overwrite) {
  OutputFileSet set(overwrite);
  if (OutputWrite w = set.add(path, parts); !w.ok()) return w;
  return set.commit();
}

OutputWrite write_output_files(const std::vector<OutputBytes>& files, bool overwrite) {
  OutputFileSet set(overwrite);
  for (const OutputBytes& f : files)
    if (OutputWrite w = set.add(f.path, {f.bytes}); !w.ok()) return w;
  return set.commit();
}

// ---- OutputFolder ----------------------------------------------------------------

OutputFolder::OutputFolder(std::string dir, std::vector<std::string> known, bool overwrite)
    : dir_(std::move(dir)), known_(std::move(known)), overwrite_(overwrite), set_(overwrite) {}

OutputFolder::~OutputFolder() {
  if (!committed_) abandon();
}

std::string OutputFolder::problem(const std::string& dir, const std::vector<std::string>& known, bool overwrite,
                                  bool* holds) {
  if (holds) *holds = false;
  std::error_code ec;
  const fs::path p(dir);
  if (fs::exists(p, ec) && !fs::is_directory(p, ec)) return "exists and is not a directory";
  if (!fs::is_directory(p, ec)) return "";
  // Not even overwriting replaces a FIFO, device or socket (or a folder) by such a name.
  for (const std::string& name : known)
    if (const std::string problem = output_path_problem((p / name).string()); !problem.empty())
      return name + ": " + problem;
  if (overwrite) return "";
  for (const std::string& name : known)
    if (name_taken((p / name).string())) {
      if (holds) *holds = true;
      return "holds " + name;
    }
  return "";
}

OutputWrite OutputFolder::open() {
  OutputWrite r;
  r.path = dir_;
  bool holds = false;
  if (dir_.empty())
    r.problem = "the output folder's name is empty";
  else
    r.problem = problem(dir_, known_, overwrite_, &holds);
  r.exists = holds;
  if (!r.ok()) return r;
  // The folders made here, outermost first, so that a failed run removes them again.
  std::error_code ec;
  std::vector<fs::path> missing;
  for (fs::path d = fs::path(dir_).lexically_normal(); !d.empty() && !fs::exists(d, ec); d = d.parent_path()) {
    missing.push_back(d);
    if (d == d.parent_path()) break;
  }
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    if (it->filename().empty()) continue;  // "dir/" normalised keeps a trailing empty name
    if (!fs::create_directory(*it, ec) || ec) {
      abandon();
      r.problem = "cannot create directory" + (ec ? ": " + ec.message() : std::string());
      return r;
    }
    created_.push_back(it->string());
  }
  r.path.clear();
  return r;
}

OutputWrite OutputFolder::add(const std::string& name, std::initializer_list<std::string_view> parts) {
  if (std::find(known_.begin(), known_.end(), name) == known_.end()) {
    OutputWrite r;
    r.path = (fs::path(dir_) / name).string();
    r.problem = "not one of the folder's known names (a bug)";
    return r;
  }
  written_.push_back(name);
  return set_.add((fs::path(dir_) / name).string(), parts);
}

OutputWrite OutputFolder::commit() {
  OutputWrite r = set_.commit();
  if (!r.ok()) {
    abandon();
    return r;
  }
  committed_ = true;
  // The earlier run's files that this one did not replace: only names of the
  // scheme, never anything else in the folder.
  std::error_code ec;
  for (const std::string& name : known_) {
    if (std::find(written_.begin(), written_.end(), name) != written_.end()) continue;
    const fs::path f = fs::path(dir_) / name;
    if (!name_taken(f.string())) continue;
    if (!fs::remove(f, ec) || ec) stale_left_.push_back(f.string() + (ec ? ": " + ec.message() : std::string()));
  }
  return r;
}

void OutputFolder::abandon() {
  set_.discard();
  // Only folders left empty: remove() does not remove one that holds anything.
  std::error_code ec;
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) fs::remove(*it, ec);
  created_.clear();
}

bool name_taken(const std::string& path) {
  std::error_code ec;
  return fs::exists(fs::symlink_status(path, ec));
}

}  // namespace accelviz
