#include "engine/coupling_schemes/make_coupling.hpp"

#include "engine/immersed_boundary/immersed_boundary.hpp"
#include "engine/partially_saturated/partially_saturated_cells.hpp"

namespace flocsim::coupling {

template <class Real>
std::unique_ptr<SphereCoupling<Real>> make_coupling(const Scheme& scheme, double input_radius) {
  switch (scheme.method) {
    case Method::immersed_boundary:
      return std::make_unique<immersed_boundary::ImmersedBoundary<Real>>(
          immersed_boundary::ImmersedBoundarySettings{input_radius, scheme, false});
    case Method::partially_saturated:
      return std::make_unique<partially_saturated::PartiallySaturatedCells<Real>>(input_radius);
  }
  throw std::invalid_argument("coupling: " + scheme.describe() + " is not built in");
}

template std::unique_ptr<SphereCoupling<float>> make_coupling<float>(const Scheme&, double);
template std::unique_ptr<SphereCoupling<double>> make_coupling<double>(const Scheme&, double);

}  // namespace flocsim::coupling
