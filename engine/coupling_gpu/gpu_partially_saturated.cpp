#include "engine/coupling_gpu/gpu_partially_saturated.hpp"

#include <stdexcept>
#include <string>

#include "engine/coupling_gpu/covered_cell_kernels.hpp"
#include "engine/partially_saturated/covered_cell_body.hpp"

namespace flocsim::gpu {

using spheres::Vec3;

std::vector<double> covering_spheres(const spheres::SphereSet& spheres, const lattice::Extent& e,
                                     double input_radius) {
  const std::size_t n = spheres.size();
  std::vector<double> out(kCoveringNumbers * n);
  for (std::size_t s = 0; s < n; ++s) {
    const double p[3] = {spheres.position[s][0], spheres.position[s][1], spheres.position[s][2]};
    const double u[3] = {spheres.velocity[s][0], spheres.velocity[s][1], spheres.velocity[s][2]};
    const double w[3] = {spheres.angular_velocity[s][0], spheres.angular_velocity[s][1],
                         spheres.angular_velocity[s][2]};
    const partially_saturated::CoveringSphere c =
        partially_saturated::covering_sphere(p, u, w, e, input_radius);
    double* o = &out[kCoveringNumbers * s];
    for (int d = 0; d < 3; ++d) {
      o[d] = c.centre[d];
      o[3 + d] = c.lo[d];
    }
    for (int q = 0; q < 6; ++q) o[6 + q] = c.motion[q];
  }
  return out;
}

template <class Real>
GpuPartiallySaturatedCells<Real>::GpuPartiallySaturatedCells(double input_radius,
                                                             GpuFluidLattice<Real>& device)
    : coupling::SphereCoupling<Real>(coupling::kPartiallySaturatedScheme),
      input_radius_(input_radius),
      device_(device) {
  if (!(input_radius >= 1.0 && input_radius <= 2000.0))  // the CPU coupling's range
    throw std::invalid_argument("partially saturated cells: input_radius = " +
                                std::to_string(input_radius) + ": must be in [1, 2000] dx");
  kernels_ = std::make_unique<CoveredCellKernels<Real>>(input_radius);
}

template <class Real>
GpuPartiallySaturatedCells<Real>::~GpuPartiallySaturatedCells() = default;

template <class Real>
void GpuPartiallySaturatedCells<Real>::apply(lattice::ForcedLiquid<Real>& /*mirror*/,
                                             const spheres::SphereSet& spheres) {
  partially_saturated::check_box_length(device_.extent(), input_radius_);
  spheres_ = covering_spheres(spheres, device_.extent(), input_radius_);
  kernels_->cover(device_, spheres_);
}

template <class Real>
void GpuPartiallySaturatedCells<Real>::after_liquid_step(
    const lattice::ForcedLiquid<Real>& /*mirror*/, const spheres::SphereSet& spheres) {
  const std::size_t n = spheres.size();
  if (spheres_.size() != kCoveringNumbers * n)
    throw std::logic_error("GPU partially saturated cells: after_liquid_step() without apply()");
  if (device_.cover_pending())
    throw std::logic_error(
        "GPU partially saturated cells: after_liquid_step() before the liquid's step");
  kernels_->exchange(device_, exchange_);
  // the spheres give up what their solid operator gave the liquid
  this->force_.resize(n);
  this->torque_.resize(n);
  std::vector<Vec3> momentum(n), angular(n);
  for (std::size_t s = 0; s < n; ++s) {
    const double* e = &exchange_[kExchangeNumbers * s];
    this->force_[s] = -Vec3(e[0], e[1], e[2]);
    this->torque_[s] = -Vec3(e[3], e[4], e[5]);
    momentum[s] = Vec3(e[6], e[7], e[8]);
    angular[s] = Vec3(e[9], e[10], e[11]);
  }
  this->record_internal_momenta(std::move(momentum), std::move(angular));
}

template <class Real>
void GpuPartiallySaturatedCells<Real>::remove(lattice::ForcedLiquid<Real>& /*mirror*/) {
  kernels_->withdraw(device_);
}

template class GpuPartiallySaturatedCells<float>;
template class GpuPartiallySaturatedCells<double>;

}  // namespace flocsim::gpu
