#include "engine/output/hdf5_file.hpp"

#include <stdexcept>

namespace flocsim::output {

namespace {

template <class T>
hid_t memory_type();
template <>
hid_t memory_type<double>() {
  return H5T_NATIVE_DOUBLE;
}
template <>
hid_t memory_type<float>() {
  return H5T_NATIVE_FLOAT;
}
template <>
hid_t memory_type<std::int64_t>() {
  return H5T_NATIVE_INT64;
}
template <>
hid_t memory_type<std::uint8_t>() {
  return H5T_NATIVE_UINT8;
}

// Closes an HDF5 handle with the matching function when it leaves scope.
struct Handle {
  hid_t id;
  herr_t (*close)(hid_t);
  ~Handle() {
    if (id >= 0) close(id);
  }
};

// The operating system's reason behind the HDF5 error on the stack, such as
// "No space left on device", which HDF5's file driver records in the text of
// its error entry ("..., errno = 28, error message = 'No space left on device', ...").
std::string system_cause() {
  std::string cause;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_DOWNWARD,
      [](unsigned, const H5E_error2_t* e, void* out) -> herr_t {
        const std::string desc = e && e->desc ? e->desc : "";
        const std::string key = "error message = '";
        const auto at = desc.find(key);
        if (at == std::string::npos) return 0;
        const auto end = desc.find('\'', at + key.size());
        *static_cast<std::string*>(out) = desc.substr(at + key.size(), end - at - key.size());
        return 1;  // the first system error is the cause
      },
      &cause);
  H5Eclear2(H5E_DEFAULT);
  return cause;
}

[[noreturn]] void fail(const std::string& what) {
  const std::string cause = system_cause();
  throw std::runtime_error(cause.empty() ? what : what + ": " + cause);
}

}  // namespace

Hdf5File::Hdf5File(const std::filesystem::path& path, Mode mode) : path_(path) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported by exceptions below
  switch (mode) {
    case Mode::create:
      file_ = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
      break;
    case Mode::read:
      file_ = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
      break;
    case Mode::append:
      file_ = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
      break;
  }
  if (file_ < 0) fail("cannot open HDF5 file " + path.string());
}

Hdf5File::~Hdf5File() {
  if (file_ >= 0) H5Fclose(file_);
}

void Hdf5File::close() {
  if (file_ < 0) return;
  const herr_t flushed = H5Fflush(file_, H5F_SCOPE_LOCAL);
  const herr_t closed = H5Fclose(file_);
  file_ = -1;
  if (flushed < 0 || closed < 0) fail("cannot complete HDF5 file " + path_.string());
}

