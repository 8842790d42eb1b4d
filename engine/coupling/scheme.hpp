#pragma once
// How a case couples its spheres to the liquid (docs/coupling.md): the method
// and its options.
//
//   immersed boundary  markers on each sphere's surface force the liquid
//                      towards the surface velocity (engine/immersed_boundary):
//                      with direct forcing (Uhlmann 2005, Breugem 2012: the
//                      force that brings the interpolated velocity to the
//                      target, in one or more sweeps) or with control forcing
//                      (the paper's: ten Cate et al. 2002 after Derksen & Van
//                      den Akker 1999, the marker force carried from step to
//                      step and corrected by the slip the last step left);
//   partially saturated  no markers: each cell's collision is blended with a
//                      solid operator in proportion to the part of the cell the
//                      spheres cover (Noble & Torczynski 1998;
//                      engine/partially_saturated).
//
// Each scheme moves the hydrodynamic radius and the lattice's own close-pair
// resistance, so the calibration tables keep entries per scheme
// (same_calibration) and a case accepts only a scheme they hold.
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace flocsim::coupling {

enum class Method { immersed_boundary, partially_saturated };

inline std::string method_name(Method m) {
  return m == Method::immersed_boundary ? "immersed-boundary" : "partially-saturated";
}
inline const std::vector<std::string>& method_names() {
  static const std::vector<std::string> names = {"immersed-boundary", "partially-saturated"};
  return names;
}
inline std::optional<Method> method_from_name(const std::string& name) {
  if (name == "immersed-boundary") return Method::immersed_boundary;
  if (name == "partially-saturated") return Method::partially_saturated;
  return std::nullopt;
}

// roma3: Roma, Peskin & Berger (1999), 3 points per direction (the paper's
// and Uhlmann's/Breugem's choice). linear2: the 2-point linear hat, 8 cells
// per marker instead of 27; cheaper and less smooth (immersed_boundary/kernel.hpp).
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

// direct: the force that brings the interpolated velocity to the surface
// velocity, computed afresh every step (in `sweeps` Jacobi sweeps). control:
// the force of the previous step corrected by the slip it left (a PI
// controller; immersed_boundary/control_forcing.hpp).
enum class Forcing { direct, control };

inline std::string forcing_name(Forcing f) {
  return f == Forcing::direct ? "direct" : "control";
}
inline const std::vector<std::string>& forcing_names() {
  static const std::vector<std::string> names = {"direct", "control"};
  return names;
}
inline std::optional<Forcing> forcing_from_name(const std::string& name) {
  if (name == "direct") return Forcing::direct;
  if (name == "control") return Forcing::control;
  return std::nullopt;
}

// Gains of the control forcing, per step, in units of the force density that
// would remove the slip e of an isolated marker in one step (2 rho e): each
// step the marker force changes by rho (integral e + proportional (e - e_prev)).
// With integral = 2 and proportional = 0 an isolated marker is forced exactly
// as one direct-forcing sweep would. At a steady state any stable gains leave
// no slip at the markers (the integral action), so the calibration does not
// depend on them.
//
// Where the loop is stable was measured (docs/coupling.md, "Control forcing:
// where it is stable"; bench_control_stability, 1e5 steps per point, a = 4 at
// nu 0.01-0.04 and a = 6 at nu 0.005-0.02, a sphere held in a flow and one
// settling at a nominal Re 12): held spheres are stable up to the largest
// gains tried (integral 4); a settling sphere goes unstable within 40-225
// steps, in a
// period-2 mode, once the loop's gain at that frequency, integral +
// 2 proportional, reaches 4 (integral 4; integral 2 with proportional 1),
// and stays bounded at 3 (integral 3; integral 1 with proportional 1). One
// run with integral 0.5 blew up after 68 000 steps at a = 6, nu = 0.005,
// where 0.1 and 1 did not, so gains below 1 are not offered. Accepted:
// 1 <= integral, 0 <= proportional, integral + 2 proportional <= 3.
// Default: integral 2 (one direct-forcing sweep for an isolated marker, the
// smallest slip of the gains with a margin of almost 2 to the edge),
// proportional 0 (it did not lower the slip measurably).
struct ControlGains {
  double integral = 2.0;
  double proportional = 0.0;
  bool operator==(const ControlGains& o) const {
    return std::abs(integral - o.integral) <= 1e-12 &&
           std::abs(proportional - o.proportional) <= 1e-12;
  }
};
inline constexpr double kSmallestIntegralGain = 1.0;
inline constexpr double kLargestPeriodTwoGain = 3.0;  // integral + 2 proportional
// Whether the gains lie where the loop was measured stable.
inline bool stable_gains(const ControlGains& g) {
  return g.integral >= kSmallestIntegralGain && g.proportional >= 0 &&
         g.integral + 2 * g.proportional <= kLargestPeriodTwoGain * (1 + 1e-12);
}
// Why gains outside stable_gains are refused, for every message that refuses
// them (the case reader, flocsim calibrate): the region and what happens
// beyond it.
inline std::string stable_gains_region() {
  char text[320];  // the text is about 215 characters: room for any %g
  std::snprintf(text, sizeof text,
                "outside the region where control forcing was measured stable: integral >= %g, "
                "proportional >= 0, integral + 2 proportional <= %g (a settling sphere shakes "
                "itself apart in a period-2 mode at 4; docs/coupling.md)",
                kSmallestIntegralGain, kLargestPeriodTwoGain);
  return text;
}

struct Scheme {
  // Immersed boundary only:
  double marker_spacing = 0.7;  // mean distance between markers on the input sphere (dx)
  int sweeps = 2;               // direct-forcing sweeps per time step (1 with control forcing)
  Kernel kernel = Kernel::roma3;
  Forcing forcing = Forcing::direct;
  ControlGains gains;  // control forcing only
  Method method = Method::immersed_boundary;

  bool immersed_boundary() const { return method == Method::immersed_boundary; }
  bool control() const { return immersed_boundary() && forcing == Forcing::control; }

  // Everything that defines the scheme, gains included.
  bool operator==(const Scheme& o) const {
    return same_calibration(o) && (!control() || gains == o.gains);
  }
  // The same scheme as far as its calibration goes: the hydrodynamic radius
  // and the lattice's close-pair share do not depend on the control gains.
  bool same_calibration(const Scheme& o) const {
    if (method != o.method) return false;
    if (!immersed_boundary()) return true;
    return std::abs(marker_spacing - o.marker_spacing) <= 1e-9 && sweeps == o.sweeps &&
           kernel == o.kernel && forcing == o.forcing;
  }
  // "markers 0.7 dx apart, 2 sweeps, roma3 kernel"; "markers 1 dx apart,
  // control forcing (gains 2, 0), roma3 kernel"; "partially saturated cells"
  std::string describe() const {
    if (!immersed_boundary()) return "partially saturated cells";
    char spacing[32];
    std::snprintf(spacing, sizeof spacing, "%g", marker_spacing);
    std::string how;
    if (control()) {
      char g[64];
      std::snprintf(g, sizeof g, "control forcing (gains %g, %g), ", gains.integral,
                    gains.proportional);
      how = g;
    } else {
      how = std::to_string(sweeps) + (sweeps == 1 ? " sweep, " : " sweeps, ");
    }
    return std::string("markers ") + spacing + " dx apart, " + how + kernel_name(kernel) +
           " kernel";
  }
};

// The paper's markers (Derksen 2013: 0.7 dx apart) with multi-direct forcing
// (Uhlmann 2005, Breugem 2012: two sweeps), Roma's 3-point kernel: the
// reference the other schemes are measured against.
inline constexpr Scheme kPaperScheme{};

// The offered cheaper option: markers 1 dx apart (about dx^3 of shell per
// marker, as Uhlmann 2005 and Breugem 2012) and one forcing sweep. On frozen
// random arrays at phi = 0.2, Re = 10 its drag is the paper method's to
// 0.01 % (a = 4 and 6) at 0.8 of its cost per step (docs/accuracy-cost.md);
// the draft and standard presets use it where it is validated.
inline constexpr Scheme kOneSweepScheme{1.0, 1, Kernel::roma3};

// The paper's own forcing, control forcing, with markers 1 dx apart. Not the
// paper's 0.7 dx: with markers denser than the lattice a sphere dragged
// through the liquid feels 0.78-0.85 of the drag it feels held (nu 0.1-0.02,
// Re 1), at 1 dx apart 0.995 and at 1.2 dx 1.000 (docs/coupling.md,
// "Galilean invariance"). The likely reason: closer than dx the markers'
// slips are not independent (more markers than cells under their kernels),
// so the integral action, which drives every marker's slip to zero, has no
// unique force to settle on and what it settles on depends on how the sphere
// moves across the grid.
inline constexpr Scheme kControlScheme{1.0, 1, Kernel::roma3, Forcing::control};
// Control forcing's densest markers (dx): see kControlScheme.
inline constexpr double kSmallestControlMarkerSpacing = 1.0;
// Why closer markers are refused, for every message that refuses them.
inline std::string dense_control_markers_why() {
  char text[200];
  std::snprintf(text, sizeof text,
                "must be >= %g (with markers closer than the lattice spacing a sphere moving "
                "through the liquid feels 0.78-0.85 of the drag it feels held, at 1 dx "
                "0.995-1.0005; docs/coupling.md)",
                kSmallestControlMarkerSpacing);
  return text;
}

// Partially saturated cells: no markers.
inline constexpr Scheme kPartiallySaturatedScheme{.method = Method::partially_saturated};

// The densest suspension (solids fraction) a scheme is validated for. With a
// single direct-forcing sweep the slip left where neighbouring spheres'
// kernels overlap is not corrected: simple cubic arrays at phi = 0.27 come out
// 3.2-3.8 % below Sangani-Acrivos (2 % is the bar), against within 2 % up to
// phi = 0.2. Control forcing and partially saturated cells have not been
// checked above phi = 0.2 (docs/coupling.md).
inline double largest_validated_phi(const Scheme& s) {
  return s.immersed_boundary() && s.forcing == Forcing::direct && s.sweeps >= 2 ? 1.0 : 0.2;
}

}  // namespace flocsim::coupling
