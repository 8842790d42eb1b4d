#include "engine/run/sphere_checkpoint.hpp"

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/input/input_reader.hpp"
#include "engine/output/atomic_file.hpp"
#include "engine/output/hdf5_file.hpp"
#include "engine/result_names/result_names.hpp"
#include "engine/run/lattice_files.hpp"
#include "engine/run/output_directory.hpp"

namespace flocsim::run {

namespace fs = std::filesystem;
using spheres::Vec3;

namespace {

std::vector<double> flatten(const std::vector<Vec3>& v) {
  std::vector<double> out;
  for (const auto& x : v) out.insert(out.end(), {x.x(), x.y(), x.z()});
  return out;
}

std::vector<Vec3> unflatten(const std::vector<double>& v) {
  std::vector<Vec3> out(v.size() / 3);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = Vec3(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
  return out;
}

}  // namespace

template <class Real>
void write_checkpoint(const fs::path& dir, const cases::SuspensionCase& c, const SphereRunState& s,
                      const Protocol& protocol, const events::DirectInteractions& contacts,
                      const Liquid<Real>* liquid, double wall_s) {
  output::TemporaryFile tmp(dir / "checkpoint.h5");
  {
    output::Hdf5File f(tmp.path(), output::Hdf5File::Mode::create);
    const hsize_t n = s.spheres.size();
    f.create_group("/spheres");
    f.write("/spheres/position", {n, 3}, flatten(s.spheres.position).data());
    f.write("/spheres/velocity", {n, 3}, flatten(s.spheres.velocity).data());
    f.write("/spheres/angular_velocity", {n, 3}, flatten(s.spheres.angular_velocity).data());
    std::vector<std::int64_t> pairs;
    for (const auto& [i, j] : contacts.attached_pairs()) pairs.insert(pairs.end(), {i, j});
    f.write("/spheres/attached_pairs", {pairs.size() / 2, 2}, pairs.data());
    const auto& k = contacts.counters();
    const std::vector<std::int64_t> counters = {static_cast<std::int64_t>(k.collisions),
                                                static_cast<std::int64_t>(k.well_entries),
                                                static_cast<std::int64_t>(k.escapes),
                                                static_cast<std::int64_t>(k.edge_bounces),
                                                static_cast<std::int64_t>(k.neighbour_rebuilds),
                                                static_cast<std::int64_t>(k.steps)};
    f.write("/event_counters", {counters.size()}, counters.data());
    if (liquid) {
      // the lattice populations, and the inside-liquid momenta whose change
      // the first resumed step feeds to the sphere equations
      save_populations(f, liquid->fluid);
      f.set_attribute("/fluid", "time_step", static_cast<std::int64_t>(liquid->fluid.time_step()));
      const coupling::SphereCoupling<Real>& coupling = *liquid->coupling;
      f.write("/spheres/internal_momentum", {n, 3}, flatten(coupling.internal_momentum()).data());
      f.write("/spheres/internal_angular_momentum", {n, 3},
              flatten(coupling.internal_angular_momentum()).data());
      // the coupling scheme's own memory (control forcing: every marker's force)
      const auto memory = coupling.memory();
      if (!memory.empty()) f.create_group("/coupling");
      for (const auto& a : memory)
        f.write("/coupling/" + a.name, {a.values.size()}, a.values.data());
    }
    f.create_group("/series");
    for (std::size_t col = 0; col < s.series.columns(); ++col)
      f.write("/series/" + s.series.names()[col], {s.series.column(col).size()},
              s.series.column(col).data());
    f.write("/size_distribution_sum", {s.size_distribution_sum.size()},
            s.size_distribution_sum.data());
    const auto m = s.microstructure.accumulated();
    f.create_group("/microstructure");
    f.write("/microstructure/g_counts", {m.g_counts.size()}, m.g_counts.data());
    f.write("/microstructure/h_counts", {m.h_counts.size()}, m.h_counts.data());
    f.set_attribute("/microstructure", "g_normalisation", m.g_normalisation);
    f.set_attribute("/microstructure", "h_pairs", m.h_pairs);
    f.set_attribute("/microstructure", "configurations",
                    static_cast<std::int64_t>(m.configurations));
    f.write("/phi_x", {s.phi_x.size()}, s.phi_x.data());
    f.set_attribute("/", "case", c.to_json().dump());
    f.set_attribute("/", "precision", std::string(sizeof(Real) == 8 ? "double" : "float"));
    f.set_attribute("/", "step", static_cast<std::int64_t>(s.step));
    protocol.write(f);
    f.set_attribute("/", "momentum_initial", s.momentum_initial);
    f.set_attribute("/", "momentum_initial_set", static_cast<std::int64_t>(s.momentum_initial_set));
    f.set_attribute("/", "wall_s", wall_s);
    const RunExtremes& e = s.extremes;
    const std::vector<double> extremes = {
        e.momentum_drift, e.liquid_speed, e.liquid_speed_outside_spheres,
        e.sphere_speed,   e.mass_first,   e.mass_first_set ? 1.0 : 0.0,
        e.mass_drift};
    f.write("/extremes", {extremes.size()}, extremes.data());
    f.close();
  }
  tmp.commit();
}

template <class Real>
void read_checkpoint(const fs::path& file, const cases::SuspensionCase& c, SphereRunState& s,
                     Protocol& protocol, events::DirectInteractions& contacts,
                     Liquid<Real>* liquid) {
  output::Hdf5File f(file, output::Hdf5File::Mode::read);
  const auto recorded = nlohmann::json::parse(f.attribute_string("/", "case"));
  require_resumable(file, recorded, c.to_json());
  s.spheres.position = unflatten(f.read<double>("/spheres/position"));
  s.spheres.velocity = unflatten(f.read<double>("/spheres/velocity"));
  s.spheres.angular_velocity = unflatten(f.read<double>("/spheres/angular_velocity"));
  if (s.spheres.position.size() != static_cast<std::size_t>(c.derived.sphere_count))
    throw std::runtime_error(file.string() + ": holds " +
                             std::to_string(s.spheres.position.size()) + " spheres, the case has " +
                             std::to_string(c.derived.sphere_count));
  const auto pairs = f.read<std::int64_t>("/spheres/attached_pairs");
  std::vector<std::pair<int, int>> attached;
  for (std::size_t k = 0; k + 1 < pairs.size(); k += 2)
    attached.emplace_back(static_cast<int>(pairs[k]), static_cast<int>(pairs[k + 1]));
  const auto k = f.read<std::int64_t>("/event_counters");
  events::EventCounters counters;
  counters.collisions = static_cast<std::uint64_t>(k[0]);
  counters.well_entries = static_cast<std::uint64_t>(k[1]);
  counters.escapes = static_cast<std::uint64_t>(k[2]);
  counters.edge_bounces = static_cast<std::uint64_t>(k[3]);
  counters.neighbour_rebuilds = static_cast<std::uint64_t>(k[4]);
  counters.steps = static_cast<std::uint64_t>(k[5]);
  if (liquid) {
    restore_populations(f, liquid->fluid, file);
    liquid->fluid.set_time_step(f.attribute_int("/fluid", "time_step"));
    coupling::SphereCoupling<Real>& coupling = *liquid->coupling;
    coupling.set_internal_momenta(unflatten(f.read<double>("/spheres/internal_momentum")),
                                  unflatten(f.read<double>("/spheres/internal_angular_momentum")));
    std::vector<coupling::NamedArray> memory = coupling.memory();  // the names it keeps
    for (auto& a : memory) {
      const std::string name = "/coupling/" + a.name;
      if (!f.exists(name))
        throw std::runtime_error(file.string() + ": holds no " + name + ", which " +
                                 coupling.scheme().describe() + " needs to resume");
      a.values = f.read<double>(name);
    }
    coupling.restore_memory(memory);
  }
  for (std::size_t col = 0; col < s.series.columns(); ++col) {
    const std::string& column = s.series.names()[col];
    std::string name = "/series/" + column;
    // checkpoints written before C_sph had its present name
    if (column == result_names::column::C_sph && !f.exists(name))
      name = "/series/contacts_per_sphere";
    // columns added after the checkpoint was written: unknown (NaN) so far
    if (!f.exists(name) && col > 0) {
      s.series.column(col).assign(s.series.column(0).size(),
                                  std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    s.series.column(col) = f.read<double>(name);
  }
  s.size_distribution_sum = f.read<double>("/size_distribution_sum");
  observables::PairStructure::Accumulated m;
  m.g_counts = f.read<double>("/microstructure/g_counts");
  m.h_counts = f.read<double>("/microstructure/h_counts");
  m.g_normalisation = f.attribute_double("/microstructure", "g_normalisation");
  m.h_pairs = f.attribute_double("/microstructure", "h_pairs");
  m.configurations = f.attribute_int("/microstructure", "configurations");
  s.microstructure.restore(m);
  s.phi_x = f.read<double>("/phi_x");
  s.step = f.attribute_int("/", "step");
  protocol.read(f);
  s.momentum_initial = f.attribute_double("/", "momentum_initial");
  s.momentum_initial_set = f.attribute_int("/", "momentum_initial_set") != 0;
  s.wall_s = f.attribute_double("/", "wall_s");
  // checkpoints written before the extremes were recorded: they count from here
  if (f.exists("/extremes")) {
    const auto e = f.read<double>("/extremes");
    if (e.size() != 7)
      throw std::runtime_error(file.string() + ": /extremes holds " + std::to_string(e.size()) +
                               " values, expected 7");
    s.extremes = {.momentum_drift = e[0],
                  .liquid_speed = e[1],
                  .liquid_speed_outside_spheres = e[2],
                  .sphere_speed = e[3],
                  .mass_first = e[4],
                  .mass_first_set = e[5] != 0,
                  .mass_drift = e[6]};
  }
  protocol.restore_well(contacts);
  contacts.set_attached_pairs(attached);
  contacts.set_counters(counters);
}

template void write_checkpoint<float>(const fs::path&, const cases::SuspensionCase&,
                                      const SphereRunState&, const Protocol&,
                                      const events::DirectInteractions&, const Liquid<float>*,
                                      double);
template void write_checkpoint<double>(const fs::path&, const cases::SuspensionCase&,
                                       const SphereRunState&, const Protocol&,
                                       const events::DirectInteractions&, const Liquid<double>*,
                                       double);
template void read_checkpoint<float>(const fs::path&, const cases::SuspensionCase&, SphereRunState&,
                                     Protocol&, events::DirectInteractions&, Liquid<float>*);
template void read_checkpoint<double>(const fs::path&, const cases::SuspensionCase&,
                                      SphereRunState&, Protocol&, events::DirectInteractions&,
                                      Liquid<double>*);

}  // namespace flocsim::run
