#pragma once
// Files that readers must never see half-written (result.json, progress.json,
// checkpoints) are written to a temporary name in the same directory, flushed
// to disk with fsync, and renamed over the final name: rename is atomic, so a
// reader sees either the old complete file or the new complete file.
#include <filesystem>
#include <string>

namespace flocsim::output {

void write_file_atomically(const std::filesystem::path& path, const std::string& content);

// For files written by a library (HDF5): write to path(), then commit() makes
// it final (fsync of the file and its directory, rename). A TemporaryFile
// destroyed without a commit (an exception on the way) removes its file, so
// a failed write never replaces the previous complete file nor leaves debris.
class TemporaryFile {
 public:
  explicit TemporaryFile(std::filesystem::path final_path);
  ~TemporaryFile();
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  const std::filesystem::path& path() const { return temporary_; }
  void commit();

 private:
  std::filesystem::path final_, temporary_;
  bool committed_ = false;
};

}  // namespace flocsim::output
