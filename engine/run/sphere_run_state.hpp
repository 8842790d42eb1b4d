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

  explicit SphereRunState(bool with_liquid) : series(with_liquid) {}
};

}  // namespace flocsim::run
