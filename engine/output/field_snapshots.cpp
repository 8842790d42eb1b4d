#include "engine/output/field_snapshots.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "engine/output/atomic_file.hpp"
#include "engine/output/hdf5_file.hpp"

namespace flocsim::output {

namespace {

std::string group_name(long step) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "/step_%010ld", step);
  return buf;
}

herr_t collect_step(hid_t, const char* name, const H5L_info_t*, void* out) {
  long step = 0;
  if (std::sscanf(name, "step_%ld", &step) == 1) static_cast<std::vector<long>*>(out)->push_back(step);
  return 0;
}

void write_xdmf(const std::filesystem::path& h5, const std::vector<long>& steps, int nx, int ny, int nz) {
  const std::string file = h5.filename().string();
  std::ostringstream x;
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n<Domain>\n"
    << "<Grid Name=\"liquid\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (long step : steps) {
    const std::string g = group_name(step);
    const std::string dims = std::to_string(nz) + " " + std::to_string(ny) + " " + std::to_string(nx);
    x << "<Grid Name=\"step " << step << "\" GridType=\"Uniform\">\n"
      << "  <Time Value=\"" << step << "\"/>\n"
      // cell-centred data on a grid of (n+1)^3 nodes with unit spacing
      << "  <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"" << nz + 1 << " " << ny + 1 << " "
      << nx + 1 << "\"/>\n"
      << "  <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n"
      << "    <DataItem Dimensions=\"3\" Format=\"XML\">0 0 0</DataItem>\n"
      << "    <DataItem Dimensions=\"3\" Format=\"XML\">1 1 1</DataItem>\n  </Geometry>\n";
    for (const char* name : {"density", "velocity_x", "velocity_y", "velocity_z"})
      x << "  <Attribute Name=\"" << name << "\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
        << "    <DataItem Dimensions=\"" << dims << "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">"
        << file << ":" << g << "/" << name << "</DataItem>\n  </Attribute>\n";
    x << "</Grid>\n";
  }
  x << "</Grid>\n</Domain>\n</Xdmf>\n";
  auto xdmf = h5;
  xdmf.replace_extension(".xdmf");
  write_file_atomically(xdmf, x.str());
}

}  // namespace

std::vector<long> snapshot_steps(const std::filesystem::path& h5) {
  std::vector<long> steps;
  if (!std::filesystem::exists(h5)) return steps;
  hid_t f = H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return steps;
  H5Literate(f, H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_step, &steps);
  H5Fclose(f);
  std::sort(steps.begin(), steps.end());
  return steps;
}

void append_field_snapshot(const std::filesystem::path& h5, const FieldSnapshot& s) {
  {
    Hdf5File file(h5, std::filesystem::exists(h5) ? Hdf5File::Mode::append : Hdf5File::Mode::create);
    const std::string g = group_name(s.step);
    if (file.exists(g)) file.remove(g);
    file.create_group(g);
    const std::vector<hsize_t> shape = {static_cast<hsize_t>(s.nz), static_cast<hsize_t>(s.ny),
                                        static_cast<hsize_t>(s.nx)};
    file.write(g + "/density", shape, s.density->data());
    file.write(g + "/velocity_x", shape, s.ux->data());
    file.write(g + "/velocity_y", shape, s.uy->data());
    file.write(g + "/velocity_z", shape, s.uz->data());
    file.set_attribute(g, "step", static_cast<std::int64_t>(s.step));
  }
  write_xdmf(h5, snapshot_steps(h5), s.nx, s.ny, s.nz);
}

}  // namespace flocsim::output
