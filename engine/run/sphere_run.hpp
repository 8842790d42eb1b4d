#pragma once
// The time loop of the scenes with spheres (cases::kScenes says which modules
// each composes). It puts together, each in its own unit:
//   coupled_step.hpp     one time step as named, timed stages
//   protocol.hpp         stage 1 (du = 0), the well's switch-on, stage 2,
//                        the statistics window; owns the well strength
//   time_series.hpp      the sampled columns, declared by name
//   sphere_checkpoint.hpp  the checkpoint
//   sphere_results.hpp   steady averages, distributions, series.h5
//   run_shell.hpp        output directory, log, stop signals, result.json's
//                        envelope (shared with the fluid scene)
// and here: the initial placement, what one sample measures, and the loop.
//
// Output directory: as fluid_run.hpp, plus spheres/ + spheres.xdmf
// (snapshots), series.h5 (time series and phi(x, t)), the final liquid field
// (fields/ + fields.xdmf); result.json holds steady averages with errors and
// the window used, the reference correlations at the measured state,
// per-stage cost and the derived lattice-unit quantities.
#include "engine/case/suspension_case.hpp"
#include "engine/run/fluid_run.hpp"
#include "engine/spheres/sphere_set.hpp"

namespace flocsim::run {

// A scene without spheres is refused (input::InputError).
RunReport run_sphere_case(const cases::SuspensionCase& c, const RunOptions& options);

// The spheres of a fresh start: a single sphere in the middle, a snapshot's
// centres, or random non-overlapping positions (at rest with a liquid; with
// Maxwellian velocities of no net momentum in a granular gas).
void place_spheres(const cases::SuspensionCase& c, const cases::SceneModules& m,
                   const spheres::PeriodicBox& box, spheres::SphereSet& s);

}  // namespace flocsim::run
