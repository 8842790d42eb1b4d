// GPU fluid-kernel benchmark: MLUPS of the GPU lattice's D3Q19 AA-pattern TRT
// step (engine/lattice_gpu) as a fraction of the device's copy bandwidth
// measured in the same run, paired repetition by repetition as bench_fluid
// does on the CPU: roofline MLUPS = copy bandwidth / bytes per cell update
// (2 x 19 x sizeof(Real), plus 3 x sizeof(Real) with the per-cell force field).
// The target (issue: the GPU back-end): at least 75 % of the roofline;
// FluidX3D reaches 80 % on an H100 SXM.
// Usage: bench_fluid_gpu [--sizes NX,NY,NZ;...] [--reps R] [--steps S] [--json FILE]
// Exit: 0 measured; 77 no usable GPU (the reason printed), 2 bad arguments.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "engine/lattice/fluid_lattice.hpp"
#include "engine/lattice_gpu/gpu_fluid_lattice.hpp"
#include "engine/lattice_gpu/gpu_runtime.hpp"

using namespace flocsim;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

template <class Real>
nlohmann::json time_gpu_kernel(lattice::Extent e, bool force_field, int steps, int reps) {
  lattice::FluidLattice<Real> host(e, {0.01, 0.25});
  host.set_body_force({1e-6, 0, 0});
  if (force_field) host.enable_force_field();
  const double k = 2 * M_PI / e.nx;
  host.initialise_equilibrium([&](int x, int, int) {
    return lattice::Macroscopic{1.0, {0, 0.02 * std::sin(k * x), 0}};
  });
  gpu::GpuFluidLattice<Real> fluid(e, {0.01, 0.25});
  fluid.upload(host);
  for (int s = 0; s < 2; ++s) fluid.step();  // warm-up: one even and one odd step
  fluid.synchronize();
  const double bytes = static_cast<double>(fluid.bytes_per_cell_update());
  // the copy the roofline is taken from moves as many bytes as one step
  const std::size_t copy_bytes = static_cast<std::size_t>(bytes / 2 * e.cells());
  std::vector<double> rates, bandwidths, fractions;
  for (int r = 0; r < reps; ++r) {
    const double bandwidth = gpu::measure_copy_bandwidth_gbs(copy_bytes, 3) * 1e9;
    const auto t0 = std::chrono::steady_clock::now();
    for (int s = 0; s < steps; ++s) fluid.step();
    fluid.synchronize();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double mlups = static_cast<double>(e.cells()) * steps / seconds / 1e6;
    rates.push_back(mlups);
    bandwidths.push_back(bandwidth);
    fractions.push_back(mlups * 1e6 * bytes / bandwidth);
  }
  if (!std::isfinite(fluid.total_mass()))
    throw std::runtime_error("the benchmark's lattice blew up: its figures are not valid");
  return {{"size", {e.nx, e.ny, e.nz}},
          {"precision", sizeof(Real) == 8 ? "double" : "float"},
          {"force_field", force_field},
          {"MLUPS", median(rates)},
          {"copy_bandwidth_GBs", median(bandwidths) / 1e9},
          {"fraction_of_copy_roofline", median(fractions)},
          {"bytes_per_cell_update", bytes},
          {"reps", reps},
          {"steps", steps}};
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<lattice::Extent> sizes = {{288, 144, 144}, {256, 256, 256}};
  int reps = 5, steps = 100;
  std::string json_file;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (a + 1 >= argc) {
      std::fprintf(stderr, "bench_fluid_gpu: %s needs a value\n", arg.c_str());
      return 2;
    }
    const std::string value = argv[++a];
    if (arg == "--reps") {
      reps = std::stoi(value);
    } else if (arg == "--steps") {
      steps = std::stoi(value);
    } else if (arg == "--json") {
      json_file = value;
    } else if (arg == "--sizes") {  // "288,144,144;256,256,256"
      sizes.clear();
      std::stringstream list(value);
      for (std::string one; std::getline(list, one, ';');) {
        lattice::Extent e;
        if (std::sscanf(one.c_str(), "%d,%d,%d", &e.nx, &e.ny, &e.nz) != 3 || e.nx < 1 ||
            e.ny < 1 || e.nz < 1) {
          std::fprintf(stderr, "bench_fluid_gpu: --sizes: \"%s\" is not NX,NY,NZ\n", one.c_str());
          return 2;
        }
        sizes.push_back(e);
      }
    } else {
      std::fprintf(stderr,
                   "usage: bench_fluid_gpu [--sizes NX,NY,NZ;...] [--reps R] [--steps S] "
                   "[--json FILE]\n");
      return 2;
    }
  }
  if (reps < 1 || steps < 2) {
    std::fprintf(stderr, "bench_fluid_gpu: --reps must be >= 1 and --steps >= 2\n");
    return 2;
  }
  const gpu::GpuQuery q = gpu::query_gpus();
  if (q.devices.empty()) {
    std::printf("no GPU: %s\n", q.why_none.c_str());
    return 77;
  }
  const gpu::GpuDevice& d = q.devices.front();
  std::printf(
      "GPU %s (%.0f GiB, compute capability %d.%d); medians of %d repetitions of %d steps\n",
      d.name.c_str(), d.memory_gib, d.compute_major, d.compute_minor, reps, steps);
  std::printf("%-15s %-9s %-10s %10s %14s %12s\n", "size", "precision", "force", "MLUPS",
              "copy GB/s", "of roofline");
  nlohmann::json all = nlohmann::json::array();
  // rewritten after each configuration: a run stopped at its time limit (the
  // device check's) keeps every figure measured so far ("complete": false)
  const auto save = [&](bool complete) {
    if (json_file.empty()) return;
    const std::string tmp = json_file + ".tmp";
    std::ofstream(tmp)
        << nlohmann::json{{"gpu", d.name}, {"complete", complete}, {"figures", all}}.dump(2)
        << "\n";
    std::rename(tmp.c_str(), json_file.c_str());
  };
  for (const lattice::Extent& e : sizes)
    for (const bool double_precision : {false, true})
      for (const bool field : {false, true}) {
        const nlohmann::json f = double_precision ? time_gpu_kernel<double>(e, field, steps, reps)
                                                  : time_gpu_kernel<float>(e, field, steps, reps);
        std::printf("%4dx%4dx%4d  %-9s %-10s %10.0f %14.0f %11.1f %%  (limit 75 %%)\n", e.nx, e.ny,
                    e.nz, f["precision"].get<std::string>().c_str(), field ? "per-cell" : "uniform",
                    f["MLUPS"].get<double>(), f["copy_bandwidth_GBs"].get<double>(),
                    100 * f["fraction_of_copy_roofline"].get<double>());
        all.push_back(f);
        save(false);
      }
  save(true);
  return 0;
}
