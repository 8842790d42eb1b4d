#include "engine/run/sphere_run.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <fstream>
#include <limits>
#include <memory>
#include <random>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/events/direct_interactions.hpp"
#include "engine/immersed_boundary/immersed_boundary.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/lubrication/radial_lubrication.hpp"
#include "engine/observables/aggregates.hpp"
#include "engine/observables/liquid_averages.hpp"
#include "engine/observables/pair_structure.hpp"
#include "engine/observables/reference_correlations.hpp"
#include "engine/observables/suspension_averages.hpp"
#include "engine/output/atomic_file.hpp"
#include "engine/output/field_snapshots.hpp"
#include "engine/output/hdf5_file.hpp"
#include "engine/output/sphere_snapshots.hpp"
#include "engine/placement/random_placement.hpp"
#include "engine/process/stop_signal.hpp"
#include "engine/run/lattice_files.hpp"
#include "engine/run/output_directory.hpp"
#include "engine/run/run_log.hpp"
#include "engine/spheres/sphere_dynamics.hpp"

#ifndef FLOCSIM_VERSION
#define FLOCSIM_VERSION "0.1.0"
#endif

namespace flocsim::run {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using spheres::Vec3;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

using cases::SceneModules;

// ---- time series -------------------------------------------------------------
// Columns sampled every protocol.sample_every a/U_inf; scenes with a liquid add
// the settling observables of docs/model.md section 4.
std::vector<std::string> columns_of(const SceneModules& m) {
  std::vector<std::string> cols = {"step",
                                   "time",
                                   "stage",
                                   "C_sph",
                                   "mean_aggregate_size",
                                   "granular_temperature",
                                   "Re_T",
                                   "kinetic_energy",
                                   "well_energy",
                                   "collisions"};
  if (m.liquid)
    cols.insert(cols.end(), {"U_over_Uinf", "U", "F", "Re", "liquid_velocity", "sphere_velocity",
                             "momentum_balance", "liquid_velocity_all_cells", "F_all_cells"});
  return cols;
}

struct Series {
  std::vector<std::string> names;
  std::vector<std::vector<double>> data;

  explicit Series(std::vector<std::string> columns)
      : names(std::move(columns)), data(names.size()) {}
  std::size_t column(const std::string& name) const {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) throw std::logic_error("no time-series column " + name);
    return static_cast<std::size_t>(it - names.begin());
  }
  const std::vector<double>& operator[](const std::string& name) const {
    return data[column(name)];
  }
  std::size_t samples() const { return data[0].size(); }
};

// Microstructure accumulated over the statistics window (paper Fig. 2):
// g(r) with bins of 0.05a up to 5a (or just under half the box), h(theta)
// with bins of pi/60 for pairs closer than 3a.
observables::PairStructure pair_structure_for(const cases::SuspensionCase& c) {
  const double a = c.radius_cells;
  const double half_box = 0.5 * std::min({c.box.nx, c.box.ny, c.box.nz});
  return observables::PairStructure(std::min(5.0 * a, half_box - 0.05 * a), 0.05 * a, 3.0 * a,
                                    M_PI / 60);
}

// Slabs of phi(x, t): one per sphere radius along x.
int phi_slabs(const cases::SuspensionCase& c) {
  return std::max(1, static_cast<int>(std::lround(c.box.nx / c.radius_cells)));
}

// The liquid and its coupling to the spheres (every scene but granular).
template <class Real>
struct Liquid {
  lattice::FluidLattice<Real> fluid;
  immersed_boundary::ImmersedBoundary<Real> ib;
  spheres::SphereDynamicsSettings dynamics;
  std::vector<std::uint8_t> solid;  // scratch of the liquid averages

  explicit Liquid(const cases::SuspensionCase& c)
      : fluid(c.box, {c.viscosity, c.trt_magic}), ib({c.input_radius, c.ib_scheme, false}) {
    const double volume = static_cast<double>(c.box.cells());
    dynamics.external =
        spheres::settling_forces(static_cast<std::size_t>(c.sphere_count), c.radius_cells,
                                 c.density_ratio, volume, c.gravity);
    fluid.set_body_force({dynamics.external.liquid_body_force.x(), 0, 0});
    fluid.enable_force_field();
  }
};

// Everything that evolves besides the lattice: what a checkpoint holds.
struct RunState {
  spheres::SphereSet spheres;
  long step = 0;
  int stage = 1;
  long stage2_start = -1;      // step at which du was switched on
  long statistics_start = -1;  // step after which samples enter the averages
  bool stage1_stationary = false;
  Series series;
  std::vector<double> size_distribution_sum;  // sum of p(n) over statistics samples
  observables::PairStructure microstructure{1, 1, 1, 1};
  std::vector<double> phi_x;  // phi(x, t): one row of slabs per sample
  double wall_s = 0;          // before this invocation
  // momentum balance of liquid + spheres (scenes whose spheres move freely)
  double momentum_initial = 0;
  bool momentum_initial_set = false;

