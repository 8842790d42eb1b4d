#pragma once
// What one case will cost, known before it runs: its lattice and spheres, its
// length in steps (from the protocol the run itself follows), and the time and
// memory of a few of its real time steps, measured by building the case's own
// coupled step (whatever coupling and options the case selects) and running it.
// `flocsim sweep plan` and `flocsim sweep launch` print these.
#include <nlohmann/json.hpp>
#include <string>

#include "engine/case/case_file.hpp"
#include "engine/lattice/fluid_lattice.hpp"

namespace flocsim::run {

struct CaseSize {
  std::string scene;
  lattice::Extent box{0, 0, 0};  // the lattice (0 cells in a scene without a liquid)
  long cells = 0;
  int spheres = 0;
  bool single_precision = false;
  // The run's length: the shortest and the longest the protocol allows (stage
  // 1 ends when stationary, between its bounds); equal when fixed.
  long steps_min = 0, steps_max = 0;
  double steps_per_convective_time = 0;  // a/U_inf in steps (0 without spheres)
  int threads = 0;                       // the case's OpenMP threads (0: all available)
  // The case less what does not change the cost of one step (the seed, the
  // attraction, the Reynolds number and the viscosity it sets, the protocol's
  // durations): cases with equal keys share one measurement.
  nlohmann::json cost_key;
};

CaseSize case_size(const cases::ParsedCase& c);

struct StepMeasurement {
  double setup_s = 0;       // building the lattice and the coupling, placing the spheres
  double step_s = 0;        // wall seconds per time step (mean of the timed steps)
  double memory_bytes = 0;  // bytes the solver state allocated (lattice, coupling, spheres)
  int threads = 0;          // OpenMP threads the steps ran on
  int steps = 0;            // steps timed (after one untimed warm-up step)
};

// Builds the case's solver state as its run would, takes one warm-up step and
// times at least `steps` more, and more until `seconds` have passed (a rate
// over a few milliseconds would be noise), at most kMostMeasuredSteps.
// `copies` instances run at once, each with the case's threads, as that many
// workers of a sweep would: the rate then holds what they cost each other on
// this machine (shared cores, memory bandwidth, other users' load), which no
// model of the machine knows. The result is the mean over the copies, memory
// per copy. Nothing is written to disk.
inline constexpr int kMostMeasuredSteps = 1000;
StepMeasurement measure_steps(const cases::ParsedCase& c, int steps, double seconds = 1.0,
                              int copies = 1);

// Bytes this process has allocated and not freed (glibc's count over all arenas).
double allocated_bytes();

}  // namespace flocsim::run
