#pragma once
// One time step of a sphere scene: the modules the scene composes
// (cases::SceneModules), each a named stage timed by name, in this order:
//
//   coupling           no-slip for the current sphere state: forces spread
//                      onto the lattice (immersed boundary, timed as
//                      "immersed_boundary") or the cells' solid fractions
//                      (partially saturated cells, "partially_saturated")
//   fluid              collision and streaming with them
//   (coupling)         the loads of the step, where the scheme measures them
//                      during the fluid step (timed with the coupling)
//   spheres            velocities from the hydrodynamic force and torque, net
//                      gravity and the inside-liquid momentum change
//   (health)           every sphere's speed, before anything moves them, and
//                      the coupling's period-2 oscillation (coupling_monitor.hpp)
//   lubrication        radial lubrication below s0, implicit per pair
//   events             collisions and square wells while the spheres move to
//                      the end of the step; without contacts a ballistic move
//                      (timed as spheres)
//
// The liquid is driven by the body force f that balances the net gravity of
// the spheres (docs/model.md section 1), so the total momentum stays zero.
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "engine/case/suspension_case.hpp"
#include "engine/coupling/sphere_coupling.hpp"
#include "engine/coupling_gpu/gpu_partially_saturated.hpp"
#include "engine/coupling_gpu/gpu_sphere_coupling.hpp"
#include "engine/coupling_schemes/make_coupling.hpp"
#include "engine/events/direct_interactions.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/lattice_gpu/gpu_fluid_lattice.hpp"
#include "engine/lubrication/radial_lubrication.hpp"
#include "engine/observables/liquid_averages.hpp"
#include "engine/observables_gpu/gpu_liquid_averages.hpp"
#include "engine/run/coupling_monitor.hpp"
#include "engine/run/timed_stages.hpp"
#include "engine/spheres/sphere_dynamics.hpp"

namespace flocsim::run {

// Stage names, as result.json's cost.modules_s reports them.
namespace stage_name {
inline constexpr std::string_view fluid = "fluid";
inline constexpr std::string_view spheres = "spheres";
inline constexpr std::string_view lubrication = "lubrication";
inline constexpr std::string_view events = "events";
}  // namespace stage_name

// The liquid and its coupling to the spheres (scenes with a liquid). On a
// GPU (`device` given: the case's "device": "cuda") the lattice steps there
// and the coupling (immersed boundary or partially saturated cells) couples
// the spheres to it (engine/coupling_gpu); the samples' liquid averages are
// reduced there too (averages(), engine/observables_gpu), so a sample
// downloads no lattice. `fluid` is then the run's mirror, brought up to date
// by to_host() before anything else reads it (checkpoints and the health
// check before one, the final fields), so that everything downstream is the
// CPU run's code unchanged; between those it is stale, and nothing reads it.
template <class Real>
struct Liquid {
  lattice::FluidLattice<Real> fluid;
  std::unique_ptr<gpu::GpuFluidLattice<Real>> device;
  std::unique_ptr<gpu::GpuLiquidAverages<Real>> device_averages;  // with `device`
  std::unique_ptr<coupling::SphereCoupling<Real>> coupling;
  spheres::SphereDynamicsSettings dynamics;
  std::vector<std::uint8_t> solid;  // scratch of the CPU's liquid averages
  std::vector<double> centres;      // scratch of the GPU's: x y z per sphere
  // The immersed boundary on the GPU has the spheres' loads before the step,
  // so the sphere side runs while the GPU steps; partially saturated cells
  // measure them during the step, so the step is waited for at once.
  bool overlaps_sphere_side = false;

  explicit Liquid(const cases::SuspensionCase& c,
                  std::unique_ptr<gpu::GpuFluidLattice<Real>> on_gpu = nullptr)
      : fluid(c.derived.box, {c.numerics.viscosity, c.numerics.trt_magic}),
        device(std::move(on_gpu)) {
    const double volume = static_cast<double>(c.derived.box.cells());
    dynamics.external = spheres::settling_forces(static_cast<std::size_t>(c.derived.sphere_count),
                                                 c.numerics.radius_cells, c.physics.density_ratio,
                                                 volume, c.derived.gravity);
    dynamics.rigid_inside_liquid = c.numerics.inside_liquid == "rigid-body";
    fluid.set_body_force({dynamics.external.liquid_body_force.x(), 0, 0});
    if (c.numerics.coupling.immersed_boundary()) fluid.enable_force_field();
    if (device) {
      device->set_body_force(fluid.body_force());
      // every coupling's samples reduce the liquid on the GPU (averages())
      device_averages = std::make_unique<gpu::GpuLiquidAverages<Real>>();
    }
    if (device && !c.numerics.coupling.immersed_boundary()) {
      coupling =
          std::make_unique<gpu::GpuPartiallySaturatedCells<Real>>(c.numerics.input_radius, *device);
    } else if (device) {
      overlaps_sphere_side = true;
      coupling = std::make_unique<gpu::GpuSphereCoupling<Real>>(
          immersed_boundary::ImmersedBoundarySettings{c.numerics.input_radius, c.numerics.coupling,
                                                      false},
          *device);
    } else {
      coupling = coupling::make_coupling<Real>(c.numerics.coupling, c.numerics.input_radius);
    }
  }

