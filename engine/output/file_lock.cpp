#include "engine/output/file_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>

namespace flocsim::output {

std::filesystem::path FileLock::lock_file(const std::filesystem::path& path) {
  // appended piece by piece: GCC 12 warns (-Wrestrict, falsely) on "." + string
  std::string name = ".";
  name += path.filename().string();
  name += ".lock";
  return path.parent_path() / name;
}

FileLock::FileLock(const std::filesystem::path& path) : FileLock(path, true) {}

FileLock::FileLock(const std::filesystem::path& path, bool wait) : lock_path_(lock_file(path)) {
  for (;;) {
    // O_NOFOLLOW: a link put where the lock file goes is refused, not followed
    fd_ = ::open(lock_path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd_ < 0)
      throw std::runtime_error("cannot lock " + path.string() + " (" + lock_path_.string() +
                               "): " + std::strerror(errno));
    while (::flock(fd_, wait ? LOCK_EX : LOCK_EX | LOCK_NB) != 0) {
      const bool no_locks_here =
          errno == ENOLCK || errno == ENOSYS || errno == EOPNOTSUPP || errno == EINVAL;
      if (!wait && (errno == EWOULDBLOCK || no_locks_here)) {
        unsupported_ = no_locks_here;
        ::close(fd_);
        fd_ = -1;
        return;
      }
      if (errno != EINTR)
        throw std::runtime_error("cannot lock " + lock_path_.string() + ": " +
                                 std::strerror(errno));
    }
    // The previous holder removes the file as it lets go: the lock counts only
    // if the path still names the file locked here.
    struct stat held {
    }, now{};
    if (::fstat(fd_, &held) == 0 && ::stat(lock_path_.c_str(), &now) == 0 &&
        held.st_dev == now.st_dev && held.st_ino == now.st_ino) {
      // who holds it, for a process that finds it taken (best effort: the
      // lock itself is the flock, not this text)
      const std::string pid = std::to_string(::getpid()) + "\n";
      if (::ftruncate(fd_, 0) == 0) {
        [[maybe_unused]] const ssize_t written = ::pwrite(fd_, pid.data(), pid.size(), 0);
      }
      return;
    }
    ::close(fd_);
  }
}

std::unique_ptr<FileLock> FileLock::try_lock(const std::filesystem::path& path, long* holder) {
  std::unique_ptr<FileLock> lock(new FileLock(path, false));
  if (lock->held()) return lock;
  if (lock->unsupported_) {
    if (holder) *holder = -1;
    return nullptr;
  }
  if (holder) {
    *holder = 0;
    std::ifstream in(lock_file(path));
    if (!(in >> *holder)) *holder = 0;
  }
  return nullptr;
}

FileLock::~FileLock() {
  if (fd_ < 0) return;
  ::unlink(lock_path_.c_str());  // while still held: see the constructor
  ::close(fd_);
}

}  // namespace flocsim::output
