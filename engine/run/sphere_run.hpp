#pragma once
// The time loop of the scenes with spheres. It composes only the modules a
// scene needs (cases::kScenes), in this order within a time step:
//
//   scene          liquid + IB   sphere motion      lubrication   direct interactions
//   suspension     yes           IB + gravity       yes           yes (events)
//   fixed-array    yes           held still         -             -
//   single-sphere  yes           IB + gravity       -             -
//   granular       -             ballistic          -             yes (events)
//
//   ib.apply (no-slip force for the current state) -> fluid.step ->
//   advance_velocities (IB force and torque, inside-liquid momentum change,
//   net gravity) -> lubrication (implicit, pairwise) -> events (move the
//   spheres to the end of the step with collisions and square wells; without
//   events a ballistic move).
//
// The liquid is driven by the body force f that balances the net gravity of
// the spheres (docs/model.md section 1), so the total momentum stays zero.
//
// It runs the start-up protocol of the paper (end of section 3): stage 1
// with du = 0 until a dynamically stationary state (two-window detector on
// U/U_inf with a liquid, on the granular temperature without; at least
// stage1_min and at most stage1_max a/U_inf); stage 2 with du at its target,
// stage2_settle a/U_inf to reach the new state, then `statistics` a/U_inf of
// time series summarised by batch means. Without a square well (du = 0,
// fixed-array, single-sphere) there is no stage 2: statistics begin when
// stage 1 ends.
//
// Output directory: as fluid_run.hpp, plus spheres/ + spheres.xdmf
// (snapshots), series.h5 (time series and phi(x, t)), the final liquid field
// (fields/ + fields.xdmf); result.json holds steady averages with errors and
// the window used, the reference correlations at the measured state,
// per-module cost and the derived lattice-unit quantities. Checkpoints hold
// the lattice populations, sphere states, the immersed boundary's
// inside-liquid momenta, attached pairs, event counters and accumulators.
#include "engine/case/suspension_case.hpp"
#include "engine/run/fluid_run.hpp"

namespace flocsim::run {

// A scene without spheres is refused (input::InputError).
RunReport run_sphere_case(const cases::SuspensionCase& c, const RunOptions& options);

}  // namespace flocsim::run
