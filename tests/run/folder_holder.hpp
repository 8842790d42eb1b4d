#pragma once
// Another process holding an output folder's lock, as a live `flocsim run`
// does (engine/run/output_directory.hpp): forked, it takes the lock, says so,
// and waits until it is killed (SIGKILL: no destructor runs, as in a crash,
// so its lock file stays behind).
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>

#include "engine/output/file_lock.hpp"

namespace flocsim::testing {

class FolderHolder {
 public:
  explicit FolderHolder(const std::filesystem::path& dir) {
    int ready[2];
    if (::pipe(ready) != 0) throw std::runtime_error("pipe");
    pid_ = ::fork();
    if (pid_ < 0) throw std::runtime_error("fork");
    if (pid_ == 0) {
      auto lock = output::FileLock::try_lock(dir / "flocsim-run");
      const char ok = lock ? '1' : '0';
      [[maybe_unused]] const ssize_t w = ::write(ready[1], &ok, 1);
      for (;;) ::pause();
    }
    char ok = 0;
    const bool told = ::read(ready[0], &ok, 1) == 1;
    ::close(ready[0]);
    ::close(ready[1]);
    if (!told || ok != '1') {
      kill();
      throw std::runtime_error("the holder could not take the lock of " + dir.string());
    }
  }
  ~FolderHolder() { kill(); }
  FolderHolder(const FolderHolder&) = delete;
  FolderHolder& operator=(const FolderHolder&) = delete;

  pid_t pid() const { return pid_; }
  // Kills the holder outright, as a crash would.
  void kill() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

 private:
  pid_t pid_ = -1;
};

}  // namespace flocsim::testing