  // One collision and streaming step, where the lattice lives. On the GPU it
  // is only launched: the sphere side of the step (velocities, lubrication,
  // events) reads the loads the coupling's apply() already brought to the
  // host, never the lattice, so it runs on the CPU while the GPU steps, and
  // finish_step() waits for what is left. Every read of the device's state
  // before that (a download, the next apply's loads) is a blocking copy on
  // the same stream, so it sees the step complete whatever the order here.
  void step() {
    if (device)
      device->step();
    else
      fluid.step();
  }
  // Waits for the GPU's step (nothing on the CPU, where step() is complete).
  void finish_step() {
    if (device) device->synchronize();
  }
  // The liquid averages of the current state (observables/liquid_averages.hpp)
  // with the cells inside the spheres `s` solid, where the lattice lives: on
  // the GPU its reduction (the centres up, a partial sum per block down; the
  // mirror is neither read nor updated), else on the lattice itself.
  observables::LiquidAverages averages(const spheres::SphereSet& s) {
    if (!device) return observables::liquid_averages(fluid, s, solid);
    centres.resize(3 * s.size());
    for (std::size_t i = 0; i < s.size(); ++i)
      for (int d = 0; d < 3; ++d) centres[3 * i + d] = s.position[i][d];
    return observables::averages_from_sums(device_averages->sums(*device, centres, s.radius),
                                           device->extent().cells());
  }
  // The mirror up to date with the GPU: populations and the force field.
  // Nothing to do where it already is (a checkpoint, then the final fields
  // on one step: the field changes only in the coupling's apply(), before a
  // step).
  void to_host() {
    if (!device || fluid.time_step() == device->time_step()) return;
    device->download(fluid);
    device->download_force_field(fluid);
  }
  // The mirror's state (placed or resumed) onto the GPU.
  void to_device() {
    if (device) device->upload(fluid);
  }
};

// Fastest sphere speed accepted before the run is called unstable: beyond
// 0.3 (Ma ~ 0.5) the lattice cannot carry the flow around it.
inline constexpr double kMaxSphereSpeed = 0.3;

// The number of other spheres whose surfaces are within `gap` of sphere i's.
int close_neighbours(const spheres::SphereSet& s, const spheres::PeriodicBox& box, std::size_t i,
                     double gap);

// Empty when every sphere's speed is finite and below kMaxSphereSpeed, else
// what went wrong, with how many spheres were within `close_gap_over_a` a of
// the runaway one (the lubrication onset: a crowded sphere points at the
// coupling of close spheres rather than at the lattice).
std::string sphere_health(const spheres::SphereSet& s, const spheres::PeriodicBox& box,
                          double close_gap_over_a);

template <class Real>
class CoupledStep {
 public:
  // `escape_velocity`: the square well's strength at the start (the protocol's).
  // `device`: the lattice on a GPU for a case on "cuda" (null: the CPU).
  CoupledStep(const cases::SuspensionCase& c, double escape_velocity, TimedStages& stages,
              std::unique_ptr<gpu::GpuFluidLattice<Real>> device = nullptr)
      : modules_(cases::modules_of(c.scene)),
        box_{spheres::Vec3(c.derived.box.nx, c.derived.box.ny, c.derived.box.nz)},
        contacts_({.restitution = c.physics.restitution,
                   .friction = c.physics.friction,
                   .escape_velocity = escape_velocity,
                   .well_width = c.derived.well_width}),
        lubrication_({.viscosity = c.numerics.viscosity,
                      .liquid_density = 1.0,
                      .onset_gap = c.physics.lubrication_onset_over_a,
                      .saturation_gap = c.physics.lubrication_saturation_over_a,
                      .lattice_share = c.numerics.lubrication_lattice_share,
                      .explicit_euler = c.physics.lubrication_integration == "explicit-paper"}),
        stages_(stages) {
    // The stages a scene reports: those of the liquid's coupling wherever
    // there is a liquid, events always (0 s without contacts).
    if (modules_.liquid) {
      liquid_ = std::make_unique<Liquid<Real>>(c, std::move(device));
      if (modules_.spheres_move) coupling_ = std::make_unique<CouplingMonitor>();
      coupling_stage_ = stages.declare(liquid_->coupling->stage_name());
      fluid_stage_ = stages.declare(stage_name::fluid);
      lubrication_stage_ = stages.declare(stage_name::lubrication);
    }
    if (modules_.liquid || (modules_.spheres_move && !modules_.contacts))
      spheres_stage_ = stages.declare(stage_name::spheres);
    events_stage_ = stages.declare(stage_name::events);
  }

