#include "engine/case/numerics_limits.hpp"

#include <algorithm>
#include <vector>

#include "engine/case/case_support.hpp"
#include "engine/case/fluid_case.hpp"
#include "engine/case/scene.hpp"
#include "engine/coupling/scheme.hpp"
#include "engine/input/input_reader.hpp"

namespace flocsim::cases {

using input::InputError;

namespace {
// A suspension coupled by the immersed boundary with more than one sweep: the
// cases the multi-sweep floor holds (a single settling sphere ran clean at
// a = 6 down to nu 0.0083; its oscillation needs neighbours).
bool multi_sweep_suspension(const SuspensionCase& c) {
  return c.scene == Scene::suspension && c.numerics.coupling.immersed_boundary() &&
         c.numerics.coupling.sweeps > 1;
}

// The smallest viscosity this case may run at with a_over_dx = radius.
double viscosity_floor(const SuspensionCase& c, double radius) {
  const double lattice = smallest_stable_viscosity(radius);
  return multi_sweep_suspension(c) ? std::max(lattice, kSmallestMultiSweepViscosity) : lattice;
}

// Whether nu = 2 a U_inf / Re_inf reaches this case's floor at a_over_dx =
// radius with U_inf within the Mach limit.
bool reaches_floor_within_mach(const SuspensionCase& c, double radius) {
  return 2 * radius * kMaxSettlingVelocity >=
         viscosity_floor(c, radius) * c.physics.reynolds_inf * (1 - 1e-9);
}

// The smallest resolution with shipped calibrations (radius and close pairs
// for both immersed-boundary options) above this case's a at which the floor
// is reached within the Mach limit; 0 where none does.
double finer_resolution_reaching_floor(const SuspensionCase& c) {
  for (double calibrated : {4.0, 6.0, 8.0})
    if (calibrated > c.numerics.radius_cells && reaches_floor_within_mach(c, calibrated))
      return calibrated;
  return 0;
}

// Re_inf = 2 a U_inf / nu: with U_inf at the Mach limit and nu at the
// stability floor the largest Re_inf grows with a. Where this Re_inf is out of
// reach at this a, say so and name the smallest a that reaches it (the paper's
// method held to its own floor there: the standard preset runs such a case at
// a = 6 with one sweep, phi <= 0.2).
std::string beyond_reach(const SuspensionCase& c) {
  const double a = c.numerics.radius_cells;
  const double nu_min = smallest_stable_viscosity(a);
  const double largest_re = 2 * a * kMaxSettlingVelocity / nu_min;
  const bool multi_sweep = multi_sweep_suspension(c);
  const double needed = finer_resolution_reaching_floor(c);
  const std::string finer =
      needed > 0
          ? "raise numerics.a_over_dx to at least " + format_value(needed) +
                (a < 6 && needed <= 6 && !multi_sweep ? " (fidelity standard)" : "") +
                (multi_sweep
                     ? " (with " + std::to_string(c.numerics.coupling.sweeps) +
                           " sweeps nu >= " + format_value(kSmallestMultiSweepViscosity) + " there)"
                     : "")
          : "no calibrated a_over_dx (4, 6, 8) reaches it";
  return "at a_over_dx = " + format_value(a) +
         " the stability floor nu >= " + format_value(nu_min) +
         " and the Mach limit U_inf <= " + format_value(kMaxSettlingVelocity) +
         " allow Re_inf <= 2 a U_inf / nu = " + format_value(largest_re) + "; " + finer +
         " or lower Re_inf";
}
}  // namespace

double smallest_stable_viscosity(double radius_cells) {
  return radius_cells >= 6 ? kSmallestTestedViscosity : 2 * kSmallestTestedViscosity;
}

// The coupling's period-2 oscillation (docs/numerics.md, "Stability floor"):
// a multi-sweep suspension below its floor.
bool multi_sweep_oscillates(const SuspensionCase& c) {
  return multi_sweep_suspension(c) &&
         c.numerics.viscosity < kSmallestMultiSweepViscosity * (1 - 1e-9);
}
// The U_inf that puts this case's viscosity on that floor.
double settling_velocity_at_multi_sweep_floor(const SuspensionCase& c) {
  return kSmallestMultiSweepViscosity * c.physics.reynolds_inf / (2 * c.numerics.radius_cells);
}

bool has_liquid(const SuspensionCase& c) {
  return modules_of(c.scene).liquid;
}

// The largest U_inf: the Mach limit with a liquid, the sphere speed check's
// margin without (suspension_case.hpp).
double largest_settling_velocity(const SuspensionCase& c) {
  return has_liquid(c) ? kMaxSettlingVelocity : kMaxSettlingVelocityWithoutLiquid;
}

std::string largest_settling_velocity_why(const SuspensionCase& c) {
  return has_liquid(c) ? "(Mach limit for settling flows)"
                       : "(a scene without liquid starts Maxwellian with U_inf per component; the "
                         "runs' sphere speed check, 0.3 per step, must stay 6 U_inf away)";
}

std::string stable_why(double a) {
  return "(the smallest viscosity the coupled solver is measured stable at with a_over_dx = " +
         format_value(a) + "; docs/numerics.md)";
}

// The viscosity ceiling (kLargestViscosity), one rule for a viscosity given
// directly (its range, case_fields.cpp) and one implied by Re_inf and a given
// U_inf: nu = 2 a U_inf / Re_inf has no upper bound as Re_inf falls (Re_inf
// 0.01 at draft: nu 56), and such runs blew up with hints that the viscosity
// was too small. Refused before any work, naming the implied viscosity and the
// U_inf that brings it to the ceiling. (Without a U_inf given, the preset's is
// lowered onto the ceiling instead, as it is raised onto the stability floor.)
void check_viscosity_ceiling(const SuspensionCase& c) {
  // (rounding allowed: Re_inf 2.8 with U_inf 0.07 at a = 4 is on the ceiling)
  if (!has_liquid(c) || c.numerics.viscosity <= kLargestViscosity * (1 + 1e-12)) return;
  const double a = c.numerics.radius_cells;
  const double u_works = c.physics.reynolds_inf * kLargestViscosity / (2 * a);
  throw InputError(
      "Re_inf = " + exact_value(c.physics.reynolds_inf) + " with numerics.U_inf = " +
      exact_value(c.derived.settling_velocity) + " and a_over_dx = " + exact_value(a) +
      " implies numerics.viscosity = 2 a U_inf / Re_inf = " + format_value(c.numerics.viscosity) +
      ", above the largest accepted (" + format_value(kLargestViscosity) +
      "; docs/numerics.md, \"Viscosity ceiling\")" +
      "; give numerics.U_inf <= " + format_value(u_works) +
      " (or numerics.viscosity <= " + format_value(kLargestViscosity) + "), or a larger Re_inf");
}

// The Mach cap, for U_inf given, derived from a given viscosity or the preset's.
void check_mach_cap(const SuspensionCase& c) {
  const double largest_u = largest_settling_velocity(c);
  if (c.derived.settling_velocity <= largest_u) return;
  const double a = c.numerics.radius_cells;
  const std::string way_out = c.numerics.viscosity <= smallest_stable_viscosity(a)
                                  ? beyond_reach(c)
                                  : std::string("lower numerics.viscosity");
  throw InputError("numerics: U_inf = Re_inf nu / (2a) = " + exact_value(c.physics.reynolds_inf) +
                   " * " + format_value(c.numerics.viscosity) + " / " + format_value(2 * a) +
                   " = " + format_value(c.derived.settling_velocity) +
                   ": must be <= " + format_value(largest_u) + " " +
                   largest_settling_velocity_why(c) + "; " + way_out);
}

// The stability floor for a viscosity implied by a given U_inf (a given
// viscosity is range-checked when read and the default U_inf is raised to stay
// inside the range, so only an explicit U_inf reaches this).
void check_stability_floor(const SuspensionCase& c) {
  const double a = c.numerics.radius_cells;
  const double nu_min = smallest_stable_viscosity(a);
  if (c.numerics.viscosity >= nu_min) return;
  const double largest_re = 2 * a * kMaxSettlingVelocity / nu_min;
  throw InputError(
      "numerics.U_inf = " + exact_value(c.derived.settling_velocity) + " with Re_inf = " +
      exact_value(c.physics.reynolds_inf) + " and a_over_dx = " + format_value(a) +
      " gives viscosity = U_inf 2a / Re_inf = " + format_value(c.numerics.viscosity) +
      ": must be >= " + format_value(nu_min) + " " + stable_why(a) + "; " +
      (c.physics.reynolds_inf > largest_re
           ? beyond_reach(c)
           : "raise numerics.U_inf to at least " +
                 format_value(nu_min * c.physics.reynolds_inf / (2 * a)) + " or leave it out"));
}

// The coupling's period-2 oscillation (docs/numerics.md): with more than one
// forcing sweep, moving spheres at nu = 0.01 (the a = 4 stand-in of the
// standard box) developed it from t = 26 a/U_inf in all five runs measured,
// with and without the well and with either close-pair model: three blew up,
// two shook 11-42 % of the spheres every step to the end. nu = 0.0133 and
// 0.02 stayed clean; the one-sweep option stayed clean at nu = 0.01. At a = 6
// the same onset (nu 0.0067 stopped by the coupling monitor at phi 0.2 and
// 0.32 after 170-177 a/U_inf, 0.01 at or over its limit at Re_inf 72, 0.0133
// completed 600 a/U_inf at phi 0.32; a = 8 on the floor ran 200 a/U_inf at
// 0.31 of the monitor's limit, phi 0.32, Re_inf 72).
void check_multi_sweep_floor(const SuspensionCase& c, bool viscosity_given,
                             bool settling_velocity_given) {
  if (!multi_sweep_oscillates(c)) return;
  std::vector<std::string> remedies;
  const double a = c.numerics.radius_cells, re = c.physics.reynolds_inf;
  const double nu_floor = kSmallestMultiSweepViscosity;
  const double u_needed = settling_velocity_at_multi_sweep_floor(c);
  // the floor within the Mach limit at this a, or at the smallest finer
  // calibrated one
  const bool reaches_floor_here = reaches_floor_within_mach(c, a);
  const double finer = finer_resolution_reaching_floor(c);
  if (viscosity_given) {
    if (reaches_floor_here)
      remedies.push_back("raise numerics.viscosity to at least " + format_value(nu_floor));
    else if (finer > 0)
      remedies.push_back("raise numerics.viscosity to at least " + format_value(nu_floor) +
                         " with numerics.a_over_dx at least " + format_value(finer) +
                         " (the Mach limit)");
  } else if (u_needed <= kMaxSettlingVelocity) {
    remedies.push_back("raise numerics.U_inf to at least " + format_value(u_needed));
  }
  if (c.physics.phi <= coupling::largest_validated_phi(coupling::kOneSweepScheme))
    remedies.push_back(
        "take the one-sweep option (numerics.immersed_boundary: {\"marker_spacing\": 1, "
        "\"sweeps\": 1})");
  if (!viscosity_given && finer > 0) {
    // a finer lattice reaches the floor at a smaller U_inf; with a given U_inf,
    // the U_inf it then needs
    const double u_there = nu_floor * re / (2 * finer);
    remedies.push_back(
        "raise numerics.a_over_dx to " + format_value(finer) +
        (settling_velocity_given && c.derived.settling_velocity < u_there * (1 - 1e-9)
             ? " with numerics.U_inf at least " + format_value(u_there)
             : ""));
  }
  if (!viscosity_given) {
    // at this a and the given U_inf (else the Mach limit), nu reaches the
    // floor up to this Re_inf
    const double u_top =
        settling_velocity_given ? c.derived.settling_velocity : kMaxSettlingVelocity;
    remedies.push_back("lower Re_inf to at most " + format_value(2 * a * u_top / nu_floor));
  }
  std::string ways;
  for (std::size_t k = 0; k < remedies.size(); ++k)
    ways += (k == 0 ? "" : k + 1 == remedies.size() ? " or " : ", ") + remedies[k];
  throw InputError(
      "numerics: viscosity = " + format_value(c.numerics.viscosity) + " with " +
      std::to_string(c.numerics.coupling.sweeps) +
      " immersed-boundary sweeps at a_over_dx = " + format_value(c.numerics.radius_cells) +
      ": the coupling of moving spheres is measured to oscillate there below "
      "viscosity " +
      format_value(kSmallestMultiSweepViscosity) + " (docs/numerics.md); " + ways);
}

}  // namespace flocsim::cases
