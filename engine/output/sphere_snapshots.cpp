#include "engine/output/sphere_snapshots.hpp"

#include <sstream>

#include "engine/output/atomic_file.hpp"
#include "engine/output/field_snapshots.hpp"
#include "engine/output/hdf5_file.hpp"

namespace flocsim::output {

namespace fs = std::filesystem;

namespace {
std::vector<double> flatten(const std::vector<spheres::Vec3>& v) {
  std::vector<double> out;
  out.reserve(3 * v.size());
  for (const auto& x : v) out.insert(out.end(), {x.x(), x.y(), x.z()});
  return out;
}
}  // namespace

void write_sphere_snapshot(const fs::path& directory, long step, double time,
                           const spheres::SphereSet& s, const spheres::PeriodicBox& box,
                           const std::vector<int>& aggregate_of) {
  fs::create_directories(directory);
  const hsize_t n = s.size();
  {
    TemporaryFile tmp(snapshot_file(directory, step));
    Hdf5File f(tmp.path(), Hdf5File::Mode::create);
    f.write("/position", {n, 3}, flatten(s.position).data());
    f.write("/velocity", {n, 3}, flatten(s.velocity).data());
    f.write("/angular_velocity", {n, 3}, flatten(s.angular_velocity).data());
    std::vector<std::int64_t> ids(aggregate_of.begin(), aggregate_of.end());
    ids.resize(n, -1);
    f.write("/aggregate", {n}, ids.data());
    f.set_attribute("/", "step", static_cast<std::int64_t>(step));
    f.set_attribute("/", "time", time);
    f.set_attribute("/", "radius", s.radius);
    const double box_cells[3] = {box.length.x(), box.length.y(), box.length.z()};
    f.write("/box", {3}, box_cells);
    f.close();
    tmp.commit();
  }
  const std::string folder = directory.filename().string();
  std::ostringstream x;
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n<Domain>\n"
    << "<Grid Name=\"spheres\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (long st : snapshot_steps(directory)) {
    const fs::path path = snapshot_file(directory, st);
    const double t = Hdf5File(path, Hdf5File::Mode::read).attribute_double("/", "time");
    const std::string file = folder + "/" + path.filename().string();
    x << "<Grid Name=\"step " << st << "\" GridType=\"Uniform\">\n  <Time Value=\"" << t << "\"/>\n"
      << "  <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << n << "\"/>\n"
      << "  <Geometry GeometryType=\"XYZ\">\n    <DataItem Dimensions=\"" << n
      << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << file
      << ":/position</DataItem>\n"
      << "  </Geometry>\n"
      << "  <Attribute Name=\"velocity\" AttributeType=\"Vector\" Center=\"Node\">\n    <DataItem "
         "Dimensions=\""
      << n << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << file
      << ":/velocity</DataItem>\n"
      << "  </Attribute>\n"
      << "  <Attribute Name=\"aggregate\" AttributeType=\"Scalar\" Center=\"Node\">\n    <DataItem "
         "Dimensions=\""
      << n << "\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">" << file
      << ":/aggregate</DataItem>\n"
      << "  </Attribute>\n</Grid>\n";
  }
  x << "</Grid>\n</Domain>\n</Xdmf>\n";
  fs::path xdmf = directory;
  xdmf += ".xdmf";
  write_file_atomically(xdmf, x.str());
}

}  // namespace flocsim::output
