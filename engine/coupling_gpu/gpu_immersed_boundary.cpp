#include "engine/coupling_gpu/gpu_immersed_boundary.hpp"

#include <stdexcept>
#include <string>

#include "engine/coupling_gpu/marker_kernels.hpp"
#include "engine/immersed_boundary/sphere_markers.hpp"

namespace flocsim::gpu {

using spheres::Vec3;

MarkerSetup marker_setup(const immersed_boundary::ImmersedBoundarySettings& settings) {
  const coupling::Scheme& scheme = settings.scheme;
  MarkerSetup setup;
  setup.markers = immersed_boundary::marker_count(settings.input_radius, scheme.marker_spacing);
  for (const Vec3& u : immersed_boundary::fibonacci_sphere(setup.markers))
    for (int d = 0; d < 3; ++d) setup.offsets.push_back(settings.input_radius * u[d]);
  setup.kernel_width = coupling::kernel_width(scheme.kernel);
  setup.box = immersed_boundary::sphere_box_edge(settings.input_radius);
  setup.input_radius = settings.input_radius;
  setup.marker_volume = immersed_boundary::marker_volume(settings.input_radius, setup.markers);
  setup.sweeps = scheme.sweeps;
  setup.control = scheme.control();
  setup.integral_gain = scheme.gains.integral;
  setup.proportional_gain = scheme.gains.proportional;
  return setup;
}

template <class Real>
GpuImmersedBoundary<Real>::GpuImmersedBoundary(immersed_boundary::ImmersedBoundarySettings settings)
    : settings_(settings) {
  immersed_boundary::check_settings(settings);
  if (settings.measure_slip)
    throw std::invalid_argument(
        "GPU immersed boundary: measure_slip is a diagnostic of the CPU coupling only (run the "
        "case on the CPU to measure the slip)");
  MarkerSetup setup = marker_setup(settings);
  markers_ = setup.markers;
  marker_volume_ = setup.marker_volume;
  kernels_ = std::make_unique<MarkerKernels<Real>>(std::move(setup));
}

template <class Real>
GpuImmersedBoundary<Real>::~GpuImmersedBoundary() = default;

template <class Real>
void GpuImmersedBoundary<Real>::apply(GpuFluidLattice<Real>& liquid,
                                      const spheres::SphereSet& spheres) {
  immersed_boundary::check_box_fits(liquid.extent(), settings_.input_radius);
  const std::size_t n = spheres.size();
  poses_.resize(kPoseNumbers * n);
  for (std::size_t s = 0; s < n; ++s)
    for (int d = 0; d < 3; ++d) {
      poses_[kPoseNumbers * s + d] = spheres.position[s][d];
      poses_[kPoseNumbers * s + 3 + d] = spheres.velocity[s][d];
      poses_[kPoseNumbers * s + 6 + d] = spheres.angular_velocity[s][d];
    }
  kernels_->apply(liquid, poses_, loads_);
  force_.resize(n);
  torque_.resize(n);
  std::vector<Vec3> momentum(n), angular(n);
  for (std::size_t s = 0; s < n; ++s) {
    const double* l = &loads_[kLoadNumbers * s];
    force_[s] = Vec3(l[0], l[1], l[2]);
    torque_[s] = Vec3(l[3], l[4], l[5]);
    momentum[s] = Vec3(l[6], l[7], l[8]);
    angular[s] = Vec3(l[9], l[10], l[11]);
  }
  inside_.record(std::move(momentum), std::move(angular));
}

template <class Real>
void GpuImmersedBoundary<Real>::remove(GpuFluidLattice<Real>& liquid) {
  kernels_->clear(liquid);
}

template <class Real>
std::vector<coupling::NamedArray> GpuImmersedBoundary<Real>::memory() const {
  if (!settings_.scheme.control()) return {};
  return {{"marker_force", immersed_boundary::lanes_to_vectors(kernels_->marker_force())},
          {"marker_slip", immersed_boundary::lanes_to_vectors(kernels_->marker_slip())}};
}

template <class Real>
void GpuImmersedBoundary<Real>::restore_memory(const std::vector<coupling::NamedArray>& memory) {
  if (!settings_.scheme.control()) return;
  std::vector<Real> force, slip;
  for (const auto& a : memory) {
    if (a.values.size() % (3 * static_cast<std::size_t>(markers_)) != 0)
      throw std::invalid_argument("GPU immersed boundary: checkpointed " + a.name + " holds " +
                                  std::to_string(a.values.size()) +
                                  " numbers, not 3 per marker of whole spheres (" +
                                  std::to_string(markers_) + " markers each)");
    if (a.name == "marker_force") force = immersed_boundary::vectors_to_lanes<Real>(a.values);
    if (a.name == "marker_slip") slip = immersed_boundary::vectors_to_lanes<Real>(a.values);
  }
  kernels_->restore(force, slip);
}

template class GpuImmersedBoundary<float>;
template class GpuImmersedBoundary<double>;

}  // namespace flocsim::gpu