  explicit RunState(const SceneModules& m) : series(columns_of(m)) {}
};

struct Durations {  // protocol in time steps
  long sample, stage1_min, stage1_max, settle, statistics, snapshot, window_samples;
};

Durations durations(const cases::SuspensionCase& c) {
  const double T = c.convective_time;
  auto steps = [T](double in_convective_times) {
    return static_cast<long>(std::llround(in_convective_times * T));
  };
  Durations d;
  d.sample = std::max(1L, steps(c.sample_every));
  d.stage1_min = steps(c.stage1_min);
  d.stage1_max = steps(c.stage1_max);
  d.settle = steps(c.stage2_settle);
  d.statistics = std::max(d.sample, steps(c.statistics));
  d.snapshot = c.snapshot_every > 0 ? std::max(1L, steps(c.snapshot_every)) : 0;
  d.window_samples =
      std::max(5L, static_cast<long>(std::llround(c.stationarity_window / c.sample_every)));
  return d;
}

// Stage 2 (du at its target, then stage2_settle before statistics) exists
// only where a square well acts; elsewhere statistics begin where stage 1
// becomes stationary.
bool has_stage2(const cases::SuspensionCase& c, const SceneModules& m) {
  return m.contacts && c.escape_velocity > 0;
}

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

// ---- checkpoint ----------------------------------------------------------------
template <class Real>
void write_checkpoint(const fs::path& dir, const cases::SuspensionCase& c, const RunState& s,
                      const events::DirectInteractions& contacts, const Liquid<Real>* liquid,
                      double wall_s) {
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
      f.write("/spheres/internal_momentum", {n, 3}, flatten(liquid->ib.internal_momentum()).data());
      f.write("/spheres/internal_angular_momentum", {n, 3},
              flatten(liquid->ib.internal_angular_momentum()).data());
    }
    f.create_group("/series");
    for (std::size_t col = 0; col < s.series.names.size(); ++col)
      f.write("/series/" + s.series.names[col], {s.series.data[col].size()},
              s.series.data[col].data());
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
    f.set_attribute("/", "stage", static_cast<std::int64_t>(s.stage));
    f.set_attribute("/", "stage2_start", static_cast<std::int64_t>(s.stage2_start));
    f.set_attribute("/", "statistics_start", static_cast<std::int64_t>(s.statistics_start));
    f.set_attribute("/", "stage1_stationary", static_cast<std::int64_t>(s.stage1_stationary));
    f.set_attribute("/", "momentum_initial", s.momentum_initial);
    f.set_attribute("/", "momentum_initial_set", static_cast<std::int64_t>(s.momentum_initial_set));
    f.set_attribute("/", "wall_s", wall_s);
    f.close();
  }
  tmp.commit();
}

