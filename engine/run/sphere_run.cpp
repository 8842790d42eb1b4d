#include "engine/run/sphere_run.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "engine/input/input_reader.hpp"
#include "engine/observables/aggregates.hpp"
#include "engine/observables/liquid_averages.hpp"
#include "engine/observables/pair_structure.hpp"
#include "engine/observables/suspension_averages.hpp"
#include "engine/output/sphere_snapshots.hpp"
#include "engine/placement/random_placement.hpp"
#include "engine/result_names/result_names.hpp"
#include "engine/run/coupled_step.hpp"
#include "engine/run/lattice_files.hpp"
#include "engine/run/protocol.hpp"
#include "engine/run/run_shell.hpp"
#include "engine/run/sphere_checkpoint.hpp"
#include "engine/run/sphere_results.hpp"
#include "engine/run/sphere_run_state.hpp"

namespace flocsim::run {

void place_spheres(const cases::SuspensionCase& c, const cases::SceneModules& m,
                   const spheres::PeriodicBox& box, spheres::SphereSet& s) {
  s.resize(static_cast<std::size_t>(c.derived.sphere_count));
  if (c.scene == cases::Scene::single_sphere) {
    s.position[0] = 0.5 * box.length;
    return;
  }
  if (!c.initial_positions.empty()) {
    for (std::size_t i = 0; i < s.size(); ++i)
      s.position[i] = spheres::Vec3(c.initial_positions[3 * i], c.initial_positions[3 * i + 1],
                                    c.initial_positions[3 * i + 2]);
    return;  // held still where a snapshot left them
  }
  s.position = placement::place_randomly(
      {c.derived.sphere_count, c.numerics.radius_cells, 0.0, c.seed}, box);
  if (m.liquid) return;  // spheres and liquid start at rest
  // granular gas: Maxwellian velocities with U_inf per component, no net momentum
  std::mt19937_64 rng(c.seed + 1);
  std::normal_distribution<double> maxwell(0.0, c.derived.settling_velocity);
  spheres::Vec3 mean = spheres::Vec3::Zero();
  for (auto& v : s.velocity) mean += (v = spheres::Vec3(maxwell(rng), maxwell(rng), maxwell(rng)));
  mean /= static_cast<double>(c.derived.sphere_count);
  for (auto& v : s.velocity) v -= mean;
}

namespace {

using spheres::Vec3;

// Stage names of the work around the coupled step (cost.modules_s).
constexpr std::string_view kObservablesStage = "observables";
constexpr std::string_view kOutputStage = "output";
constexpr std::string_view kCheckpointStage = "checkpoint";

// Microstructure accumulated over the statistics window (paper Fig. 2):
// g(r) with bins of 0.05a up to 5a (or just under half the box), h(theta)
// with bins of pi/60 for pairs closer than 3a.
observables::PairStructure pair_structure_for(const cases::SuspensionCase& c) {
  const double a = c.numerics.radius_cells;
  const double half_box = 0.5 * std::min({c.derived.box.nx, c.derived.box.ny, c.derived.box.nz});
  return observables::PairStructure(std::min(5.0 * a, half_box - 0.05 * a), 0.05 * a, 3.0 * a,
                                    M_PI / 60);
}

// Slabs of phi(x, t): one per sphere radius along x.
int phi_slabs(const cases::SuspensionCase& c) {
  return std::max(1, static_cast<int>(std::lround(c.derived.box.nx / c.numerics.radius_cells)));
}

std::string health(const spheres::SphereSet& s, const spheres::PeriodicBox& box,
                   double close_gap_over_a, double liquid_mass) {
  if (!std::isfinite(liquid_mass)) return "the liquid mass is no longer finite";
  return sphere_health(s, box, close_gap_over_a);
}

// One sample at s.step: a row of the time series, a row of phi(x, t) and, in
// the statistics window, the distributions' accumulators. Returns what went
// wrong when the liquid is no longer healthy, else empty.
template <class Real>
std::string take_sample(const cases::SuspensionCase& c, CoupledStep<Real>& step,
                        const Protocol& protocol, SphereRunState& s, int slabs) {
  RunExtremes& extremes = s.extremes;
  const double a = c.numerics.radius_cells;
  const double mass = s.spheres.mass();
  const spheres::PeriodicBox& box = step.box();
  const auto agg =
      observables::find_aggregates(s.spheres.position, box, 2.0 * (a + c.derived.well_width));
  const double T = observables::granular_temperature(s.spheres.velocity);
  double kinetic = 0;
  Vec3 sphere_mean = Vec3::Zero();
  for (const auto& v : s.spheres.velocity) {
    kinetic += 0.5 * mass * v.squaredNorm();
    sphere_mean += v;
    extremes.sphere_speed = std::max(extremes.sphere_speed, v.norm());
  }
  sphere_mean /= static_cast<double>(s.spheres.size());
  const SphereSample row{.step = static_cast<double>(s.step),
                         .time = s.step / c.derived.convective_time,
                         .stage = static_cast<double>(protocol.stage()),
                         .C_sph = agg.contacts_per_sphere,
                         .mean_aggregate_size = agg.mean_size,
                         .granular_temperature = T,
                         .Re_T = std::sqrt(T) * 2 * a / c.numerics.viscosity,
                         .kinetic_energy = kinetic,
                         .well_energy = step.contacts().well_energy(s.spheres),
                         .collisions = static_cast<double>(step.contacts().counters().collisions)};
  if (Liquid<Real>* liquid = step.liquid()) {
    // on the GPU, reduced there: the mirror (liquid->fluid) is stale here and
    // nothing in a sample reads it (the inside momenta are the coupling's)
    const auto l = liquid->averages(s.spheres);
    std::string sick = health(s.spheres, step.box(), c.physics.lubrication_onset_over_a, l.mass);
    if (!sick.empty()) return sick;
    if (!extremes.mass_first_set) {
      extremes.mass_first = l.mass;
      extremes.mass_first_set = true;
    }
    extremes.mass_drift = std::max(extremes.mass_drift, std::abs(l.mass - extremes.mass_first));
    extremes.liquid_speed = std::max(extremes.liquid_speed, l.max_speed);
    extremes.liquid_speed_outside_spheres =
        std::max(extremes.liquid_speed_outside_spheres, l.max_speed_outside_spheres);
    const double U = observables::superficial_slip_velocity(l.mean_velocity_x, sphere_mean.x(),
                                                            c.derived.phi_realised);
    // lattice momentum + sum (m_p u_p - P_in), or with the rigid-body inside
    // liquid sum (m_p - rho V_p) u_p: constant (sphere_dynamics.hpp)
    double balance = l.lattice_momentum_x;
    for (std::size_t i = 0; i < s.spheres.size(); ++i)
      balance += spheres::sphere_balance_momentum(s.spheres, liquid->dynamics, i,
                                                  liquid->coupling->internal_momentum()[i])
                     .x();
    if (!s.momentum_initial_set) {
      // not 0: the first step has no inside-momentum change, while the
      // inside liquid already carries the half body force f/2 (a constant)
      s.momentum_initial = balance;
      s.momentum_initial_set = true;
    }
    const double drift = step.modules().spheres_move ? balance - s.momentum_initial : 0.0;
    // the other reading of <u>: every cell, the liquid inside the spheres too
    const double U_all = observables::superficial_slip_velocity(
        l.mean_velocity_x_all_cells, sphere_mean.x(), c.derived.phi_realised);
    const double body = liquid->dynamics.external.liquid_body_force.x();
    const LiquidSample liquid_row{
        .U_over_Uinf = U / c.derived.settling_velocity,
        .U = U,
        .F = observables::dimensionless_drag(body, a, c.derived.phi_realised, c.numerics.viscosity,
                                             U),
        .Re = U * 2 * a / c.numerics.viscosity,
        .liquid_velocity = l.mean_velocity_x,
        .sphere_velocity = sphere_mean.x(),
        .momentum_balance = drift,
        .liquid_velocity_all_cells = l.mean_velocity_x_all_cells,
        .F_all_cells = observables::dimensionless_drag(body, a, c.derived.phi_realised,
                                                       c.numerics.viscosity, U_all)};
    extremes.momentum_drift = std::max(extremes.momentum_drift, std::abs(drift));
    s.series.append(row, &liquid_row);
  } else {
    s.series.append(row);
  }
  const auto phi = observables::slab_solids_fraction(s.spheres.position, a, box, slabs);
  s.phi_x.insert(s.phi_x.end(), phi.begin(), phi.end());
  if (protocol.in_statistics()) {
    for (std::size_t n = 0; n < agg.size_distribution.size(); ++n)
      s.size_distribution_sum[n] += agg.size_distribution[n];
    s.microstructure.add_configuration(s.spheres.position, box);
  }
  return {};
}

template <class Real>
RunReport run_scene(const cases::SuspensionCase& c, const RunOptions& o) {
  // On a GPU the lattice and its coupling step there (Liquid in
  // coupled_step.hpp); its memory is taken before the output folder is
  // touched, so a GPU that cannot hold the lattice refuses the run up front.
  std::unique_ptr<gpu::GpuFluidLattice<Real>> device = lattice_on_gpu<Real>(
      c.device == cases::Device::cuda, c.derived.box, {c.numerics.viscosity, c.numerics.trt_magic});
  const nlohmann::json device_record = device ? gpu_device_record(device->gpu()) : nlohmann::json();
  RunShell shell(o, c.to_json(), c.warnings, c.protocol.threads);
  if (shell.start() == StartMode::already_completed) return shell.already_completed();
  RunLog& log = shell.log();
  const cases::SceneModules& modules = cases::modules_of(c.scene);

  // ---- the modules of the scene, the protocol around them ---------------------
  TimedStages stages;
  Protocol protocol(c, modules);
  CoupledStep<Real> step(c, protocol.escape_velocity(), stages, std::move(device));
  const auto observables_stage = stages.declare(kObservablesStage);
  const auto output_stage = stages.declare(kOutputStage);
  const auto checkpoint_stage = stages.declare(kCheckpointStage);
  const Protocol::Durations& d = protocol.durations();
  const spheres::PeriodicBox& box = step.box();
  Liquid<Real>* liquid = step.liquid();

  SphereRunState s(modules.liquid);
  s.spheres.radius = c.numerics.radius_cells;
  s.spheres.density_ratio = c.physics.density_ratio;
  s.size_distribution_sum.assign(static_cast<std::size_t>(c.derived.sphere_count) + 1, 0.0);
  s.microstructure = pair_structure_for(c);
  const int slabs = phi_slabs(c);
  const std::filesystem::path& checkpoint = shell.checkpoint_file();
  if (shell.resuming()) {
    // a checkpoint of another case is an input error of its own; any other
    // failure to read it means the file is damaged: say what to do with it
    try {
      read_checkpoint(checkpoint, c, s, protocol, step.contacts(), liquid);
    } catch (const input::InputError&) {
      throw;
    } catch (const std::exception& e) {
      damaged_checkpoint(checkpoint, e.what());
    }
    log.info("resumed from " + checkpoint.string() + " at step " + std::to_string(s.step));
  } else {
    place_spheres(c, modules, box, s.spheres);
  }
  if (liquid && liquid->device) {
    liquid->to_device();
    log.info("lattice and " + std::string(liquid->coupling->stage_name()) + " on GPU " +
             std::to_string(liquid->device->gpu().index) + ", " + liquid->device->gpu().name);
  }
  log.info(
      std::string("flocsim ") + kFlocsimVersion + " " + std::string(cases::scene_name(c.scene)) +
      " scene: " + std::to_string(c.derived.sphere_count) + " spheres of radius " +
      std::to_string(c.numerics.radius_cells) +
      (modules.liquid ? std::string(c.numerics.coupling.immersed_boundary() ? " (markers"
                                                                            : " (covered cells") +
                            " at a_g = " + std::to_string(c.numerics.input_radius) + ")"
                      : "") +
      " in " + std::to_string(c.derived.box.nx) + " x " + std::to_string(c.derived.box.ny) + " x " +
      std::to_string(c.derived.box.nz) + ", phi = " + std::to_string(c.derived.phi_realised) +
      ", a/U_inf = " + std::to_string(c.derived.convective_time) + " steps" +
      (modules.liquid ? std::string(", ") + (sizeof(Real) == 8 ? "double" : "float") +
                            " lattice, nu = " + std::to_string(c.numerics.viscosity)
                      : std::string()) +
      ", " + std::to_string(omp_get_max_threads()) + " threads");

  const long cells = modules.liquid ? c.derived.box.cells() : 0;
  ProgressReporter progress(log, o.out_dir / "progress.json", s.step,
                            protocol.expected_total(s.step), cells, c.protocol.progress_every_s);
  shell.set_first_step(s.step);
  bool done = protocol.done(s.step);

  auto fail = [&](const std::string& what) {
    return shell.blown_up("step " + std::to_string(s.step) + " (t U_inf/a = " +
                              std::to_string(s.step / c.derived.convective_time) + ")",
                          what,
                          "U_inf too high for the Mach limit, a viscosity too small for the "
                          "resolution, a density ratio near 1, or the coupling's period-2 "
                          "oscillation (measured with the paper's IB method at nu = 0.01 at a = 4, "
                          "0.0067-0.01 at a = 6; "
                          "docs/numerics.md: a larger viscosity or the one-sweep option runs)");
  };

  while (!done) {
    if (const std::string sick = step.advance(s.spheres); !sick.empty()) return fail(sick);
    ++s.step;

    if (s.step % d.sample == 0) {
      {
        const auto timing = stages.time(observables_stage);
        const std::string sick = take_sample(c, step, protocol, s, slabs);
        if (!sick.empty()) return fail(sick);
      }
      if (protocol.advance(s.step, s.series[protocol.stationarity_signal()], step.contacts(),
                           s.spheres, box, log))
        progress.set_steps_total(protocol.expected_total(s.step));
      done = protocol.done(s.step);
    }
    if (d.snapshot > 0 && (s.step % d.snapshot == 0 || done)) {
      stages.run(output_stage, [&] {
        const auto agg = observables::find_aggregates(
            s.spheres.position, box, 2.0 * (c.numerics.radius_cells + c.derived.well_width));
        output::write_sphere_snapshot(o.out_dir / "spheres", s.step,
                                      s.step / c.derived.convective_time, s.spheres, box,
                                      agg.aggregate_of);
      });
    }
    const bool stop_now = shell.stop_requested(s.step);
    if (!done && (stop_now || shell.checkpoint_due(s.step, c.protocol.checkpoint_every_s))) {
      // only a healthy state is checkpointed: the last good one is never replaced by a bad one
      if (liquid) liquid->to_host();  // the GPU's lattice, where it has one
      const std::string sick = health(s.spheres, step.box(), c.physics.lubrication_onset_over_a,
                                      liquid ? liquid->fluid.total_mass() : 0.0);
      if (!sick.empty()) return fail(sick);
      stages.run(checkpoint_stage, [&] {
        write_checkpoint(o.out_dir, c, s, protocol, step.contacts(), liquid,
                         s.wall_s + shell.wall_s());
      });
      shell.checkpoint_written(s.step);
      if (stop_now) return shell.interrupted(progress, s.step);
    }
    if (s.series.samples() > 0 && s.step % d.sample == 0) {
      namespace column = result_names::column;
      char extra[200];
      const std::string phase = protocol.phase();
      if (liquid)
        std::snprintf(extra, sizeof extra, "%s | t U/a %.1f | U/U_inf %.3f | C_sph %.3f",
                      phase.c_str(), s.step / c.derived.convective_time,
                      s.series[column::U_over_Uinf].back(), s.series[column::C_sph].back());
      else
        std::snprintf(extra, sizeof extra, "%s | t U/a %.1f | C_sph %.3f | <n_a> %.3f",
                      phase.c_str(), s.step / c.derived.convective_time,
                      s.series[column::C_sph].back(), s.series[column::mean_aggregate_size].back());
      progress.set_state(
          {{"stage", phase},
           {"time", s.step / c.derived.convective_time},
           {"time_total", protocol.expected_total(s.step) / c.derived.convective_time},
           {"time_unit", "a/U_inf"}});
      progress.update(s.step, extra);
    }
  }
  progress.finish(s.step);

  // ---- output and result.json ----------------------------------------------------
  StatisticsSummary summary = summarise(c, s, protocol, step.contacts(), s.extremes);
  if (const CouplingMonitor* m = step.coupling())
    summary.observables["coupling_oscillation"] = {
        {"worst_window", m->worst_window()},
        {"limit", CouplingMonitor::kFlipLimit},
        {"window_steps", CouplingMonitor::kWindowSteps},
        {"what",
         "largest fraction of sphere-steps, per window since this invocation started, "
         "whose hydrodynamic load exceeded " +
             std::to_string(static_cast<int>(CouplingMonitor::kLargeLoad)) +
             " net weights and had reversed " + std::to_string(CouplingMonitor::kSustainedFlips) +
             " steps in a row"}};
  stages.run(output_stage, [&] {
    write_series(o.out_dir, s, slabs, summary.distributions);
    if (liquid) {
      liquid->to_host();
      write_fields(o.out_dir, liquid->fluid);
    }
  });

  const double wall = shell.wall_s();
  const long steps_here = s.step - shell.first_step();
  nlohmann::json cost = shell.cost(s.wall_s, wall, s.step, steps_here, stages);
  if (liquid) {
    const double fluid_s = stages.seconds(stage_name::fluid);
    const double updates = static_cast<double>(steps_here) * static_cast<double>(cells);
    cost["MLUPS_fluid"] = fluid_s > 0 ? updates / fluid_s / 1e6 : 0.0;
    cost["MLUPS_full_step"] = wall > 0 ? updates / wall / 1e6 : 0.0;
    cost["MLUPS"] = cost["MLUPS_full_step"];  // the rate the results database records
  }
  nlohmann::json result;
  result["case"] = c.to_json();
  result["derived"] = c.derived_json();
  result["not_stationary"] = not_stationary(summary.observables, log);
  result["observables"] = std::move(summary.observables);
  result["cost"] = cost;
  if (!device_record.is_null()) result["device"] = device_record;
  return shell.complete(std::move(result), wall,
                        std::to_string(s.step) + " steps (" +
                            std::to_string(s.step / c.derived.convective_time) + " a/U_inf)");
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
  return run_guarded(o.out_dir, [&] {
    return c.numerics.single_precision ? run_scene<float>(c, o) : run_scene<double>(c, o);
  });
}

}  // namespace flocsim::run
