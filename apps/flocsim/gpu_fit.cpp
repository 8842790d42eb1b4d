#include "apps/flocsim/gpu_fit.hpp"

#include <cstdio>

#include "engine/lattice_gpu/gpu_runtime.hpp"

namespace flocsim::app {

std::string gpu_refusal(const cases::ParsedCase& parsed) {
  const bool on_gpu = parsed.fluid_scene ? parsed.fluid.device == cases::Device::cuda
                                         : parsed.spheres.device == cases::Device::cuda;
  if (!on_gpu) return "";
  const gpu::GpuQuery q = gpu::query_gpus();
  if (q.devices.empty())
    return "device = \"cuda\": " + q.why_none + "; run on the CPU with --device cpu";
  // the populations must fit the GPU's free memory (the host mirror is
  // checked with the case, against this machine's); the lattice takes its
  // memory before any output too, should another process take it meanwhile
  // (a sphere scene adds the 3-component force field the immersed boundary
  // writes, or the 8 numbers per cell of partially saturated cells, and the
  // byte per cell of the liquid averages' solid mask)
  const double cells = static_cast<double>(parsed.fluid_scene ? parsed.fluid.size.cells()
                                                              : parsed.spheres.derived.box.cells());
  const bool single = parsed.fluid_scene
                          ? parsed.fluid.precision == cases::Precision::single_precision
                          : parsed.spheres.numerics.single_precision;
  const double per_cell = parsed.fluid_scene                                     ? 19.0
                          : parsed.spheres.numerics.coupling.immersed_boundary() ? 22.0
                                                                                 : 27.0;
  const double bytes = per_cell * cells * (single ? 4 : 8) + (parsed.fluid_scene ? 0 : cells);
  const double available = 0.9 * q.devices.front().free_gib * (1u << 30);
  if (bytes <= available) return "";
  char text[400];
  std::snprintf(text, sizeof text,
                "the lattice takes %.1f GiB on the GPU, more than 90 %% of the %.1f GiB free "
                "there (%s); use a smaller box, float precision, or --device cpu",
                bytes / (1u << 30), q.devices.front().free_gib, q.devices.front().name.c_str());
  return text;
}

}  // namespace flocsim::app
