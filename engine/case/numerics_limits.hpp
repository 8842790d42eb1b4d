// The numerical limits a sphere case must respect, each measured
// (docs/numerics.md): the Mach limit on U_inf, the coupled solver's stability
// floor on the viscosity, the higher floor of the multi-sweep immersed boundary
// in suspensions, and the viscosity ceiling. Each check refuses a case before
// any work with what would work; the readers in suspension_case.cpp move the
// preset's U_inf onto these limits where the case leaves it to them.
#pragma once

#include <string>

#include "engine/case/suspension_case.hpp"

namespace flocsim::cases {

// The scene has a liquid (lattice): the Mach limit and the floors apply.
bool has_liquid(const SuspensionCase& c);

// The largest U_inf: the Mach limit with a liquid, the sphere speed check's
// margin without; and the reason, for messages.
double largest_settling_velocity(const SuspensionCase& c);
std::string largest_settling_velocity_why(const SuspensionCase& c);

// Why the stability floor at this a_over_dx, for messages.
std::string stable_why(double a);

// A suspension with more than one immersed-boundary sweep below its floor
// (kSmallestMultiSweepViscosity), and the U_inf that puts it on the floor.
bool multi_sweep_oscillates(const SuspensionCase& c);
double settling_velocity_at_multi_sweep_floor(const SuspensionCase& c);

// The refusals, each naming what would work; the multi-sweep floor's remedies
// depend on whether the case gave its viscosity or its U_inf.
void check_viscosity_ceiling(const SuspensionCase& c);
void check_mach_cap(const SuspensionCase& c);
void check_stability_floor(const SuspensionCase& c);
void check_multi_sweep_floor(const SuspensionCase& c, bool viscosity_given,
                             bool settling_velocity_given);

}  // namespace flocsim::cases
