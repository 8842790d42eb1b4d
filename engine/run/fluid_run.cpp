#include "engine/run/fluid_run.hpp"

#include <omp.h>

#include <cmath>
#include <memory>

#include "engine/input/input_reader.hpp"
#include "engine/lattice_gpu/gpu_fluid_lattice.hpp"
#include "engine/lattice_gpu/gpu_runtime.hpp"
#include "engine/output/atomic_file.hpp"
#include "engine/output/field_snapshots.hpp"
#include "engine/output/hdf5_file.hpp"
#include "engine/run/lattice_files.hpp"
#include "engine/run/output_directory.hpp"
#include "engine/run/run_log.hpp"
#include "engine/run/run_shell.hpp"

namespace flocsim::run {

namespace {

using lattice::FluidLattice;
namespace fs = std::filesystem;

// Quantities fixed at the start of the run, kept in the checkpoint so that a
// resumed run reports against the same reference.
struct Baseline {
  double mass = 0;
  lattice::Vector3 momentum;
  double amplitude = 0;
  double wall_s = 0;  // wall time spent before this invocation
};

// Amplitude of the initial wave mode (shear wave or Taylor-Green), measured by
// projection onto it so that it is insensitive to a uniform flow and noise.
template <class Real>
double wave_amplitude(const FluidLattice<Real>& fluid, const cases::FluidCase& c) {
  const auto& in = c.initial;
  if (in.type != "shear_wave" && in.type != "taylor_green") return 0.0;
  const lattice::Extent e = fluid.extent();
  double s = 0, q = 0, p = 0, t = 0;
  for (int z = 0; z < e.nz; ++z)
    for (int y = 0; y < e.ny; ++y)
      for (int x = 0; x < e.nx; ++x) {
        const lattice::Macroscopic m = fluid.macroscopic(x, y, z);
        const double u[3] = {m.velocity.x, m.velocity.y, m.velocity.z};
        const int r[3] = {x, y, z};
        if (in.type == "shear_wave") {
          const double k = cases::initial_wave_number(c);
          s += u[in.component] * std::sin(k * r[in.axis]);
          q += u[in.component] * std::cos(k * r[in.axis]);
        } else {
          // u_a = -U cos(k1 (a - a0)) sin(k2 (b - b0)): project on the four
          // products of cos and sin so that the amplitude U comes out whatever
          // the phase (the vortex is carried along by a mean flow)
          const int a = in.plane_first, b = in.plane_second;
          const double k1 = 2 * M_PI * in.wavelengths / (a == 0 ? e.nx : a == 1 ? e.ny : e.nz);
          const double k2 = 2 * M_PI * in.wavelengths / (b == 0 ? e.nx : b == 1 ? e.ny : e.nz);
          const double ca = std::cos(k1 * r[a]), sa = std::sin(k1 * r[a]);
          const double cb = std::cos(k2 * r[b]), sb = std::sin(k2 * r[b]);
          s += u[a] * ca * sb;
          q += u[a] * sa * sb;
          p += u[a] * ca * cb;
          t += u[a] * sa * cb;
        }
      }
  const double n = static_cast<double>(e.cells());
  if (in.type == "shear_wave") return 2.0 * std::hypot(s, q) / n;
  return 4.0 * std::sqrt(s * s + q * q + p * p + t * t) / n;
}

template <class Real>
void write_checkpoint(const fs::path& dir, const FluidLattice<Real>& fluid,
                      const cases::FluidCase& c, const Baseline& base, double wall_s) {
  output::TemporaryFile tmp(dir / "checkpoint.h5");
  {
    output::Hdf5File f(tmp.path(), output::Hdf5File::Mode::create);
    save_populations(f, fluid);
    f.set_attribute("/", "time_step", static_cast<std::int64_t>(fluid.time_step()));
    f.set_attribute("/", "case", c.to_json().dump());
    f.set_attribute("/", "precision", std::string(sizeof(Real) == 8 ? "double" : "float"));
    f.set_attribute("/", "baseline_mass", base.mass);
    f.set_attribute("/", "baseline_momentum_x", base.momentum.x);
    f.set_attribute("/", "baseline_momentum_y", base.momentum.y);
    f.set_attribute("/", "baseline_momentum_z", base.momentum.z);
    f.set_attribute("/", "baseline_amplitude", base.amplitude);
    f.set_attribute("/", "wall_s", wall_s);
    f.close();
  }
  tmp.commit();
}

template <class Real>
void read_checkpoint(const fs::path& file, FluidLattice<Real>& fluid, const cases::FluidCase& c,
                     Baseline& base) {
  output::Hdf5File f(file, output::Hdf5File::Mode::read);
  const auto recorded = nlohmann::json::parse(f.attribute_string("/", "case"));
  require_resumable(file, recorded, c.to_json());
  restore_populations(f, fluid, file);
  fluid.set_time_step(f.attribute_int("/", "time_step"));
  base.mass = f.attribute_double("/", "baseline_mass");
  base.momentum = {f.attribute_double("/", "baseline_momentum_x"),
                   f.attribute_double("/", "baseline_momentum_y"),
                   f.attribute_double("/", "baseline_momentum_z")};
  base.amplitude = f.attribute_double("/", "baseline_amplitude");
  base.wall_s = f.attribute_double("/", "wall_s");
}

template <class Real>
RunReport run_with_precision(const cases::FluidCase& c, const RunOptions& o) {
  // On a GPU the lattice steps there, and `fluid` below is the host mirror
  // that the checkpoints, snapshots and final observables read: brought up to
  // date by a download before each read, so they are the CPU run's code
  // unchanged. The GPU's memory is taken before the output folder is
  // touched, so a GPU that cannot hold the lattice refuses the run up front.
  std::unique_ptr<gpu::GpuFluidLattice<Real>> device =
      lattice_on_gpu<Real>(c.device == cases::Device::cuda, c.size, c.relaxation);
  RunShell shell(o, c.to_json(), c.warnings, c.run.threads);
  if (shell.start() == StartMode::already_completed) return shell.already_completed();
  RunLog& log = shell.log();

  FluidLattice<Real> fluid(c.size, c.relaxation);
  fluid.set_body_force(c.body_force);
  Baseline base;
  const fs::path& checkpoint = shell.checkpoint_file();
  if (shell.resuming()) {
    // a checkpoint of another case is an input error of its own; any other
    // failure to read it means the file is damaged: say what to do with it
    try {
      read_checkpoint(checkpoint, fluid, c, base);
    } catch (const input::InputError&) {
      throw;
    } catch (const std::exception& e) {
      damaged_checkpoint(checkpoint, e.what());
    }
    log.info("resumed from " + checkpoint.string() + " at step " +
             std::to_string(fluid.time_step()));
  } else {
    fluid.initialise_equilibrium(
        [&](int x, int y, int z) { return cases::initial_state(c, x, y, z); });
    base.mass = fluid.total_mass();
    base.momentum = fluid.total_momentum();
    base.amplitude = wave_amplitude(fluid, c);
  }
  nlohmann::json device_record;
  if (device) {
    device->upload(fluid);
    const gpu::GpuDevice& g = device->gpu();
    device_record = gpu_device_record(g);
    log.info("lattice on GPU " + std::to_string(g.index) + ", " + g.name);
  }
  const auto time_step = [&] { return device ? device->time_step() : fluid.time_step(); };
  const auto total_mass = [&] { return device ? device->total_mass() : fluid.total_mass(); };
  const auto mirror = [&] {
    if (device) device->download(fluid);
  };
  log.info(
      std::string("flocsim ") + kFlocsimVersion + " fluid scene: " + std::to_string(c.size.nx) +
      " x " + std::to_string(c.size.ny) + " x " + std::to_string(c.size.nz) +
      " cells, nu = " + std::to_string(c.relaxation.viscosity) +
      " (tau = " + std::to_string(c.relaxation.tau_plus()) + "), " +
      (sizeof(Real) == 8 ? "double" : "float") + " precision, " +
      (device ? std::string("on the GPU") : std::to_string(omp_get_max_threads()) + " threads") +
      ", " + std::to_string(c.run.steps) + " steps");

  ProgressReporter progress(log, o.out_dir / "progress.json", fluid.time_step(), c.run.steps,
                            c.size.cells(), c.run.progress_every_s);
  TimedStages stages;
  const auto fluid_stage = stages.declare("fluid");
  const auto output_stage = stages.declare("output");
  const auto checkpoint_stage = stages.declare("checkpoint");
  shell.set_first_step(fluid.time_step());
  // A blow-up shows as a non-finite population, which makes the mass sum
  // non-finite; checking it every few steps costs about 1 % of the run.
  const long health_every = 100;

  while (time_step() < c.run.steps) {
    stages.run(fluid_stage, [&] {
      if (!device) return fluid.step();
      // Steps queue on the GPU; waiting for them at each health check keeps
      // the stage's time the steps' own (not their launches') without a
      // wait per step. Reads between (snapshots, checkpoints) wait in theirs.
      device->step();
      if (device->time_step() % health_every == 0 || device->time_step() == c.run.steps)
        device->synchronize();
    });
    const long t = time_step();

    if (t % health_every == 0 || t == c.run.steps) {
      const double mass = total_mass();
      if (!std::isfinite(mass)) {
        return shell.blown_up("step " + std::to_string(t), "the liquid mass is no longer finite",
                              "velocities beyond the Mach limit or a viscosity too small for the "
                              "resolution");
      }
    }
    if (c.run.write_fields && c.run.fields_every > 0 && t % c.run.fields_every == 0 &&
        t != c.run.steps)
      stages.run(output_stage, [&] {
        mirror();
        write_fields(o.out_dir, fluid);
      });
    const bool stop_now = shell.stop_requested(t);
    if ((stop_now || shell.checkpoint_due(t, c.run.checkpoint_every_s)) && t < c.run.steps) {
      // only a state that passed the health check is checkpointed
      if (!std::isfinite(total_mass())) continue;
      stages.run(checkpoint_stage, [&] {
        mirror();
        write_checkpoint(o.out_dir, fluid, c, base, base.wall_s + shell.wall_s());
      });
      shell.checkpoint_written(t);
      if (stop_now) return shell.interrupted(progress, t);
    }
    progress.update(t);
  }
  progress.finish(time_step());

  // ---- final state and result.json ------------------------------------------
  mirror();
  if (c.run.write_fields) stages.run(output_stage, [&] { write_fields(o.out_dir, fluid); });

  nlohmann::json obs;
  const double mass = fluid.total_mass();
  const lattice::Vector3 p = fluid.total_momentum();
  const double n = static_cast<double>(c.size.cells());
  const double steps = static_cast<double>(c.run.steps);
  obs["mass_initial"] = base.mass;
  obs["mass_final"] = mass;
  obs["mass_relative_change"] = (mass - base.mass) / base.mass;
  obs["momentum_final"] = {p.x, p.y, p.z};
  // exact expectation: the body force adds f per cell per step
  obs["momentum_expected"] = {base.momentum.x + steps * n * c.body_force.x,
                              base.momentum.y + steps * n * c.body_force.y,
                              base.momentum.z + steps * n * c.body_force.z};
  {
    std::vector<double> rho, ux, uy, uz;
    fluid.macroscopic_fields(rho, ux, uy, uz);
    double ke = 0, umax = 0;
    for (std::size_t i = 0; i < rho.size(); ++i) {
      const double u2 = ux[i] * ux[i] + uy[i] * uy[i] + uz[i] * uz[i];
      ke += 0.5 * rho[i] * u2;
      umax = std::max(umax, std::sqrt(u2));
    }
    obs["kinetic_energy_final"] = ke;
    obs["max_speed_final"] = umax;
  }
  const double analytic_rate = cases::analytic_decay_rate(c);
  if (analytic_rate > 0 && steps > 0) {
    const double a1 = wave_amplitude(fluid, c);
    const double measured_rate = std::log(base.amplitude / a1) / steps;
    obs["wave_amplitude_initial"] = base.amplitude;
    obs["wave_amplitude_final"] = a1;
    obs["wave_amplitude_analytic_final"] = base.amplitude * std::exp(-analytic_rate * steps);
    obs["decay_rate_measured"] = measured_rate;
    obs["decay_rate_analytic"] = analytic_rate;
    obs["viscosity_measured"] = c.relaxation.viscosity * measured_rate / analytic_rate;
  }
  const double wall = shell.wall_s();
  const long steps_here = fluid.time_step() - shell.first_step();
  const double fluid_s = stages.seconds(fluid_stage);
  nlohmann::json result;
  result["case"] = c.to_json();
  result["observables"] = obs;
  result["cost"] = shell.cost(base.wall_s, wall, c.run.steps, steps_here, stages);
  result["cost"]["MLUPS"] = fluid_s > 0 ? steps_here * n / fluid_s / 1e6 : 0.0;
  if (device) result["device"] = device_record;
  const std::string mlups = std::to_string(result["cost"]["MLUPS"].get<double>());
  return shell.complete(std::move(result), wall, std::to_string(c.run.steps) + " steps",
                        " (" + mlups + " MLUPS)");
}

}  // namespace

RunReport run_fluid_case(const cases::FluidCase& c, const RunOptions& options) {
  return run_guarded(options.out_dir, [&] {
    return c.precision == cases::Precision::single_precision
               ? run_with_precision<float>(c, options)
               : run_with_precision<double>(c, options);
  });
}

}  // namespace flocsim::run
