#include "engine/output/sphere_snapshots.hpp"

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

std::vector<double> flatten(const std::vector<spheres::Vec3>& v) {
  std::vector<double> out;
  out.reserve(3 * v.size());
  for (const auto& x : v) out.insert(out.end(), {x.x(), x.y(), x.z()});
  return out;
}

}  // namespace

void append_sphere_snapshot(const std::filesystem::path& h5, long step, double time,
                            const spheres::SphereSet& s, const std::vector<int>& aggregate_of) {
  std::vector<std::pair<long, double>> index;  // (step, time) of every snapshot in the file
  const hsize_t n = s.size();
  {
    const bool exists = std::filesystem::exists(h5);
    Hdf5File f(h5, exists ? Hdf5File::Mode::append : Hdf5File::Mode::create);
    if (!exists) {
      f.set_attribute("/", "radius", s.radius);
      f.write<std::int64_t>("/snapshot_steps", {0}, nullptr);
      f.write<double>("/snapshot_times", {0}, nullptr);
    }
    const std::string g = group_name(step);
    if (f.exists(g)) f.remove(g);
    f.create_group(g);
    f.write(g + "/position", {n, 3}, flatten(s.position).data());
    f.write(g + "/velocity", {n, 3}, flatten(s.velocity).data());
    f.write(g + "/angular_velocity", {n, 3}, flatten(s.angular_velocity).data());
    std::vector<std::int64_t> ids(aggregate_of.begin(), aggregate_of.end());
    ids.resize(n, -1);
    f.write(g + "/aggregate", {n}, ids.data());
    f.set_attribute(g, "step", static_cast<std::int64_t>(step));
    f.set_attribute(g, "time", time);
    // the index of snapshots, rewritten whole (it is small)
    auto steps = f.read<std::int64_t>("/snapshot_steps");
    auto times = f.read<double>("/snapshot_times");
    bool replaced = false;
    for (std::size_t k = 0; k < steps.size(); ++k)
      if (steps[k] == step) times[k] = time, replaced = true;
    if (!replaced) {
      steps.push_back(step);
      times.push_back(time);
    }
    f.remove("/snapshot_steps");
    f.remove("/snapshot_times");
    f.write("/snapshot_steps", {steps.size()}, steps.data());
    f.write("/snapshot_times", {times.size()}, times.data());
    for (std::size_t k = 0; k < steps.size(); ++k) index.emplace_back(steps[k], times[k]);
  }
  std::ostringstream x;
  const std::string file = h5.filename().string();
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n<Domain>\n"
    << "<Grid Name=\"spheres\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const auto& [st, t] : index) {
    const std::string g = group_name(st);
    x << "<Grid Name=\"step " << st << "\" GridType=\"Uniform\">\n  <Time Value=\"" << t << "\"/>\n"
      << "  <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << n << "\"/>\n"
      << "  <Geometry GeometryType=\"XYZ\">\n    <DataItem Dimensions=\"" << n
      << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << file << ":" << g
      << "/position</DataItem>\n  </Geometry>\n"
      << "  <Attribute Name=\"velocity\" AttributeType=\"Vector\" Center=\"Node\">\n    <DataItem Dimensions=\"" << n
      << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << file << ":" << g
      << "/velocity</DataItem>\n  </Attribute>\n"
      << "  <Attribute Name=\"aggregate\" AttributeType=\"Scalar\" Center=\"Node\">\n    <DataItem Dimensions=\"" << n
      << "\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">" << file << ":" << g
      << "/aggregate</DataItem>\n  </Attribute>\n</Grid>\n";
  }
  x << "</Grid>\n</Domain>\n</Xdmf>\n";
  auto xdmf = h5;
  xdmf.replace_extension(".xdmf");
  write_file_atomically(xdmf, x.str());
}

}  // namespace flocsim::output
