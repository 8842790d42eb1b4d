#pragma once
// Everything of a sphere scene that evolves besides the modules' own state
// (lattice, contacts, protocol): the spheres, the step, the time series and
// the accumulators of the statistics window. What a checkpoint holds, with
// the modules' state beside it.
#include <vector>

#include "engine/observables/pair_structure.hpp"
#include "engine/run/time_series.hpp"
#include "engine/spheres/sphere_set.hpp"

namespace flocsim::run {

// The largest values seen at the samples (every protocol.sample_every) over
// the run; checkpointed, so that a resumed run reports the same as one that
// ran straight through (from a checkpoint written before they were, they
// count from the resume).
struct RunExtremes {
  double momentum_drift = 0;  // |momentum balance - its first sample| (moving spheres, liquid)
  double liquid_speed = 0;    // |u| over every cell, lattice units (with a liquid)
  double liquid_speed_outside_spheres = 0;  // |u| over the cells outside every sphere
  double sphere_speed = 0;                  // |u_p| (moving spheres)
  // the liquid mass (sum of rho over every cell) at the first sample and its
  // largest deviation from it since (with a liquid)
  double mass_first = 0;
  bool mass_first_set = false;
  double mass_drift = 0;
};

struct SphereRunState {
  spheres::SphereSet spheres;
  long step = 0;
  TimeSeries series;
  std::vector<double> size_distribution_sum;  // sum of p(n) over statistics samples
  observables::PairStructure microstructure{1, 1, 1, 1};
  std::vector<double> phi_x;  // phi(x, t): one row of slabs per sample
  double wall_s = 0;          // before this invocation
  // momentum balance of liquid + spheres (scenes whose spheres move freely)
  double momentum_initial = 0;
  bool momentum_initial_set = false;
  RunExtremes extremes;

  explicit SphereRunState(bool with_liquid) : series(with_liquid) {}
};

}  // namespace flocsim::run
