#include "engine/run/sphere_run.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <fstream>
#include <random>

#include "engine/events/direct_interactions.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/observables/aggregates.hpp"
#include "engine/observables/pair_structure.hpp"
#include "engine/observables/suspension_averages.hpp"
#include "engine/output/atomic_file.hpp"
#include "engine/output/hdf5_file.hpp"
#include "engine/output/sphere_snapshots.hpp"
#include "engine/placement/random_placement.hpp"
#include "engine/run/output_directory.hpp"
#include "engine/run/run_log.hpp"
#include "engine/run/stop_signal.hpp"

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

// Columns of the time series, sampled every protocol.sample_every a/U_inf.
const std::vector<std::string> kColumns = {"step",
                                           "time",
                                           "stage",
                                           "contacts_per_sphere",
                                           "mean_aggregate_size",
                                           "granular_temperature",
                                           "Re_T",
                                           "kinetic_energy",
                                           "well_energy",
                                           "collisions"};

std::size_t column(const std::string& name) {
  const auto it = std::find(kColumns.begin(), kColumns.end(), name);
  if (it == kColumns.end()) throw std::logic_error("no time-series column " + name);
  return static_cast<std::size_t>(it - kColumns.begin());
}

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

// Everything that evolves: what a checkpoint holds.
struct RunState {
  spheres::SphereSet spheres;
  long step = 0;
  int stage = 1;
  long stage2_start = -1;      // step at which du was switched on
  long statistics_start = -1;  // step after which samples enter the averages
  bool stage1_stationary = false;
  std::vector<std::vector<double>> series = std::vector<std::vector<double>>(kColumns.size());
  std::vector<double> size_distribution_sum;  // sum of p(n) over statistics samples
  observables::PairStructure microstructure{1, 1, 1, 1};
  std::vector<double> phi_x;  // phi(x, t): one row of slabs per sample
  double wall_s = 0;          // before this invocation
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

void write_checkpoint(const fs::path& dir, const cases::SuspensionCase& c, const RunState& s,
                      const events::DirectInteractions& contacts, double wall_s) {
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
    f.create_group("/series");
    for (std::size_t col = 0; col < kColumns.size(); ++col)
      f.write("/series/" + kColumns[col], {s.series[col].size()}, s.series[col].data());
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
    f.set_attribute("/", "step", static_cast<std::int64_t>(s.step));
    f.set_attribute("/", "stage", static_cast<std::int64_t>(s.stage));
    f.set_attribute("/", "stage2_start", static_cast<std::int64_t>(s.stage2_start));
    f.set_attribute("/", "statistics_start", static_cast<std::int64_t>(s.statistics_start));
    f.set_attribute("/", "stage1_stationary", static_cast<std::int64_t>(s.stage1_stationary));
    f.set_attribute("/", "wall_s", wall_s);
    f.close();
  }
  tmp.commit();
}

void read_checkpoint(const fs::path& file, const cases::SuspensionCase& c, RunState& s,
                     events::DirectInteractions& contacts) {
  output::Hdf5File f(file, output::Hdf5File::Mode::read);
  if (!resumable_under(nlohmann::json::parse(f.attribute_string("/", "case")), c.to_json()))
    throw input::InputError(
        file.string() + " belongs to a different case; remove it or use another --out directory");
  s.spheres.position = unflatten(f.read<double>("/spheres/position"));
  s.spheres.velocity = unflatten(f.read<double>("/spheres/velocity"));
  s.spheres.angular_velocity = unflatten(f.read<double>("/spheres/angular_velocity"));
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
  for (std::size_t col = 0; col < kColumns.size(); ++col)
    s.series[col] = f.read<double>("/series/" + kColumns[col]);
  s.size_distribution_sum = f.read<double>("/size_distribution_sum");
  observables::PairStructure::Accumulated m;
  m.g_counts = f.read<double>("/microstructure/g_counts");
  m.h_counts = f.read<double>("/microstructure/h_counts");
  m.g_normalisation = f.attribute_double("/microstructure", "g_normalisation");
  m.h_pairs = f.attribute_double("/microstructure", "h_pairs");
  m.configurations = f.attribute_int("/microstructure", "configurations");
  s.microstructure.restore(m);
  s.phi_x = f.read<double>("/phi_x");
  if (s.spheres.position.size() != static_cast<std::size_t>(c.sphere_count))
    throw std::runtime_error(file.string() + ": holds " +
                             std::to_string(s.spheres.position.size()) + " spheres, the case has " +
                             std::to_string(c.sphere_count));
  s.step = f.attribute_int("/", "step");
  s.stage = static_cast<int>(f.attribute_int("/", "stage"));
  s.stage2_start = f.attribute_int("/", "stage2_start");
  s.statistics_start = f.attribute_int("/", "statistics_start");
  s.stage1_stationary = f.attribute_int("/", "stage1_stationary") != 0;
  s.wall_s = f.attribute_double("/", "wall_s");
  if (s.stage == 2) contacts.set_escape_velocity(c.escape_velocity);
  contacts.set_attached_pairs(attached);
  contacts.set_counters(counters);
}

