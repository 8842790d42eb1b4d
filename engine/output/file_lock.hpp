#pragma once
// An exclusive lock for a read-modify-write of one file by several processes
// (two `flocsim calibrate` extending one table): the lock is held on a hidden
// companion file, .NAME.lock in the same folder, which the holder removes
// when it lets go, so that nothing is left beside the file. A waiter that
// finds its lock file replaced in the meantime locks the new one: only one
// process ever holds the lock of a path. Combined with write_file_atomically
// or TemporaryFile, readers see the old or the new file, writers never lose
// each other's changes. (A lock is shared with a child forked while it is
// held, as any flock: fork before taking it.)
#include <filesystem>
#include <memory>

namespace flocsim::output {

class FileLock {
 public:
  // Blocks until this process holds the lock of `path`. Throws
  // std::runtime_error with the system's reason when the lock file cannot be
  // made (a missing or read-only folder).
  explicit FileLock(const std::filesystem::path& path);
  ~FileLock();

  // The lock of `path` if no other process holds it now, without waiting;
  // nullptr where one does, with that holder's process id in *holder (0 where
  // it cannot be read), or where the file system offers no locks (some NFS,
  // Lustre and FUSE mounts), with *holder = -1. Throws as the constructor does.
  static std::unique_ptr<FileLock> try_lock(const std::filesystem::path& path,
                                            long* holder = nullptr);
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

  // The companion file that carries the lock of `path`.
  static std::filesystem::path lock_file(const std::filesystem::path& path);

 private:
  // wait: block until the lock is free; otherwise held() tells whether it was
  FileLock(const std::filesystem::path& path, bool wait);
  bool held() const { return fd_ >= 0; }
  bool unsupported_ = false;  // flock refused by the file system itself

  std::filesystem::path lock_path_;
  int fd_ = -1;
};

}  // namespace flocsim::output
