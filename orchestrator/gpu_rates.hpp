#pragma once
// A GPU's rate for `flocsim sweep plan --gpu-rate FILE`: the figures the GPU
// benchmarks wrote on a GPU machine (bench_fluid_gpu --json, bench_coupling_gpu
// --json; scripts/device-check.sh writes both), turned into seconds per step
// of a planned configuration, so that a plan says what a sweep would cost on
// that GPU without one here.
//
// The model, per configuration, in lattice updates and marker work:
//   fluid scene:   cells / (the fluid benchmark's MLUPS, same precision and
//                  forcing);
//   sphere scene:  cells / (the coupled benchmark's fluid MLUPS) + its
//                  coupling milliseconds (the coupled step's time less the
//                  fluid's) scaled by the coupling's work against the
//                  benchmark's, same precision and scheme. The work is N x
//                  markers per sphere for the immersed boundary, N x the
//                  cells of the cube each sphere covers for partially
//                  saturated cells.
// Both parts scale linearly on a GPU once a box has millions of cells and the
// spheres fill its multiprocessors many times over (the paper's case: 6 M
// cells, 1320 blocks of 256 threads on 132 multiprocessors); far smaller
// cases are estimated optimistically, which the plan says.
#include <optional>
#include <string>
#include <vector>

#include "engine/case/case_file.hpp"
#include "engine/run/case_cost.hpp"

namespace flocsim::orchestrator {

struct GpuFluidRate {
  bool single_precision = true;
  bool force_field = false;
  double mlups = 0;
};

struct GpuCouplingRate {
  bool single_precision = true;
  std::string option;  // coupling::Scheme::describe()
  double fluid_mlups = 0;
  double coupling_ms = 0;  // the coupled step's milliseconds less the fluid's
  double work = 0;         // spheres x (markers or covered cube cells) per sphere
};

struct GpuRates {
  std::string file, gpu;
  std::vector<GpuFluidRate> fluid;
  std::vector<GpuCouplingRate> coupling;

  // Seconds per step of `c` on this GPU; empty with `why` set where the file
  // has no figure for it (another precision or coupling scheme).
  std::optional<double> step_s(const cases::ParsedCase& c, const run::CaseSize& size,
                               std::string& why) const;
};

// Reads one or more benchmark files (their results merged; the GPU names must
// agree). Throws input::InputError naming the file and the field when a file
// cannot be read, is not a GPU benchmark's output, or holds a figure that is
// not a positive finite number.
GpuRates read_gpu_rates(const std::vector<std::string>& files);

}  // namespace flocsim::orchestrator