void write_series(const fs::path& dir, const RunState& s, int slabs) {
  output::TemporaryFile tmp(dir / "series.h5");
  {
    output::Hdf5File f(tmp.path(), output::Hdf5File::Mode::create);
    for (std::size_t col = 0; col < kColumns.size(); ++col)
      f.write("/" + kColumns[col], {s.series[col].size()}, s.series[col].data());
    // phi(x, t): rows are samples (times in /time), columns slabs of width L / slabs
    const auto slab_count = static_cast<hsize_t>(slabs);
    f.write("/phi_x", {s.phi_x.size() / slab_count, slab_count}, s.phi_x.data());
    f.close();
  }
  tmp.commit();
}

// The samples of one column taken after the statistics started.
std::vector<double> statistics_window(const RunState& s, const std::string& column_name) {
  const std::size_t step_col = 0;
  const std::size_t col = column(column_name);
  std::vector<double> out;
  for (std::size_t k = 0; k < s.series[step_col].size(); ++k)
    if (s.series[step_col][k] > static_cast<double>(s.statistics_start))
      out.push_back(s.series[col][k]);
  return out;
}

// Steady average with its batch-means error over 10 batches (the protocol
// guarantees at least 20 samples in the window).
nlohmann::json steady(const std::vector<double>& samples) {
  const auto a = observables::batch_means(samples, 10);
  return {{"mean", a.mean},
          {"error", a.error},
          {"batches", a.batches},
          {"samples", a.samples},
          {"correlation_samples", a.correlation_samples},
          {"error_reliable", a.error_reliable}};
}

}  // namespace

const std::vector<std::string>& runnable_sphere_scenes() {
  static const std::vector<std::string> scenes = {"granular"};
  return scenes;
}

