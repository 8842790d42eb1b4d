#pragma once
// A small RAII layer over the HDF5 C API: the few operations flocsim needs
// (datasets of float/double/int64 with any shape, scalar and string
// attributes, groups), each throwing with the file and object name on error.
#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace flocsim::output {

class Hdf5File {
 public:
  enum class Mode { create, read, append };
  Hdf5File(const std::filesystem::path& path, Mode mode);
  ~Hdf5File();  // closes, ignoring errors: call close() where they matter
  // Flushes and closes, throwing when HDF5 cannot complete the file (full
  // disk, quota): a checkpoint must not be committed after a failed close.
  void close();
  Hdf5File(const Hdf5File&) = delete;
  Hdf5File& operator=(const Hdf5File&) = delete;

  void create_group(const std::string& name);
  bool exists(const std::string& name) const;
  void remove(const std::string& name);

  // Dataset `name` of the given shape (slowest dimension first).
  template <class T>
  void write(const std::string& name, const std::vector<hsize_t>& shape, const T* data);
  template <class T>
  std::vector<T> read(const std::string& name, std::vector<hsize_t>* shape = nullptr) const;

  void set_attribute(const std::string& object, const std::string& key, double value);
  void set_attribute(const std::string& object, const std::string& key, std::int64_t value);
  void set_attribute(const std::string& object, const std::string& key, const std::string& value);
  double attribute_double(const std::string& object, const std::string& key) const;
  std::int64_t attribute_int(const std::string& object, const std::string& key) const;
  std::string attribute_string(const std::string& object, const std::string& key) const;

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  hid_t file_ = -1;
};

}  // namespace flocsim::output
