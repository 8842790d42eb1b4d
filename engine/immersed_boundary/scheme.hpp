#pragma once
// The immersed-boundary options a case may choose (docs/immersed-boundary.md,
// "Options"): how far apart the markers sit, how many direct-forcing sweeps a
// step makes and which interpolation/spreading kernel couples them to the
// lattice. Each combination changes the hydrodynamic radius and the lattice's
// own close-pair resistance, so a run accepts only a scheme that the shipped
// calibration tables hold for its resolution (engine/calibration).
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

}  // namespace flocsim::immersed_boundary
