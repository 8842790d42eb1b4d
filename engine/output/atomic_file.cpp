#include "engine/output/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace flocsim::output {

namespace {

[[noreturn]] void fail(const std::string& what, const std::filesystem::path& p) {
  throw std::runtime_error(what + " " + p.string() + ": " + std::strerror(errno));
}

void fsync_path(const std::filesystem::path& p, bool directory) {
  const int fd = ::open(p.c_str(), directory ? O_RDONLY | O_DIRECTORY : O_RDONLY);
  if (fd < 0) fail("cannot open for fsync", p);
  if (::fsync(fd) != 0) {
    const int saved = errno;  // close() may overwrite it
    ::close(fd);
    errno = saved;
    fail("fsync failed for", p);
  }
  ::close(fd);
}

std::filesystem::path temporary_name_for(const std::filesystem::path& path) {
  std::string name = ".";
  name += path.filename().string();
  name += ".tmp.";
  name += std::to_string(::getpid());
  return path.parent_path() / name;
}

void commit_temporary(const std::filesystem::path& temporary, const std::filesystem::path& path) {
  fsync_path(temporary, false);
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec)
    throw std::runtime_error("cannot rename " + temporary.string() + " to " + path.string() + ": " +
                             ec.message());
  const auto dir = path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
  fsync_path(dir, true);
}

}  // namespace

TemporaryFile::TemporaryFile(std::filesystem::path final_path)
    : final_(std::move(final_path)), temporary_(temporary_name_for(final_)) {}

TemporaryFile::~TemporaryFile() {
  if (!committed_) {
    std::error_code ec;
    std::filesystem::remove(temporary_, ec);
  }
}

void TemporaryFile::commit() {
  commit_temporary(temporary_, final_);
  committed_ = true;
}

void write_file_atomically(const std::filesystem::path& path, const std::string& content) {
  TemporaryFile tmp(path);
  const int fd = ::open(tmp.path().c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) fail("cannot create", tmp.path());
  std::size_t done = 0;
  while (done < content.size()) {
    const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int saved = errno;
      ::close(fd);
      errno = saved;
      fail("cannot write", tmp.path());
    }
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) fail("cannot close", tmp.path());
  tmp.commit();
}

}  // namespace flocsim::output
