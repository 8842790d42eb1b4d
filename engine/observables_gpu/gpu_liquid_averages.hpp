#pragma once
// The liquid averages (engine/observables/liquid_averages.hpp) of a lattice
// on the GPU, computed there: a sphere run's sample then moves a few kB over
// the bus (the sphere centres up, one partial sum per block down) instead of
// downloading the lattice (populations and force field, ~0.5 GB at the
// paper's 288 x 144 x 144 in float).
//
// Two launches per call, both running kernel bodies of
// engine/observables/liquid_average_body.hpp:
//   mark    the solid mask (1 byte per cell, device memory) from the sphere
//           centres, one block per sphere over the cube mark_solid_cells
//           walks, so no mask crosses the bus (uploading the host's
//           mark_solid_cells mask instead would cost its marking on the host
//           and 1 byte per cell, 6 MB at the paper's box, per sample);
//   sum     liquid_thread_sums per thread over a grid-stride of cells, a
//           fixed tree per block into one LiquidSums per block; the host
//           adds the blocks in block order.
// Every sum has a fixed order (no atomics): on a given GPU (the grid is
// sized to it) the same state gives the same averages on every run, whatever
// the scheduling. They differ from the CPU's
// (whose OpenMP threads add rows in another order) at round-off only.
//
// Declared without CUDA headers; a build without CUDA has the class but its
// constructor throws with the reason (gpu_runtime.hpp), like the lattice's.
#include <memory>
#include <vector>

#include "engine/lattice_gpu/gpu_fluid_lattice.hpp"
#include "engine/observables/liquid_average_body.hpp"

namespace flocsim::gpu {

// Threads per block of both launches (a power of two: the block's tree).
constexpr int kLiquidSumThreads = 256;

template <class Real>
class GpuLiquidAverages {
 public:
  // On the current GPU (the lattice's); throws std::runtime_error without one.
  GpuLiquidAverages();
  ~GpuLiquidAverages();
  GpuLiquidAverages(const GpuLiquidAverages&) = delete;
  GpuLiquidAverages& operator=(const GpuLiquidAverages&) = delete;

  // The sums over `liquid`'s cells as it stands (its next step's parity, its
  // body force and device force field), with the cells within `radius` of a
  // centre (x y z per sphere, periodic images included) solid; the caller
  // turns them into averages (observables::averages_from_sums). Waits for
  // the GPU.
  observables::LiquidSums sums(const GpuFluidLattice<Real>& liquid,
                               const std::vector<double>& centres, double radius);

  // The grid of the sum launch on this GPU (blocks of kLiquidSumThreads).
  int blocks() const;

 private:
  struct Device;  // device memory, defined in the .cu
  std::unique_ptr<Device> device_;
};

extern template class GpuLiquidAverages<float>;
extern template class GpuLiquidAverages<double>;

}  // namespace flocsim::gpu
