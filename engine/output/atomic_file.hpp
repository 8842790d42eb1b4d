#pragma once
// Files that readers must never see half-written (result.json, progress.json,
// checkpoints) are written to a temporary name in the same directory, flushed
// to disk with fsync, and renamed over the final name: rename is atomic, so a
// reader sees either the old complete file or the new complete file.
#include <filesystem>
#include <string>

namespace flocsim::output {

void write_file_atomically(const std::filesystem::path& path, const std::string& content);

// For files written by a library (HDF5): the temporary name to write to, and
// the commit that makes it final (fsync of the file and its directory, rename).
std::filesystem::path temporary_name_for(const std::filesystem::path& path);
void commit_temporary(const std::filesystem::path& temporary, const std::filesystem::path& path);

}  // namespace flocsim::output
