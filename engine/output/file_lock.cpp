#include "engine/output/file_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
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

FileLock::FileLock(const std::filesystem::path& path) : lock_path_(lock_file(path)) {
  for (;;) {
    fd_ = ::open(lock_path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0)
      throw std::runtime_error("cannot lock " + path.string() + " (" + lock_path_.string() +
                               "): " + std::strerror(errno));
    while (::flock(fd_, LOCK_EX) != 0)
      if (errno != EINTR)
        throw std::runtime_error("cannot lock " + lock_path_.string() + ": " +
                                 std::strerror(errno));
    // The previous holder removes the file as it lets go: the lock counts only
    // if the path still names the file locked here.
    struct stat held {
    }, now{};
    if (::fstat(fd_, &held) == 0 && ::stat(lock_path_.c_str(), &now) == 0 &&
        held.st_dev == now.st_dev && held.st_ino == now.st_ino)
      return;
    ::close(fd_);
  }
}

FileLock::~FileLock() {
  ::unlink(lock_path_.c_str());  // while still held: see the constructor
  ::close(fd_);
}

}  // namespace flocsim::output
