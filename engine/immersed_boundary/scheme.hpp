#pragma once
// The immersed-boundary options a case may choose (docs/immersed-boundary.md,
// "Options"): how far apart the markers sit, how many direct-forcing sweeps a
// step makes and which interpolation/spreading kernel couples them to the
// lattice. Each combination changes the hydrodynamic radius and the lattice's
// own close-pair resistance, so a run accepts only a scheme that the shipped
// calibration tables hold for its resolution (with a hand-given input radius,
// at some resolution) (engine/calibration).
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace flocsim::immersed_boundary {

// roma3: Roma, Peskin & Berger (1999), 3 points per direction (the paper's
// and Uhlmann's/Breugem's choice). linear2: the 2-point linear hat, 8 cells
// per marker instead of 27; cheaper and less smooth (kernel.hpp).
enum class Kernel { roma3, linear2 };

// Points per direction of the kernel's support.
constexpr int kernel_width(Kernel k) {
  return k == Kernel::roma3 ? 3 : 2;
}

inline std::string kernel_name(Kernel k) {
  return k == Kernel::roma3 ? "roma3" : "linear2";
}

inline const std::vector<std::string>& kernel_names() {
  static const std::vector<std::string> names = {"roma3", "linear2"};
  return names;
}

inline std::optional<Kernel> kernel_from_name(const std::string& name) {
  if (name == "roma3") return Kernel::roma3;
  if (name == "linear2") return Kernel::linear2;
  return std::nullopt;
}

struct Scheme {
  double marker_spacing = 0.7;  // mean distance between markers on the input sphere (dx)
  int sweeps = 2;               // direct-forcing sweeps per time step
  Kernel kernel = Kernel::roma3;

  bool operator==(const Scheme& o) const {
    return std::abs(marker_spacing - o.marker_spacing) <= 1e-9 && sweeps == o.sweeps &&
           kernel == o.kernel;
  }
  // "markers 0.7 dx apart, 2 sweeps, roma3 kernel"
  std::string describe() const {
    char spacing[32];
    std::snprintf(spacing, sizeof spacing, "%g", marker_spacing);
    return std::string("markers ") + spacing + " dx apart, " + std::to_string(sweeps) +
           (sweeps == 1 ? " sweep, " : " sweeps, ") + kernel_name(kernel) + " kernel";
  }
};

// The paper's method (Derksen 2013, after Uhlmann 2005 and Breugem 2012):
// markers 0.7 dx apart, two forcing sweeps, Roma's 3-point kernel.
inline constexpr Scheme kPaperScheme{};

// The offered cheaper option: markers 1 dx apart (about dx^3 of shell per
// marker, as Uhlmann 2005 and Breugem 2012) and one forcing sweep. On frozen
// random arrays at phi = 0.2, Re = 10 its drag is the paper method's to
// 0.01 % (a = 4 and 6) at 0.8 of its cost per step (docs/accuracy-cost.md);
// the draft and standard presets use it where it is validated.
inline constexpr Scheme kOneSweepScheme{1.0, 1, Kernel::roma3};

// The densest suspension (solids fraction) a scheme is validated for. With a
// single sweep the slip left where neighbouring spheres' kernels overlap is
// not corrected: simple cubic arrays at phi = 0.27 come out 3.2-3.8 % below
// Sangani-Acrivos (2 % is the bar), against within 2 % up to phi = 0.2.
inline double largest_validated_phi(const Scheme& s) {
  return s.sweeps >= 2 ? 1.0 : 0.2;
}

}  // namespace flocsim::immersed_boundary
