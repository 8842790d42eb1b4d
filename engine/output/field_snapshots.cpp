#include "engine/output/field_snapshots.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "engine/output/atomic_file.hpp"
#include "engine/output/hdf5_file.hpp"

namespace flocsim::output {

namespace fs = std::filesystem;

fs::path snapshot_file(const fs::path& directory, long step) {
  char name[32];
  std::snprintf(name, sizeof name, "step_%010ld.h5", step);
  return directory / name;
}

std::vector<long> snapshot_steps(const fs::path& directory) {
  std::vector<long> steps;
  if (!fs::is_directory(directory)) return steps;
  for (const auto& e : fs::directory_iterator(directory)) {
    long step = 0;
    char tail = 0;
    const std::string name = e.path().filename().string();
    // complete snapshots only: temporaries start with a dot
    if (std::sscanf(name.c_str(), "step_%ld.h%c", &step, &tail) == 2 && name.size() == 18)
      steps.push_back(step);
  }
  std::sort(steps.begin(), steps.end());
  return steps;
}

void write_field_snapshot(const fs::path& directory, const FieldSnapshot& s) {
  fs::create_directories(directory);
  {
    TemporaryFile tmp(snapshot_file(directory, s.step));
    Hdf5File file(tmp.path(), Hdf5File::Mode::create);
    const std::vector<hsize_t> shape = {static_cast<hsize_t>(s.nz), static_cast<hsize_t>(s.ny),
                                        static_cast<hsize_t>(s.nx)};
    file.write("/density", shape, s.density->data());
    file.write("/velocity_x", shape, s.ux->data());
    file.write("/velocity_y", shape, s.uy->data());
    file.write("/velocity_z", shape, s.uz->data());
    file.set_attribute("/", "step", static_cast<std::int64_t>(s.step));
    file.close();
    tmp.commit();
  }
  // The index lists every complete snapshot file on disk.
  const std::string folder = directory.filename().string();
  const std::string dims =
      std::to_string(s.nz) + " " + std::to_string(s.ny) + " " + std::to_string(s.nx);
  std::ostringstream x;
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n<Domain>\n"
    << "<Grid Name=\"liquid\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (long step : snapshot_steps(directory)) {
    const std::string file = folder + "/" + snapshot_file("", step).string();
    x << "<Grid Name=\"step " << step << "\" GridType=\"Uniform\">\n"
      << "  <Time Value=\"" << step
      << "\"/>\n"
      // cell-centred data on a grid of (n+1)^3 nodes with unit spacing
      << "  <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"" << s.nz + 1 << " " << s.ny + 1
      << " " << s.nx + 1 << "\"/>\n"
      << "  <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n"
      << "    <DataItem Dimensions=\"3\" Format=\"XML\">0 0 0</DataItem>\n"
      << "    <DataItem Dimensions=\"3\" Format=\"XML\">1 1 1</DataItem>\n  </Geometry>\n";
    for (const char* name : {"density", "velocity_x", "velocity_y", "velocity_z"})
      x << "  <Attribute Name=\"" << name << "\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
        << "    <DataItem Dimensions=\"" << dims
        << "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << file << ":/" << name
        << "</DataItem>\n  </Attribute>\n";
    x << "</Grid>\n";
  }
  x << "</Grid>\n</Domain>\n</Xdmf>\n";
  fs::path xdmf = directory;
  xdmf += ".xdmf";
  write_file_atomically(xdmf, x.str());
}

}  // namespace flocsim::output