  // Advances `s` by one time step. Returns what went wrong when a sphere ran
  // away (a blow-up starts within a few steps): a diagnosed failure with the
  // last good checkpoint kept, not an event engine asked for an impossible
  // pair search. Empty when healthy.
  std::string advance(spheres::SphereSet& s) {
    if (liquid_) {
      Liquid<Real>& l = *liquid_;
      coupling::SphereCoupling<Real>& coupling = *l.coupling;
      stages_.run(coupling_stage_, [&] { coupling.apply(l.fluid, s); });
      stages_.run(fluid_stage_, [&] {
        l.step();
        if (!l.overlaps_sphere_side) l.finish_step();
      });
      stages_.run(coupling_stage_, [&] { coupling.after_liquid_step(l.fluid, s); });
      stages_.run(spheres_stage_, [&] {
        if (modules_.spheres_move) spheres::advance_velocities(s, coupling.loads(), l.dynamics);
      });
    }
    // O(N), well under 1 % of a step
    if (modules_.spheres_move) {
      std::string sick = sphere_health(s, box_, lubrication_.params().onset_gap);
      if (!sick.empty()) return sick;
    }
    if (coupling_) {
      const Liquid<Real>& l = *liquid_;
      loads_.resize(s.size());
      for (std::size_t i = 0; i < s.size(); ++i)
        loads_[i] = spheres::liquid_load_per_step(s, l.dynamics, l.coupling->force()[i],
                                                  l.coupling->internal_momentum_change()[i]);
      std::string sick = coupling_->observe(
          loads_, spheres::external_force_per_sphere(l.dynamics.external, s.volume()).norm());
      if (!sick.empty()) return sick;
    }
    if (modules_.lubrication)
      stages_.run(lubrication_stage_, [&] { lubrication_.apply(s, box_, 1.0); });
    if (modules_.contacts)
      stages_.run(events_stage_, [&] { contacts_.advance(s, box_, 1.0); });
    else if (modules_.spheres_move)
      stages_.run(spheres_stage_, [&] { spheres::advance_positions(s, box_); });
    // On the GPU the fluid stage is the launch above plus what of the step the
    // sphere side did not hide: the wait here (docs/gpu.md, "Overlap").
    if (liquid_) stages_.run(fluid_stage_, [&] { liquid_->finish_step(); });
    return {};
  }

  const cases::SceneModules& modules() const { return modules_; }
  const spheres::PeriodicBox& box() const { return box_; }
  events::DirectInteractions& contacts() { return contacts_; }
  const events::DirectInteractions& contacts() const { return contacts_; }
  Liquid<Real>* liquid() { return liquid_.get(); }
  // The coupling monitor of scenes with a liquid and moving spheres, else null.
  const CouplingMonitor* coupling() const { return coupling_.get(); }
  const Liquid<Real>* liquid() const { return liquid_.get(); }

 private:
  cases::SceneModules modules_;
  spheres::PeriodicBox box_;
  events::DirectInteractions contacts_;
  const lubrication::RadialLubrication lubrication_;
  std::unique_ptr<Liquid<Real>> liquid_;
  std::unique_ptr<CouplingMonitor> coupling_;
  std::vector<spheres::Vec3> loads_;
  TimedStages& stages_;
  TimedStages::Id coupling_stage_ = 0, fluid_stage_ = 0, spheres_stage_ = 0, lubrication_stage_ = 0,
                  events_stage_ = 0;
};

}  // namespace flocsim::run
