#include "core/util/output_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
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

}  // namespace

OutputWrite write_output_file(const std::string& path, std::initializer_list<std::string_view> parts, bool overwrite) {
  OutputWrite r;
  const auto fail = [&](const std::string& problem) {
    r.problem = problem;
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
  if (present && !overwrite) return refuse_existing();

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
  // earlier run's leftover); the process id and a counter make a clash rare.
  static std::atomic<unsigned> counter{0};
  fs::path tmp;
  int fd = -1;
  for (int attempt = 0; attempt < 64 && fd < 0; ++attempt) {
    // Appended piece by piece: "." + string trips GCC 12's -Wrestrict (a false positive).
    std::string name(1, '.');
    name += target.filename().string();
    name += ".tmp-";
    name += std::to_string(::getpid());
    name += '-';
    name += std::to_string(counter.fetch_add(1, std::memory_order_relaxed));
    tmp = dir / name;
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0666);
    if (fd < 0 && errno != EEXIST) return fail(std::string("cannot create: ") + std::strerror(errno));
  }
  if (fd < 0) return fail("cannot create a temporary file beside it");

  int err = 0;
  for (const std::string_view part : parts)
    if (err == 0) err = write_all(fd, part);
  // Flushed before the name moves: after a crash the name never points at
  // a file whose data did not reach the disk.
  if (err == 0 && ::fsync(fd) != 0) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;
  const auto drop_tmp = [&] { ::unlink(tmp.c_str()); };
  if (err != 0) {
    drop_tmp();
    return fail(std::string("write failed: ") + std::strerror(err));
  }

  if (overwrite) {
    if (::rename(tmp.c_str(), target.c_str()) != 0) {
      err = errno;
      drop_tmp();
      return fail(std::string("cannot replace it: ") + std::strerror(err));
    }
    return r;
  }
  // Without overwrite: link() fails with EEXIST when anything has the name,
  // however late it appeared. A file system without hard links falls back
  // to a check and a rename.
  if (::link(tmp.c_str(), target.c_str()) == 0) {
    drop_tmp();
    return r;
  }
  err = errno;
  if (err == EEXIST) {
    drop_tmp();
    return refuse_existing();
  }
  if (err == EPERM || err == ENOTSUP || err == EOPNOTSUPP || err == EMLINK) {
    if (fs::exists(fs::symlink_status(target, ec))) {
      drop_tmp();
      return refuse_existing();
    }
    if (::rename(tmp.c_str(), target.c_str()) == 0) return r;
    err = errno;
  }
  drop_tmp();
  return fail(std::string("cannot create: ") + std::strerror(err));
}

bool name_taken(const std::string& path) {
  std::error_code ec;
  return fs::exists(fs::symlink_status(path, ec));
}

}  // namespace accelviz