template <class Real>
void read_checkpoint(const fs::path& file, const cases::SuspensionCase& c, RunState& s,
                     events::DirectInteractions& contacts, Liquid<Real>* liquid) {
  output::Hdf5File f(file, output::Hdf5File::Mode::read);
  if (!resumable_under(nlohmann::json::parse(f.attribute_string("/", "case")), c.to_json()))
    throw input::InputError(
        file.string() + " belongs to a different case; remove it or use another --out directory");
  s.spheres.position = unflatten(f.read<double>("/spheres/position"));
  s.spheres.velocity = unflatten(f.read<double>("/spheres/velocity"));
  s.spheres.angular_velocity = unflatten(f.read<double>("/spheres/angular_velocity"));
  if (s.spheres.position.size() != static_cast<std::size_t>(c.sphere_count))
    throw std::runtime_error(file.string() + ": holds " +
                             std::to_string(s.spheres.position.size()) + " spheres, the case has " +
                             std::to_string(c.sphere_count));
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
    liquid->ib.set_internal_momenta(
        unflatten(f.read<double>("/spheres/internal_momentum")),
        unflatten(f.read<double>("/spheres/internal_angular_momentum")));
  }
  for (std::size_t col = 0; col < s.series.names.size(); ++col) {
    std::string name = "/series/" + s.series.names[col];
    // checkpoints written before C_sph had its present name
    if (s.series.names[col] == "C_sph" && !f.exists(name)) name = "/series/contacts_per_sphere";
    // columns added after the checkpoint was written: unknown (NaN) so far
    if (!f.exists(name) && col > 0) {
      s.series.data[col].assign(s.series.data[0].size(), std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    s.series.data[col] = f.read<double>(name);
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
  s.stage = static_cast<int>(f.attribute_int("/", "stage"));
  s.stage2_start = f.attribute_int("/", "stage2_start");
  s.statistics_start = f.attribute_int("/", "statistics_start");
  s.stage1_stationary = f.attribute_int("/", "stage1_stationary") != 0;
  s.momentum_initial = f.attribute_double("/", "momentum_initial");
  s.momentum_initial_set = f.attribute_int("/", "momentum_initial_set") != 0;
  s.wall_s = f.attribute_double("/", "wall_s");
  if (s.stage == 2) contacts.set_escape_velocity(c.escape_velocity);
  contacts.set_attached_pairs(attached);
  contacts.set_counters(counters);
}

// Distributions over the statistics window.
struct Distributions {
  std::vector<double> p;            // p(n_a), index n_a
  std::vector<double> r_over_a, g;  // g(r)
  std::vector<double> theta, h;     // h(theta), pairs closer than 3a
};

// series.h5: the time series, phi(x, t) and the steady distributions.
void write_series(const fs::path& dir, const RunState& s, int slabs, const Distributions& d) {
  output::TemporaryFile tmp(dir / "series.h5");
  {
    output::Hdf5File f(tmp.path(), output::Hdf5File::Mode::create);
    for (std::size_t col = 0; col < s.series.names.size(); ++col)
      f.write("/" + s.series.names[col], {s.series.data[col].size()}, s.series.data[col].data());
    // phi(x, t): rows are samples (times in /time), columns slabs of width L / slabs
    const auto slab_count = static_cast<hsize_t>(slabs);
    f.write("/phi_x", {s.phi_x.size() / slab_count, slab_count}, s.phi_x.data());
    f.create_group("/distributions");
    f.write("/distributions/size_distribution", {d.p.size()}, d.p.data());
    f.write("/distributions/r_over_a", {d.r_over_a.size()}, d.r_over_a.data());
    f.write("/distributions/g", {d.g.size()}, d.g.data());
    f.write("/distributions/theta", {d.theta.size()}, d.theta.data());
    f.write("/distributions/h", {d.h.size()}, d.h.data());
    f.close();
  }
  tmp.commit();
}

// The samples of one column taken after the statistics started.
std::vector<double> statistics_window(const RunState& s, const std::string& column_name) {
  const auto& steps = s.series["step"];
  const auto& values = s.series[column_name];
  std::vector<double> out;
  for (std::size_t k = 0; k < steps.size(); ++k)
    if (steps[k] > static_cast<double>(s.statistics_start)) out.push_back(values[k]);
  return out;
}

// Steady average with its batch-means error over 10 batches (the protocol
// guarantees at least 20 samples in the window).
// The window is also tested for a slow drift (observables::window_drift): a
// drifting series is reported "stationary": false, with its change over the
// window, rather than as a bare mean.
nlohmann::json steady(const std::vector<double>& samples) {
  const auto a = observables::batch_means(samples, 10);
  const auto drift = observables::window_drift(samples);
  return {{"mean", a.mean},
          {"error", a.error},
          {"batches", a.batches},
          {"samples", a.samples},
          {"correlation_samples", a.correlation_samples},
          {"error_reliable", a.error_reliable},
          {"stationary", drift.stationary},
          {"drift_over_window", drift.change},
          {"drift_z", std::isfinite(drift.z) ? drift.z : 1e300 * (drift.z > 0 ? 1 : -1)}};
}

// Initial positions and velocities of a fresh start.
void place_spheres(const cases::SuspensionCase& c, const SceneModules& m,
                   const spheres::PeriodicBox& box, spheres::SphereSet& s) {
  s.resize(static_cast<std::size_t>(c.sphere_count));
  if (c.scene == cases::Scene::single_sphere) {
    s.position[0] = 0.5 * box.length;
    return;
  }
  if (!c.initial_positions.empty()) {
    for (std::size_t i = 0; i < s.size(); ++i)
      s.position[i] = Vec3(c.initial_positions[3 * i], c.initial_positions[3 * i + 1],
                           c.initial_positions[3 * i + 2]);
    return;  // held still where a snapshot left them
  }
  s.position = placement::place_randomly({c.sphere_count, c.radius_cells, 0.0, c.seed}, box);
  if (m.liquid) return;  // spheres and liquid start at rest
  // granular gas: Maxwellian velocities with U_inf per component, no net momentum
  std::mt19937_64 rng(c.seed + 1);
  std::normal_distribution<double> maxwell(0.0, c.settling_velocity);
  Vec3 mean = Vec3::Zero();
  for (auto& v : s.velocity) mean += (v = Vec3(maxwell(rng), maxwell(rng), maxwell(rng)));
  mean /= static_cast<double>(c.sphere_count);
  for (auto& v : s.velocity) v -= mean;
}

// Fastest sphere speed accepted before the run is called unstable: beyond
// 0.3 (Ma ~ 0.5) the lattice cannot carry the flow around it.
constexpr double kMaxSphereSpeed = 0.3;

// Empty when healthy, else what went wrong.
std::string sphere_health(const spheres::SphereSet& s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double v = s.velocity[i].norm();
    if (!std::isfinite(v) || !std::isfinite(s.angular_velocity[i].norm()))
      return "sphere " + std::to_string(i) + " has a non-finite velocity";
    if (v > kMaxSphereSpeed)
      return "sphere " + std::to_string(i) + " moves at " + std::to_string(v) +
             " lattice units (limit " + std::to_string(kMaxSphereSpeed) + ")";
  }
  return {};
}

std::string health(const spheres::SphereSet& s, double liquid_mass) {
  if (!std::isfinite(liquid_mass)) return "the liquid mass is no longer finite";
  return sphere_health(s);
}

template <class Real>
RunReport run_scene(const cases::SuspensionCase& c, const RunOptions& o) {
  const SceneModules& modules = cases::modules_of(c.scene);
  const StartMode start = prepare_output_directory(o.out_dir, o.resume, c.to_json());
  RunLog log(o.out_dir / "run.log", o.quiet);
  if (start == StartMode::already_completed) return completed_run(o.out_dir, log);
  for (const auto& w : c.warnings) log.warning(w);
  if (c.threads > 0) omp_set_num_threads(c.threads);
  const Clock::time_point t_start = Clock::now();
  const Durations d = durations(c);
  const spheres::PeriodicBox box{Vec3(c.box.nx, c.box.ny, c.box.nz)};
  const bool stage2 = has_stage2(c, modules);

  // ---- modules of the scene ---------------------------------------------------
  events::DirectInteractions contacts({.restitution = c.restitution,
                                       .friction = c.friction,
                                       .escape_velocity = 0.0,  // stage 1: du = 0
                                       .well_width = c.well_width});
  const lubrication::RadialLubrication lubrication(
      {.viscosity = c.viscosity,
       .liquid_density = 1.0,
       .onset_gap = c.lubrication_onset_over_a,
       .saturation_gap = c.lubrication_saturation_over_a,
       .lattice_share = c.lubrication_lattice_share,
       .explicit_euler = c.lubrication_integration == "explicit-paper"});
  std::unique_ptr<Liquid<Real>> liquid;
  if (modules.liquid) liquid = std::make_unique<Liquid<Real>>(c);

  RunState s(modules);
  s.spheres.radius = c.radius_cells;
  s.spheres.density_ratio = c.density_ratio;
  s.size_distribution_sum.assign(static_cast<std::size_t>(c.sphere_count) + 1, 0.0);
  s.microstructure = pair_structure_for(c);
  const int slabs = phi_slabs(c);
  const fs::path checkpoint = o.out_dir / "checkpoint.h5";
  if (start == StartMode::from_checkpoint) {
    read_checkpoint(checkpoint, c, s, contacts, liquid.get());
    log.info("resumed from " + checkpoint.string() + " at step " + std::to_string(s.step));
  } else {
    place_spheres(c, modules, box, s.spheres);
  }
  log.info(std::string("flocsim ") + FLOCSIM_VERSION + " " +
           std::string(cases::scene_name(c.scene)) + " scene: " + std::to_string(c.sphere_count) +
           " spheres of radius " + std::to_string(c.radius_cells) +
           (modules.liquid ? " (markers at a_g = " + std::to_string(c.input_radius) + ")" : "") +
           " in " + std::to_string(c.box.nx) + " x " + std::to_string(c.box.ny) + " x " +
           std::to_string(c.box.nz) + ", phi = " + std::to_string(c.phi_realised) +
           ", a/U_inf = " + std::to_string(c.convective_time) + " steps" +
           (modules.liquid ? std::string(", ") + (sizeof(Real) == 8 ? "double" : "float") +
                                 " lattice, nu = " + std::to_string(c.viscosity)
                           : std::string()) +
           ", " + std::to_string(omp_get_max_threads()) + " threads");

  auto expected_total = [&] {
    const long after_stage1 = stage2 ? d.settle + d.statistics : d.statistics;
    if (s.stage == 1 && s.statistics_start < 0)
      return std::max(s.step, d.stage1_max) + after_stage1;
    if (s.statistics_start >= 0) return s.statistics_start + d.statistics;
    return s.stage2_start + d.settle + d.statistics;
  };
  const long cells = modules.liquid ? c.box.cells() : 0;
  ProgressReporter progress(log, o.out_dir / "progress.json", s.step, expected_total(), cells,
                            c.progress_every_s);
  double fluid_s = 0, ib_s = 0, spheres_s = 0, lubrication_s = 0, events_s = 0;
  double observables_s = 0, output_s = 0, checkpoint_s = 0;
  Clock::time_point last_checkpoint = Clock::now();
  long last_good_checkpoint = start == StartMode::from_checkpoint ? s.step : -1;
  const long first_step = s.step;
  const double mass = s.spheres.mass();
  // what must become stationary in stage 1: the slip velocity where there is
  // a liquid, the granular temperature in a granular gas
  const std::string signal = modules.liquid ? "U_over_Uinf" : "granular_temperature";
  const double a = c.radius_cells;
  bool done = s.statistics_start >= 0 && s.step - s.statistics_start >= d.statistics;
  double worst_momentum_drift = 0;

  auto fail = [&](const std::string& what) {
    return blown_up_run(log,
                        "step " + std::to_string(s.step) +
                            " (t U_inf/a = " + std::to_string(s.step / c.convective_time) + ")",
                        what, last_good_checkpoint, checkpoint,
                        "U_inf too high for the Mach limit, a viscosity too small for the "
                        "resolution, or a density ratio near 1");
  };

  while (!done) {
    // ---- one time step: the modules of the scene, in order -------------------
    Clock::time_point t0 = Clock::now();
    if (liquid) {
      liquid->ib.apply(liquid->fluid, s.spheres);  // no-slip forces at the current state
      ib_s += seconds_since(t0);
      t0 = Clock::now();
      liquid->fluid.step();
      fluid_s += seconds_since(t0);
      t0 = Clock::now();
      if (modules.spheres_move)
        spheres::advance_velocities(
            s.spheres,
            {liquid->ib.force(), liquid->ib.torque(), liquid->ib.internal_momentum_change(),
             liquid->ib.internal_angular_momentum_change()},
            liquid->dynamics);
      spheres_s += seconds_since(t0);
    }
    // Every step, before the event engine moves them: a sphere running away
    // (a blow-up starts within a few steps) is a diagnosed failure with the
    // last good checkpoint kept, not an event engine asked for an impossible
    // pair search. O(N), well under 1 % of a step.
    if (modules.spheres_move) {
      const std::string sick = sphere_health(s.spheres);
      if (!sick.empty()) return fail(sick);
    }
    if (modules.lubrication) {
      t0 = Clock::now();
      lubrication.apply(s.spheres, box, 1.0);
      lubrication_s += seconds_since(t0);
    }
    t0 = Clock::now();
    if (modules.contacts) {
      contacts.advance(s.spheres, box, 1.0);  // moves the spheres, with collisions and wells
      events_s += seconds_since(t0);
    } else if (modules.spheres_move) {
      spheres::advance_positions(s.spheres, box);
      spheres_s += seconds_since(t0);
    }
    ++s.step;

    if (s.step % d.sample == 0) {
      t0 = Clock::now();
      const auto agg =
          observables::find_aggregates(s.spheres.position, box, 2.0 * (a + c.well_width));
      const double T = observables::granular_temperature(s.spheres.velocity);
      double kinetic = 0;
      Vec3 sphere_mean = Vec3::Zero();
      for (const auto& v : s.spheres.velocity) {
        kinetic += 0.5 * mass * v.squaredNorm();
        sphere_mean += v;
      }
      sphere_mean /= static_cast<double>(s.spheres.size());
      std::vector<double> row = {static_cast<double>(s.step),
                                 s.step / c.convective_time,
                                 static_cast<double>(s.stage),
                                 agg.contacts_per_sphere,
                                 agg.mean_size,
                                 T,
                                 std::sqrt(T) * 2 * a / c.viscosity,
                                 kinetic,
                                 contacts.well_energy(s.spheres),
                                 static_cast<double>(contacts.counters().collisions)};
      if (liquid) {
        const auto l = observables::liquid_averages(liquid->fluid, s.spheres, liquid->solid);
        const std::string sick = health(s.spheres, l.mass);
        if (!sick.empty()) return fail(sick);
        const double U = observables::superficial_slip_velocity(l.mean_velocity_x, sphere_mean.x(),
                                                                c.phi_realised);
        // lattice momentum + sum (m_p u_p - P_in): constant (sphere_dynamics.hpp)
        double balance = l.lattice_momentum_x;
        for (std::size_t i = 0; i < s.spheres.size(); ++i)
          balance += mass * s.spheres.velocity[i].x() - liquid->ib.internal_momentum()[i].x();
        if (!s.momentum_initial_set) {
          // not 0: the first step has no inside-momentum change, while the
          // inside liquid already carries the half body force f/2 (a constant)
          s.momentum_initial = balance;
          s.momentum_initial_set = true;
        }
        const double drift = modules.spheres_move ? balance - s.momentum_initial : 0.0;
        // the other reading of <u>: every cell, the liquid inside the spheres too
        const double U_all = observables::superficial_slip_velocity(
            l.mean_velocity_x_all_cells, sphere_mean.x(), c.phi_realised);
        const double body = liquid->dynamics.external.liquid_body_force.x();
        row.insert(row.end(),
                   {U / c.settling_velocity, U,
                    observables::dimensionless_drag(body, a, c.phi_realised, c.viscosity, U),
                    U * 2 * a / c.viscosity, l.mean_velocity_x, sphere_mean.x(), drift,
                    l.mean_velocity_x_all_cells,
                    observables::dimensionless_drag(body, a, c.phi_realised, c.viscosity, U_all)});
        worst_momentum_drift = std::max(worst_momentum_drift, std::abs(drift));
      }
      for (std::size_t col = 0; col < row.size(); ++col) s.series.data[col].push_back(row[col]);
      const auto phi = observables::slab_solids_fraction(s.spheres.position, a, box, slabs);
      s.phi_x.insert(s.phi_x.end(), phi.begin(), phi.end());
      if (s.statistics_start >= 0) {
        for (std::size_t n = 0; n < agg.size_distribution.size(); ++n)
          s.size_distribution_sum[n] += agg.size_distribution[n];
        s.microstructure.add_configuration(s.spheres.position, box);
      }
      observables_s += seconds_since(t0);

      // ---- protocol -----------------------------------------------------------
      if (s.stage == 1 && s.statistics_start < 0 && s.step >= d.stage1_min) {
        const bool stationary = observables::is_stationary(s.series[signal], d.window_samples);
        if (stationary || s.step >= d.stage1_max) {
          s.stage1_stationary = stationary;
          const std::string why =
              stationary ? " (stationary)" : " (stage1_max reached before the detector fired)";
          if (stage2) {
            s.stage = 2;
            s.stage2_start = s.step;
            contacts.set_escape_velocity(c.escape_velocity);
            contacts.attach_pairs_within_well(s.spheres, box);
            log.info("stage 2 at t U_inf/a = " + std::to_string(s.step / c.convective_time) + why +
                     ": du/U_inf = " + std::to_string(c.du_over_uinf));
          } else {
            s.statistics_start = s.step;
            log.info("statistics from t U_inf/a = " + std::to_string(s.step / c.convective_time) +
                     why);
          }
          progress.set_steps_total(expected_total());
        }
      } else if (s.stage == 2 && s.statistics_start < 0 && s.step - s.stage2_start >= d.settle) {
        s.statistics_start = s.step;
        log.info("statistics from t U_inf/a = " + std::to_string(s.step / c.convective_time));
      }
      done = s.statistics_start >= 0 && s.step - s.statistics_start >= d.statistics;
    }
    if (d.snapshot > 0 && (s.step % d.snapshot == 0 || done)) {
      t0 = Clock::now();
      const auto agg =
          observables::find_aggregates(s.spheres.position, box, 2.0 * (a + c.well_width));
      output::write_sphere_snapshot(o.out_dir / "spheres", s.step, s.step / c.convective_time,
                                    s.spheres, agg.aggregate_of);
      output_s += seconds_since(t0);
    }
    const bool stop_now = process::stop_requested() != 0 ||
                          (o.stop_after_steps > 0 && s.step - first_step >= o.stop_after_steps);
    const bool checkpoint_due =
        seconds_since(last_checkpoint) >= c.checkpoint_every_s ||
        (o.checkpoint_every_steps > 0 && s.step % o.checkpoint_every_steps == 0);
    if (!done && (stop_now || checkpoint_due)) {
      // only a healthy state is checkpointed: the last good one is never replaced by a bad one
      const std::string sick = health(s.spheres, liquid ? liquid->fluid.total_mass() : 0.0);
      if (!sick.empty()) return fail(sick);
      t0 = Clock::now();
      write_checkpoint(o.out_dir, c, s, contacts, liquid.get(), s.wall_s + seconds_since(t_start));
      checkpoint_s += seconds_since(t0);
      last_checkpoint = Clock::now();
      last_good_checkpoint = s.step;
      if (stop_now) {
        progress.finish(s.step);
        log.info("stopped at step " + std::to_string(s.step) +
                 "; checkpoint written, continue with --resume");
        RunReport r;
        r.outcome = RunOutcome::interrupted;
        return r;
      }
    }
    if (s.series.samples() > 0 && s.step % d.sample == 0) {
      char extra[200];
      const std::string phase = s.statistics_start >= 0 ? "statistics"
                                : s.stage == 2          ? "stage 2"
                                                        : "stage 1";
      if (liquid)
        std::snprintf(extra, sizeof extra, "%s | t U/a %.1f | U/U_inf %.3f | C_sph %.3f",
                      phase.c_str(), s.step / c.convective_time, s.series["U_over_Uinf"].back(),
                      s.series["C_sph"].back());
      else
        std::snprintf(extra, sizeof extra, "%s | t U/a %.1f | C_sph %.3f | <n_a> %.3f",
                      phase.c_str(), s.step / c.convective_time, s.series["C_sph"].back(),
                      s.series["mean_aggregate_size"].back());
      progress.update(s.step, extra);
    }
  }
  progress.finish(s.step);

  // ---- output and result.json ----------------------------------------------------
  nlohmann::json obs;
  obs["C_sph"] = steady(statistics_window(s, "C_sph"));
  obs["n_a_mean"] = steady(statistics_window(s, "mean_aggregate_size"));
  obs["granular_temperature"] = steady(statistics_window(s, "granular_temperature"));
  obs["Re_T"] = steady(statistics_window(s, "Re_T"));
  if (liquid) {
    obs["U_over_Uinf"] = steady(statistics_window(s, "U_over_Uinf"));
    obs["U"] = steady(statistics_window(s, "U"));
    obs["F"] = steady(statistics_window(s, "F"));
    // F with <u> over every cell (docs/validation.md, "Which <u>"); F is the
    // liquid-only reading flocsim reports
    const auto f_all = statistics_window(s, "F_all_cells");
    if (std::none_of(f_all.begin(), f_all.end(), [](double v) { return std::isnan(v); }))
      obs["F_all_cells"] = steady(f_all);
    obs["Re"] = steady(statistics_window(s, "Re"));
    const double phi = c.phi_realised;
    const double re = obs["Re"]["mean"].get<double>();
    nlohmann::json ref;
    ref["beetstra_F_at_measured_Re"] = observables::beetstra_drag(phi, re);
    ref["beetstra_normalisation"] =
        "F = F_h / (6 pi mu a U), F_h = f V_p (1/phi - 1), U superficial, Re = 2aU/nu";
    if (c.scene == cases::Scene::suspension) {
      ref["richardson_zaki_U_over_Uinf"] =
          observables::richardson_zaki_velocity_ratio(phi, c.reynolds_inf);
      ref["richardson_zaki_exponent"] = observables::richardson_zaki_exponent(c.reynolds_inf);
      ref["beetstra_U_over_Uinf"] = observables::beetstra_velocity_ratio(phi, c.reynolds_inf);
    }
    if (c.scene == cases::Scene::single_sphere && c.box.nx == c.box.ny && c.box.ny == c.box.nz) {
      // creeping-flow hindrance of the simple cubic array the periodic box makes
      ref["sangani_acrivos_K"] = calibration::sangani_acrivos_drag(2 * a / c.box.nx);
    }
    obs["references"] = ref;
    if (modules.spheres_move)
      obs["momentum_balance"] = {
          {"worst_drift", worst_momentum_drift},
          {"relative_to_sphere_momentum",
           worst_momentum_drift /
               std::max(1e-300, std::abs(mass * c.sphere_count * c.settling_velocity))},
          {"what", "lattice momentum + sum (m_p u_p - P_in), x, minus its first sample"}};
  }
  if (!liquid) {
    const auto samples = statistics_window(s, "kinetic_energy");
    const auto wells = statistics_window(s, "well_energy");
    const auto collisions = statistics_window(s, "collisions");
    if (samples.size() >= 2) {
      // with e = 1 and no liquid, kinetic + well energy is conserved
      const double e0 = samples.front() + wells.front(), e1 = samples.back() + wells.back();
      obs["energy_relative_change"] = (e1 - e0) / e0;
      const auto times = statistics_window(s, "time");
      const double span = times.back() - times.front();
      obs["collisions_per_sphere_per_convective_time"] =
          (collisions.back() - collisions.front()) / c.sphere_count / span;
    }
  }
  Distributions dist;
  const double n_samples = static_cast<double>(statistics_window(s, "step").size());
  dist.p.resize(s.size_distribution_sum.size());
  for (std::size_t n = 0; n < dist.p.size(); ++n)
    dist.p[n] = n_samples > 0 ? s.size_distribution_sum[n] / n_samples : 0.0;
  while (dist.p.size() > 2 && dist.p.back() == 0.0) dist.p.pop_back();
  dist.r_over_a = s.microstructure.radial_bin_centres();
  for (double& x : dist.r_over_a) x /= a;
  dist.g = s.microstructure.radial_distribution();
  dist.theta = s.microstructure.angular_bin_centres();
  dist.h = s.microstructure.angular_distribution();
  obs["size_distribution"] = dist.p;
  {
    obs["g_r"] = {{"r_over_a", dist.r_over_a}, {"g", dist.g}};
    obs["h_theta"] = {{"theta", dist.theta}, {"h", dist.h}, {"pairs_closer_than", "3a"}};
    obs["microstructure_configurations"] = s.microstructure.configurations();
  }
  obs["window"] = {{"start", s.statistics_start / c.convective_time},
                   {"end", s.step / c.convective_time},
                   {"unit", "a/U_inf"},
                   {"samples", static_cast<long>(n_samples)}};
  obs["stage2_start"] =
      s.stage2_start >= 0 ? nlohmann::json(s.stage2_start / c.convective_time) : nullptr;
  obs["stage1_stationary"] = s.stage1_stationary;
  const auto& k = contacts.counters();
  obs["events"] = {{"collisions", k.collisions},
                   {"well_entries", k.well_entries},
                   {"escapes", k.escapes},
                   {"edge_bounces", k.edge_bounces},
                   {"attached_pairs_final", contacts.attached_count()},
                   {"worst_overlap", contacts.worst_overlap()}};

  Clock::time_point t0 = Clock::now();
  write_series(o.out_dir, s, slabs, dist);
  if (liquid) write_fields(o.out_dir, liquid->fluid);
  output_s += seconds_since(t0);

  const double wall = seconds_since(t_start);
  const long steps_here = s.step - first_step;
  nlohmann::json cost = {{"wall_s", s.wall_s + wall},
                         {"wall_s_this_invocation", wall},
                         {"steps", s.step},
                         {"steps_this_invocation", steps_here},
                         {"threads", omp_get_max_threads()}};
  nlohmann::json modules_s = {{"events", events_s},
                              {"observables", observables_s},
                              {"output", output_s},
                              {"checkpoint", checkpoint_s}};
  if (liquid) {
    modules_s["fluid"] = fluid_s;
    modules_s["immersed_boundary"] = ib_s;
    modules_s["spheres"] = spheres_s;
    modules_s["lubrication"] = lubrication_s;
    const double updates = static_cast<double>(steps_here) * static_cast<double>(cells);
    cost["MLUPS_fluid"] = fluid_s > 0 ? updates / fluid_s / 1e6 : 0.0;
    cost["MLUPS_full_step"] = wall > 0 ? updates / wall / 1e6 : 0.0;
    cost["MLUPS"] = cost["MLUPS_full_step"];  // the rate the results database records
  }
  cost["modules_s"] = modules_s;
  nlohmann::json result;
  result["status"] = "completed";
  result["flocsim_version"] = FLOCSIM_VERSION;
  result["case"] = c.to_json();
  result["derived"] = c.derived_json();
  result["observables"] = obs;
  // The steady averages whose window still drifts: listed, and said in the log,
  // so that nobody reads their means as steady-state values unawares.
  nlohmann::json drifting = nlohmann::json::array();
  for (auto it = obs.begin(); it != obs.end(); ++it)
    if (it.value().is_object() && it.value().contains("stationary") &&
        !it.value()["stationary"].get<bool>()) {
      drifting.push_back(it.key());
      char line[200];
      std::snprintf(line, sizeof line,
                    "%s is not stationary over the statistics window: it changes by %.4g "
                    "(z = %.1f); lengthen protocol.statistics or stage2_settle",
                    it.key().c_str(), it.value()["drift_over_window"].get<double>(),
                    it.value()["drift_z"].get<double>());
      log.warning(line);
    }
  result["not_stationary"] = drifting;
  result["cost"] = cost;
  result["completed_at"] = utc_timestamp();
  output::write_file_atomically(o.out_dir / "result.json", result.dump(2) + "\n");
  std::error_code ec;
  fs::remove(checkpoint, ec);
  log.info("completed " + std::to_string(s.step) + " steps (" +
           std::to_string(s.step / c.convective_time) + " a/U_inf) in " + format_duration(wall) +
           "; result in " + (o.out_dir / "result.json").string());
  RunReport r;
  r.outcome = RunOutcome::completed;
  r.result = std::move(result);
  return r;
}

}  // namespace

RunReport run_sphere_case(const cases::SuspensionCase& c, const RunOptions& o) {
  if (!cases::modules_of(c.scene).spheres) {
    std::string list;
    for (const auto& n : cases::scene_names(/*with_spheres=*/true))
      list += (list.empty() ? "\"" : ", \"") + n + "\"";
    throw input::InputError("scene = \"" + std::string(cases::scene_name(c.scene)) +
                            "\": has no spheres; the sphere run takes " + list);
  }
  try {
    return c.single_precision ? run_scene<float>(c, o) : run_scene<double>(c, o);
  } catch (const input::InputError&) {
    throw;
  } catch (const std::exception& e) {
    return failed_run(o.out_dir, e);  // a module gave up (event cap, I/O)
  }
}

}  // namespace flocsim::run
