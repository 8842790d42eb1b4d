#pragma once
// The fluid-only case ("scene": "fluid"): a periodic box of liquid with an
// analytic initial field and an optional uniform body force. Used to check
// and benchmark the lattice-Boltzmann core on its own, and as the smallest
// real case the orchestrator can run. Format: docs/user-guide.md.
#include <nlohmann/json.hpp>
#include <string>

#include "engine/case/device.hpp"
#include "engine/lattice/fluid_lattice.hpp"

namespace flocsim::cases {

// Largest lattice velocity accepted anywhere in an input: Ma = |u| / c_s <= 0.2
// keeps compressibility errors (O(Ma^2)) at the per-cent level and the TRT
// scheme well inside its stability range at tau = 0.515.
inline constexpr double kMaxMach = 0.2;
inline constexpr double kMaxLatticeSpeed = 0.11547005383792516;  // 0.2 / sqrt(3)
// Smallest viscosity the solver is tested at (tau = 0.515); lower values are
// accepted with a warning.
inline constexpr double kSmallestTestedViscosity = 0.005;

enum class Precision { single_precision, double_precision };

struct InitialField {
  std::string type = "rest";  // rest | uniform | shear_wave | taylor_green
  lattice::Vector3 mean_velocity;
  double amplitude = 0.0;
  int wavelengths = 1;                    // whole wavelengths across the box
  int axis = 0;                           // shear wave: direction of the wave vector (0 = x)
  int component = 1;                      // shear wave: velocity component
  int plane_first = 0, plane_second = 1;  // Taylor-Green plane
  double noise = 0.0;                     // amplitude of uniform random velocity perturbations
  unsigned seed = 1;
};

struct RunControl {
  long steps = 1000;
  double progress_every_s = 2.0;
  double checkpoint_every_s = 600.0;
  long fields_every = 0;  // steps between field snapshots; 0: final state only
  bool write_fields = false;
  int threads = 0;  // 0: all available
};

struct FluidCase {
  Precision precision = Precision::double_precision;
  Device device = Device::cpu;  // "device": where the lattice steps (device.hpp)
  lattice::Extent size{32, 32, 32};
  lattice::Relaxation relaxation{0.01, 0.25};
  lattice::Vector3 body_force;
  InitialField initial;
  RunControl run;
  std::vector<std::string> warnings;  // accepted, but worth telling the user

  // The case with every default filled in (what result.json records).
  nlohmann::json to_json() const;
};

// Validates everything before any work starts; throws input::InputError
// naming the field, the value and the allowed range.
FluidCase parse_fluid_case(const nlohmann::json& document);

// The macroscopic initial state at a cell.
lattice::Macroscopic initial_state(const FluidCase& c, int x, int y, int z);

// Exact decay rate of the initial mode's amplitude per step when the flow is
// a single shear wave (nu k^2) or Taylor-Green vortex (2 nu k^2); 0 otherwise.
double analytic_decay_rate(const FluidCase& c);
// Wave number of the initial mode.
double initial_wave_number(const FluidCase& c);

}  // namespace flocsim::cases