void Hdf5File::create_group(const std::string& name) {
  Handle g{H5Gcreate2(file_, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose};
  if (g.id < 0) fail(path_.string() + ": cannot create group " + name);
}

bool Hdf5File::exists(const std::string& name) const {
  return H5Lexists(file_, name.c_str(), H5P_DEFAULT) > 0;
}

void Hdf5File::remove(const std::string& name) {
  if (H5Ldelete(file_, name.c_str(), H5P_DEFAULT) < 0)
    fail(path_.string() + ": cannot remove " + name);
}

template <class T>
void Hdf5File::write(const std::string& name, const std::vector<hsize_t>& shape, const T* data) {
  Handle space{H5Screate_simple(static_cast<int>(shape.size()), shape.data(), nullptr), H5Sclose};
  Handle set{H5Dcreate2(file_, name.c_str(), memory_type<T>(), space.id, H5P_DEFAULT, H5P_DEFAULT,
                        H5P_DEFAULT),
             H5Dclose};
  if (set.id < 0) fail(path_.string() + ": cannot create dataset " + name);
  if (H5Dwrite(set.id, memory_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    fail(path_.string() + ": cannot write dataset " + name);
}

template <class T>
std::vector<T> Hdf5File::read(const std::string& name, std::vector<hsize_t>* shape) const {
  Handle set{H5Dopen2(file_, name.c_str(), H5P_DEFAULT), H5Dclose};
  if (set.id < 0) fail(path_.string() + ": no dataset " + name);
  Handle space{H5Dget_space(set.id), H5Sclose};
  const int rank = H5Sget_simple_extent_ndims(space.id);
  std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
  H5Sget_simple_extent_dims(space.id, dims.data(), nullptr);
  hsize_t n = 1;
  for (hsize_t d : dims) n *= d;
  std::vector<T> out(n);
  if (n > 0 && H5Dread(set.id, memory_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0)
    fail(path_.string() + ": cannot read dataset " + name);
  if (shape) *shape = dims;
  return out;
}

template void Hdf5File::write<double>(const std::string&, const std::vector<hsize_t>&,
                                      const double*);
template void Hdf5File::write<float>(const std::string&, const std::vector<hsize_t>&, const float*);
template void Hdf5File::write<std::int64_t>(const std::string&, const std::vector<hsize_t>&,
                                            const std::int64_t*);
template void Hdf5File::write<std::uint8_t>(const std::string&, const std::vector<hsize_t>&,
                                            const std::uint8_t*);
template std::vector<double> Hdf5File::read<double>(const std::string&,
                                                    std::vector<hsize_t>*) const;
template std::vector<float> Hdf5File::read<float>(const std::string&, std::vector<hsize_t>*) const;
template std::vector<std::int64_t> Hdf5File::read<std::int64_t>(const std::string&,
                                                                std::vector<hsize_t>*) const;
template std::vector<std::uint8_t> Hdf5File::read<std::uint8_t>(const std::string&,
                                                                std::vector<hsize_t>*) const;

namespace {

hid_t open_object(hid_t file, const std::string& object) {
  return H5Oopen(file, object.c_str(), H5P_DEFAULT);
}

void write_attribute(hid_t file, const std::filesystem::path& path, const std::string& object,
                     const std::string& key, hid_t type, const void* value) {
  Handle obj{open_object(file, object), H5Oclose};
  if (obj.id < 0) fail(path.string() + ": no object " + object);
  if (H5Aexists(obj.id, key.c_str()) > 0) H5Adelete(obj.id, key.c_str());
  Handle space{H5Screate(H5S_SCALAR), H5Sclose};
  Handle attr{H5Acreate2(obj.id, key.c_str(), type, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose};
  if (attr.id < 0 || H5Awrite(attr.id, type, value) < 0)
    fail(path.string() + ": cannot write attribute " + object + "@" + key);
}

template <class T>
T read_attribute(hid_t file, const std::filesystem::path& path, const std::string& object,
                 const std::string& key, hid_t type) {
  Handle obj{open_object(file, object), H5Oclose};
  if (obj.id < 0) fail(path.string() + ": no object " + object);
  Handle attr{H5Aopen(obj.id, key.c_str(), H5P_DEFAULT), H5Aclose};
  T value{};
  if (attr.id < 0 || H5Aread(attr.id, type, &value) < 0)
    fail(path.string() + ": cannot read attribute " + object + "@" + key);
  return value;
}

}  // namespace

void Hdf5File::set_attribute(const std::string& object, const std::string& key, double value) {
  write_attribute(file_, path_, object, key, H5T_NATIVE_DOUBLE, &value);
}

void Hdf5File::set_attribute(const std::string& object, const std::string& key,
                             std::int64_t value) {
  write_attribute(file_, path_, object, key, H5T_NATIVE_INT64, &value);
}

void Hdf5File::set_attribute(const std::string& object, const std::string& key,
                             const std::string& value) {
  Handle type{H5Tcopy(H5T_C_S1), H5Tclose};
  H5Tset_size(type.id, value.size() + 1);
  H5Tset_strpad(type.id, H5T_STR_NULLTERM);
  write_attribute(file_, path_, object, key, type.id, value.c_str());
}

double Hdf5File::attribute_double(const std::string& object, const std::string& key) const {
  return read_attribute<double>(file_, path_, object, key, H5T_NATIVE_DOUBLE);
}

std::int64_t Hdf5File::attribute_int(const std::string& object, const std::string& key) const {
  return read_attribute<std::int64_t>(file_, path_, object, key, H5T_NATIVE_INT64);
}

std::string Hdf5File::attribute_string(const std::string& object, const std::string& key) const {
  Handle obj{open_object(file_, object), H5Oclose};
  if (obj.id < 0) fail(path_.string() + ": no object " + object);
  Handle attr{H5Aopen(obj.id, key.c_str(), H5P_DEFAULT), H5Aclose};
  if (attr.id < 0) fail(path_.string() + ": no attribute " + object + "@" + key);
  Handle type{H5Aget_type(attr.id), H5Tclose};
  const std::size_t size = H5Tget_size(type.id);
  std::string value(size, '\0');
  Handle mem{H5Tcopy(H5T_C_S1), H5Tclose};
  H5Tset_size(mem.id, size);
  if (H5Aread(attr.id, mem.id, value.data()) < 0)
    fail(path_.string() + ": cannot read attribute " + object + "@" + key);
  value.resize(value.find('\0') == std::string::npos ? size : value.find('\0'));
  return value;
}

}  // namespace flocsim::output
