#pragma once
// The device side of the GPU's immersed boundary (gpu_immersed_boundary.hpp):
// device buffers and the launch of one thread block per sphere that runs the
// kernel bodies of engine/immersed_boundary/marker_body.hpp. Plain numbers in
// and out (no Eigen, no CUDA headers), so that the C++ side stays with the
// C++ compiler and this header compiles without CUDA.
#include <memory>
#include <vector>

#include "engine/lattice_gpu/gpu_fluid_lattice.hpp"

namespace flocsim::gpu {

struct MarkerSetup {
  int markers = 0;              // per sphere
  std::vector<double> offsets;  // a_g times each marker's unit direction, x y z per marker
  int kernel_width = 3;         // 3: Roma, 2: linear hat
  int box = 0;                  // edge of the cube of cells around a sphere
  double input_radius = 0;      // a_g
  double marker_volume = 0;     // dV
  int sweeps = 1;               // direct forcing
  bool control = false;         // control forcing instead (one correction per step)
  double integral_gain = 0, proportional_gain = 0;
};

// Per sphere, in: position, velocity, angular velocity (9 numbers); out:
// force and torque of the liquid on it, momentum and angular momentum of the
// liquid inside (12 numbers).
constexpr int kPoseNumbers = 9;
constexpr int kLoadNumbers = 12;

template <class Real>
class MarkerKernels {
 public:
  explicit MarkerKernels(MarkerSetup setup);
  ~MarkerKernels();
  MarkerKernels(const MarkerKernels&) = delete;
  MarkerKernels& operator=(const MarkerKernels&) = delete;

  // Replaces the liquid's device force field by the spheres' forces for its
  // next step; `loads` receives kLoadNumbers per sphere. Waits for the GPU.
  void apply(GpuFluidLattice<Real>& liquid, const std::vector<double>& poses,
             std::vector<double>& loads);
  // Zeroes the liquid's device force field.
  void clear(GpuFluidLattice<Real>& liquid);

  // Control forcing's carried state: per sphere and marker (0, x, y, z), the
  // CPU coupling's layout; empty before the first apply().
  std::vector<Real> marker_force() const;
  std::vector<Real> marker_slip() const;
  void restore(const std::vector<Real>& force, const std::vector<Real>& slip);

 private:
  struct Device;  // defined in marker_kernels.cu
  MarkerSetup setup_;
  std::unique_ptr<Device> device_;
};

extern template class MarkerKernels<float>;
extern template class MarkerKernels<double>;

}  // namespace flocsim::gpu
