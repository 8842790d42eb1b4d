#pragma once
// The coupling schemes by name: one call builds the scheme a case chose
// (engine/coupling/scheme.hpp) behind the one interface the time loop, the
// calibrations and the benchmarks use (engine/coupling/sphere_coupling.hpp).
#include <memory>

#include "engine/coupling/scheme.hpp"
#include "engine/coupling/sphere_coupling.hpp"

namespace flocsim::coupling {

// `input_radius`: the geometric radius a_g the scheme puts its boundary on
// (markers, or the spheres whose cell overlaps give the solid fractions),
// calibrated so that the hydrodynamic radius is the case's a.
template <class Real>
std::unique_ptr<SphereCoupling<Real>> make_coupling(const Scheme& scheme, double input_radius);

extern template std::unique_ptr<SphereCoupling<float>> make_coupling<float>(const Scheme&, double);
extern template std::unique_ptr<SphereCoupling<double>> make_coupling<double>(const Scheme&,
                                                                              double);

}  // namespace flocsim::coupling