RunReport run_sphere_case(const cases::SuspensionCase& c, const RunOptions& o) {
  if (std::find(runnable_sphere_scenes().begin(), runnable_sphere_scenes().end(), c.scene) ==
      runnable_sphere_scenes().end())
    throw input::InputError("scene = \"" + c.scene +
                            "\": must be one of the scenes this build runs: granular, fluid");
  const StartMode start = prepare_output_directory(o.out_dir, o.resume);
  RunLog log(o.out_dir / "run.log", o.quiet);
  if (start == StartMode::already_completed) return completed_run(o.out_dir, log);
  for (const auto& w : c.warnings) log.warning(w);
  if (c.threads > 0) omp_set_num_threads(c.threads);
  const Clock::time_point t_start = Clock::now();
  const Durations d = durations(c);
  const spheres::PeriodicBox box{Vec3(c.box.nx, c.box.ny, c.box.nz)};

  // ---- modules of the scene ---------------------------------------------------
  events::DirectInteractions contacts({.restitution = c.restitution,
                                       .friction = c.friction,
                                       .escape_velocity = 0.0,  // stage 1: du = 0
                                       .well_width = c.well_width});

  RunState s;
  s.spheres.radius = c.radius_cells;
  s.spheres.density_ratio = c.density_ratio;
  s.size_distribution_sum.assign(static_cast<std::size_t>(c.sphere_count) + 1, 0.0);
  s.microstructure = pair_structure_for(c);
  const int slabs = phi_slabs(c);
  const fs::path checkpoint = o.out_dir / "checkpoint.h5";
  if (start == StartMode::from_checkpoint) {
    read_checkpoint(checkpoint, c, s, contacts);
    log.info("resumed from " + checkpoint.string() + " at step " + std::to_string(s.step));
  } else {
    s.spheres.resize(static_cast<std::size_t>(c.sphere_count));
    s.spheres.position =
        placement::place_randomly({c.sphere_count, c.radius_cells, 0.0, c.seed}, box);
    // granular gas: Maxwellian velocities with U_inf per component, no net momentum
    std::mt19937_64 rng(c.seed + 1);
    std::normal_distribution<double> maxwell(0.0, c.settling_velocity);
    Vec3 mean = Vec3::Zero();
    for (auto& v : s.spheres.velocity) mean += (v = Vec3(maxwell(rng), maxwell(rng), maxwell(rng)));
    mean /= static_cast<double>(c.sphere_count);
    for (auto& v : s.spheres.velocity) v -= mean;
  }
  log.info(std::string("flocsim ") + FLOCSIM_VERSION + " " + c.scene + " scene: " +
           std::to_string(c.sphere_count) + " spheres of radius " + std::to_string(c.radius_cells) +
           " in " + std::to_string(c.box.nx) + " x " + std::to_string(c.box.ny) + " x " +
           std::to_string(c.box.nz) + ", phi = " + std::to_string(c.phi_realised) +
           ", a/U_inf = " + std::to_string(c.convective_time) + " steps");

  auto expected_total = [&] {
    if (s.stage == 1) return std::max(s.step, d.stage1_max) + d.settle + d.statistics;
    return s.stage2_start + d.settle + d.statistics;
  };
  ProgressReporter progress(log, o.out_dir / "progress.json", s.step, expected_total(), 0,
                            c.progress_every_s);
  double events_s = 0, observables_s = 0, output_s = 0, checkpoint_s = 0;
  Clock::time_point last_checkpoint = Clock::now();
  const long first_step = s.step;
  const double mass = s.spheres.mass();
  // what must become stationary in stage 1: the granular temperature
  const std::size_t signal_column = column("granular_temperature");
  bool done = s.statistics_start >= 0 && s.step - s.statistics_start >= d.statistics;

  while (!done) {
    Clock::time_point t0 = Clock::now();
    contacts.advance(s.spheres, box, 1.0);
    events_s += seconds_since(t0);
    ++s.step;

    if (s.step % d.sample == 0) {
      t0 = Clock::now();
      const auto agg = observables::find_aggregates(s.spheres.position, box,
                                                    2.0 * (c.radius_cells + c.well_width));
      const double T = observables::granular_temperature(s.spheres.velocity);
      double kinetic = 0;
      for (const auto& v : s.spheres.velocity) kinetic += 0.5 * mass * v.squaredNorm();
      const std::vector<double> row = {static_cast<double>(s.step),
                                       s.step / c.convective_time,
                                       static_cast<double>(s.stage),
                                       agg.contacts_per_sphere,
                                       agg.mean_size,
                                       T,
                                       std::sqrt(T) * 2 * c.radius_cells / c.viscosity,
                                       kinetic,
                                       contacts.well_energy(s.spheres),
                                       static_cast<double>(contacts.counters().collisions)};
      for (std::size_t col = 0; col < row.size(); ++col) s.series[col].push_back(row[col]);
      const auto phi =
          observables::slab_solids_fraction(s.spheres.position, c.radius_cells, box, slabs);
      s.phi_x.insert(s.phi_x.end(), phi.begin(), phi.end());
      if (s.statistics_start >= 0) {
        for (std::size_t n = 0; n < agg.size_distribution.size(); ++n)
          s.size_distribution_sum[n] += agg.size_distribution[n];
        s.microstructure.add_configuration(s.spheres.position, box);
      }
      observables_s += seconds_since(t0);

      // ---- protocol -----------------------------------------------------------
      if (s.stage == 1 && s.step >= d.stage1_min) {
        const bool stationary =
            observables::is_stationary(s.series[signal_column], d.window_samples);
        if (stationary || s.step >= d.stage1_max) {
          s.stage = 2;
          s.stage2_start = s.step;
          s.stage1_stationary = stationary;
          contacts.set_escape_velocity(c.escape_velocity);
          if (c.escape_velocity > 0) contacts.attach_pairs_within_well(s.spheres, box);
          log.info(
              "stage 2 at t U_inf/a = " + std::to_string(s.step / c.convective_time) +
              (stationary ? " (stationary)" : " (stage1_max reached before the detector fired)") +
              ": du/U_inf = " + std::to_string(c.du_over_uinf));
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
      const auto agg = observables::find_aggregates(s.spheres.position, box,
                                                    2.0 * (c.radius_cells + c.well_width));
      output::write_sphere_snapshot(o.out_dir / "spheres", s.step, s.step / c.convective_time,
                                    s.spheres, agg.aggregate_of);
      output_s += seconds_since(t0);
    }
    const bool stop_now = stop_requested() != 0 ||
                          (o.stop_after_steps > 0 && s.step - first_step >= o.stop_after_steps);
    const bool checkpoint_due =
        seconds_since(last_checkpoint) >= c.checkpoint_every_s ||
        (o.checkpoint_every_steps > 0 && s.step % o.checkpoint_every_steps == 0);
    if (!done && (stop_now || checkpoint_due)) {
      t0 = Clock::now();
      write_checkpoint(o.out_dir, c, s, contacts, s.wall_s + seconds_since(t_start));
      checkpoint_s += seconds_since(t0);
      last_checkpoint = Clock::now();
      if (stop_now) {
        progress.finish(s.step);
        log.info("stopped at step " + std::to_string(s.step) +
                 "; checkpoint written, continue with --resume");
        RunReport r;
        r.outcome = RunOutcome::interrupted;
        return r;
      }
    }
    if (!s.series[0].empty() && s.step % d.sample == 0) {
      char extra[160];
      std::snprintf(extra, sizeof extra, "stage %d | t U/a %.1f | C_sph %.3f | <n_a> %.3f", s.stage,
                    s.step / c.convective_time, s.series[column("contacts_per_sphere")].back(),
                    s.series[column("mean_aggregate_size")].back());
      progress.update(s.step, extra);
    }
  }
  progress.finish(s.step);

  // ---- result.json -------------------------------------------------------------
  write_series(o.out_dir, s, slabs);
  nlohmann::json obs;
  obs["contacts_per_sphere"] = steady(statistics_window(s, "contacts_per_sphere"));
  obs["n_a_mean"] = steady(statistics_window(s, "mean_aggregate_size"));
  obs["granular_temperature"] = steady(statistics_window(s, "granular_temperature"));
  obs["Re_T"] = steady(statistics_window(s, "Re_T"));
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
  std::vector<double> p(s.size_distribution_sum.size());
  const double n_samples = static_cast<double>(statistics_window(s, "step").size());
  for (std::size_t n = 0; n < p.size(); ++n)
    p[n] = n_samples > 0 ? s.size_distribution_sum[n] / n_samples : 0.0;
  while (p.size() > 2 && p.back() == 0.0) p.pop_back();
  obs["size_distribution"] = p;
  {
    std::vector<double> r = s.microstructure.radial_bin_centres(),
                        theta = s.microstructure.angular_bin_centres();
    for (double& x : r) x /= c.radius_cells;
    obs["g_r"] = {{"r_over_a", r}, {"g", s.microstructure.radial_distribution()}};
    obs["h_theta"] = {{"theta", theta},
                      {"h", s.microstructure.angular_distribution()},
                      {"pairs_closer_than", "3a"}};
    obs["microstructure_configurations"] = s.microstructure.configurations();
  }
  obs["window"] = {{"start", s.statistics_start / c.convective_time},
                   {"end", s.step / c.convective_time},
                   {"unit", "a/U_inf"},
                   {"samples", static_cast<long>(n_samples)}};
  obs["stage2_start"] = s.stage2_start / c.convective_time;
  obs["stage1_stationary"] = s.stage1_stationary;
  const auto& k = contacts.counters();
  obs["events"] = {{"collisions", k.collisions},
                   {"well_entries", k.well_entries},
                   {"escapes", k.escapes},
                   {"edge_bounces", k.edge_bounces},
                   {"attached_pairs_final", contacts.attached_count()},
                   {"worst_overlap", contacts.worst_overlap()}};

  const double wall = seconds_since(t_start);
  nlohmann::json result;
  result["status"] = "completed";
  result["flocsim_version"] = FLOCSIM_VERSION;
  result["case"] = c.to_json();
  result["derived"] = c.derived_json();
  result["observables"] = obs;
  result["cost"] = {{"wall_s", s.wall_s + wall},
                    {"wall_s_this_invocation", wall},
                    {"steps", s.step},
                    {"steps_this_invocation", s.step - first_step},
                    {"threads", omp_get_max_threads()},
                    {"modules_s",
                     {{"events", events_s},
                      {"observables", observables_s},
                      {"output", output_s},
                      {"checkpoint", checkpoint_s}}}};
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

}  // namespace flocsim::run
