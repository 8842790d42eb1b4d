#pragma once
// The liquid on a GPU: the D3Q19 TRT lattice of fluid_lattice.hpp with its
// populations in device memory, stepped by the same kernel body
// (engine/lattice/aa_cell.hpp, one thread per cell) in the same storage
// layout, so a state moves between the two by plain copies: upload() from a
// host FluidLattice and download() back, bit for bit. The host lattice is the
// run's mirror: checkpoints, snapshots and observables read it after a
// download, and a checkpoint written from a GPU run resumes on either device.
//
// Reductions (mass, momentum) sum per cell in double, per block in a fixed
// tree, and the blocks on the host in order: the same state gives the same
// sum on every run (no atomics).
//
// Declared without CUDA headers, so host code compiled by the C++ compiler
// uses it; a build without CUDA has the class but its constructor throws with
// the reason (gpu_runtime.hpp).
#include <cstddef>
#include <memory>

#include "engine/lattice/aa_cell.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/lattice_gpu/gpu_runtime.hpp"

namespace flocsim::gpu {

// The per-cell force density in device memory, one array per component,
// x fastest (the host field's layout).
template <class Real>
struct DeviceForceField {
  Real* component[3] = {nullptr, nullptr, nullptr};
};

// Partially saturated cells on the device (engine/coupling_gpu): per cell,
// x fastest, the summed coverage eps and V = sum eps_k u_k that the next
// step's collision blends with (zero where no sphere covers the cell), and
// the density and momentum density rho u that a covered cell's collision saw
// (written by the step where eps > 0 only).
template <class Real>
struct DeviceCoverage {
  Real* eps = nullptr;
  Real* solid_velocity[3] = {nullptr, nullptr, nullptr};
  Real* density = nullptr;
  Real* momentum[3] = {nullptr, nullptr, nullptr};
};

template <class Real>
class GpuFluidLattice {
 public:
  // On the first usable GPU (use_first_gpu; CUDA_VISIBLE_DEVICES chooses which
  // are seen), made current for this thread; throws std::runtime_error when
  // no GPU can be used, with the reason.
  GpuFluidLattice(lattice::Extent extent, lattice::Relaxation relaxation);
  ~GpuFluidLattice();
  GpuFluidLattice(const GpuFluidLattice&) = delete;
  GpuFluidLattice& operator=(const GpuFluidLattice&) = delete;

  const lattice::Extent& extent() const { return extent_; }
  long time_step() const { return time_step_; }
  void set_body_force(lattice::Vector3 f) { body_force_ = f; }
  lattice::Vector3 body_force() const { return body_force_; }

  // The whole state of `host` (populations, time step, body force and, when
  // it has one, its per-cell force field) onto the device; same extent.
  void upload(const lattice::FluidLattice<Real>& host);
  // The populations and the time step back into `host` (same extent); not the
  // body force or the force field, which the host keeps as it set them.
  void download(lattice::FluidLattice<Real>& host) const;
  // The per-cell force field of the next steps, from the host (x fastest).
  void upload_force_field(const lattice::ForceFieldView<const Real>& field);
  // The device's force field into `host`'s (enabled there if needed; zero
  // where the device has none, unless the host has none either): what the
  // host's observables then read.
  void download_force_field(lattice::FluidLattice<Real>& host) const;

  // For the couplings that work on the device (engine/coupling_gpu): the
  // populations where they are now (read with aa_load_cell and
  // next_step_is_even()), and the force field of the next step in device
  // memory, allocated and zeroed on first use. Neither is valid on the host.
  lattice::AaSlots<Real> device_slots() const;
  bool next_step_is_even() const { return time_step_ % 2 == 0; }
  DeviceForceField<Real> device_force_field();
  // For reading (the liquid averages, engine/observables_gpu): the device
  // force field where there is one, else null pointers; allocates nothing.
  DeviceForceField<const Real> device_force_field_if_set() const;
  // Partially saturated cells: the coverage arrays (8 numbers per cell,
  // allocated and zeroed on first use; whoever fills eps and V leaves them
  // zero again after the step), and the request that the next step blend
  // the collision of every cell with eps > 0 (partially_saturated_collision.hpp)
  // and leave there the density and momentum it saw. That one step only.
  DeviceCoverage<Real> device_coverage();
  void cover_next_step() { cover_next_ = true; }
  void cancel_cover() { cover_next_ = false; }
  bool cover_pending() const { return cover_next_; }

  // One lattice-Boltzmann step: collide with the current force, stream.
  void step();
  // Waits for the queued steps (timing).
  void synchronize() const;

  double total_mass() const;
  lattice::Vector3 total_momentum() const;
  std::size_t bytes_per_cell_update() const;
  // The GPU it runs on.
  const GpuDevice& gpu() const;

 private:
  struct Device;  // device memory, defined in the .cu
  lattice::Extent extent_;
  lattice::Relaxation relaxation_;
  lattice::Vector3 body_force_;
  long time_step_ = 0;
  bool cover_next_ = false;
  std::unique_ptr<Device> device_;
};

extern template class GpuFluidLattice<float>;
extern template class GpuFluidLattice<double>;

}  // namespace flocsim::gpu
