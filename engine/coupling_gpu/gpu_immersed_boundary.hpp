#pragma once
// The immersed boundary on the GPU: the method of
// engine/immersed_boundary/immersed_boundary.hpp (direct forcing with its
// sweeps, or control forcing; Roma's kernel or the linear hat) on a
// GpuFluidLattice, its markers on the device, rebuilt there every step from
// the sphere poses: only 9 numbers per sphere go to the GPU (position,
// velocity, angular velocity) and 12 come back (force, torque, the inside
// liquid's momentum and angular momentum), through page-locked buffers.
// Events, the square well, lubrication and the sphere equations stay on the
// CPU, serial and exact.
//
// The per-marker and per-cell work is the kernel bodies of
// engine/immersed_boundary/marker_body.hpp, which the test suite holds to the
// CPU's ImmersedBoundary; marker_kernels.cu only maps them to threads. This
// class owns the rest: the settings' checks (the CPU's), the markers, the
// loads as the sphere equations take them, and control forcing's carried
// state for checkpoints, in the CPU coupling's names and layout, so that a
// checkpoint moves between the devices.
//
// Not offered on the GPU: the slip measurement (a diagnostic of the CPU
// path). The GPU coupling owns the liquid's per-cell force field: apply()
// replaces it.
#include <memory>
#include <vector>

#include "engine/coupling/sphere_coupling.hpp"
#include "engine/immersed_boundary/immersed_boundary.hpp"
#include "engine/lattice_gpu/gpu_fluid_lattice.hpp"
#include "engine/spheres/sphere_set.hpp"

namespace flocsim::gpu {

template <class Real>
class MarkerKernels;
struct MarkerSetup;

// The device side's description of the markers and the method for
// `settings` (after check_settings): what the GPU runs, and what the test
// suite's serial launcher runs on the CPU.
MarkerSetup marker_setup(const immersed_boundary::ImmersedBoundarySettings& settings);

template <class Real>
class GpuImmersedBoundary {
 public:
  // Throws std::invalid_argument for settings the CPU coupling refuses too,
  // or for measure_slip; std::runtime_error where no GPU can be used.
  explicit GpuImmersedBoundary(immersed_boundary::ImmersedBoundarySettings settings);
  ~GpuImmersedBoundary();
  GpuImmersedBoundary(const GpuImmersedBoundary&) = delete;
  GpuImmersedBoundary& operator=(const GpuImmersedBoundary&) = delete;

  const immersed_boundary::ImmersedBoundarySettings& settings() const { return settings_; }
  int markers_per_sphere() const { return markers_; }
  double marker_volume() const { return marker_volume_; }

  // The liquid's force field for its next step, for the spheres where they
  // are and as they move now, and this step's loads. Call right before
  // liquid.step(); spheres must not move in between.
  void apply(GpuFluidLattice<Real>& liquid, const spheres::SphereSet& spheres);
  // Zeroes the force field apply() set.
  void remove(GpuFluidLattice<Real>& liquid);

  // This step's loads, one entry per sphere, as the CPU coupling gives them.
  const std::vector<spheres::Vec3>& force() const { return force_; }
  const std::vector<spheres::Vec3>& torque() const { return torque_; }
  const coupling::InsideMomenta& inside() const { return inside_; }
  spheres::HydrodynamicLoads loads() const {
    return {force_, torque_, inside_.momentum_change(), inside_.angular_momentum_change()};
  }
  void set_internal_momenta(std::vector<spheres::Vec3> momentum,
                            std::vector<spheres::Vec3> angular_momentum) {
    inside_.restore(std::move(momentum), std::move(angular_momentum));
  }

  // Control forcing's carried state (marker_force, marker_slip: x y z per
  // marker), as ImmersedBoundary::memory() names and orders it.
  std::vector<coupling::NamedArray> memory() const;
  void restore_memory(const std::vector<coupling::NamedArray>& memory);

 private:
  immersed_boundary::ImmersedBoundarySettings settings_;
  int markers_ = 0;
  double marker_volume_ = 0;
  std::unique_ptr<MarkerKernels<Real>> kernels_;
  std::vector<double> poses_, loads_;
  std::vector<spheres::Vec3> force_, torque_;
  coupling::InsideMomenta inside_;
};

extern template class GpuImmersedBoundary<float>;
extern template class GpuImmersedBoundary<double>;

}  // namespace flocsim::gpu
