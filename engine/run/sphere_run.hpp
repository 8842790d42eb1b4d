#pragma once
// The time loop of the scenes with spheres. It composes only the modules a
// scene needs (DESIGN.md "Engine shape"):
//
//   scene        liquid + IB   sphere motion   direct interactions   lubrication
//   granular     -             ballistic       yes (events)          -
//
// and runs the start-up protocol of the paper (end of section 3): stage 1
// with du = 0 until a dynamically stationary state (two-window detector on
// the stage's signal, at least stage1_min and at most stage1_max a/U_inf);
// stage 2 with du at its target, stage2_settle a/U_inf to reach the new
// state, then `statistics` a/U_inf of time series summarised by batch means.
//
// Output directory: as fluid_run.hpp, plus spheres.h5/.xdmf (snapshots) and
// series.h5 (time series); result.json holds steady averages with errors and
// the window used, per-module cost and the derived lattice-unit quantities.
#include "engine/case/suspension_case.hpp"
#include "engine/run/fluid_run.hpp"

namespace flocsim::run {

// Scenes run_sphere_case can run in this build.
const std::vector<std::string>& runnable_sphere_scenes();

RunReport run_sphere_case(const cases::SuspensionCase& c, const RunOptions& options);

}  // namespace flocsim::run
