#pragma once
// The GPU immersed boundary behind the interface every coupling offers the
// time loop (engine/coupling/sphere_coupling.hpp), so that a sphere scene's
// step, its coupling monitor, its observables and its checkpoints use it as
// they use the CPU's. It couples the spheres to the GPU lattice it was given;
// the host lattice the time loop passes in is the run's mirror, which it
// neither reads nor writes (engine/run/coupled_step.hpp steps the GPU
// lattice and brings the mirror up to date where something reads it).
#include <memory>
#include <string_view>
#include <utility>
#include <vector>

#include "engine/coupling/sphere_coupling.hpp"
#include "engine/coupling_gpu/gpu_immersed_boundary.hpp"
#include "engine/lattice_gpu/gpu_fluid_lattice.hpp"

namespace flocsim::gpu {

template <class Real>
class GpuSphereCoupling final : public coupling::SphereCoupling<Real> {
 public:
  GpuSphereCoupling(immersed_boundary::ImmersedBoundarySettings settings,
                    GpuFluidLattice<Real>& device)
      : coupling::SphereCoupling<Real>(settings.scheme), device_(device), gpu_(settings) {}

  std::string_view stage_name() const override { return "immersed_boundary"; }

  void apply(lattice::ForcedLiquid<Real>& /*mirror*/, const spheres::SphereSet& spheres) override {
    gpu_.apply(device_, spheres);
    this->force_ = gpu_.force();
    this->torque_ = gpu_.torque();
    this->record_internal_momenta(gpu_.inside().momentum(), gpu_.inside().angular_momentum());
  }
  void remove(lattice::ForcedLiquid<Real>& /*mirror*/) override { gpu_.remove(device_); }

  std::vector<coupling::NamedArray> memory() const override { return gpu_.memory(); }
  void restore_memory(const std::vector<coupling::NamedArray>& memory) override {
    gpu_.restore_memory(memory);
  }

 private:
  GpuFluidLattice<Real>& device_;
  GpuImmersedBoundary<Real> gpu_;
};

}  // namespace flocsim::gpu
