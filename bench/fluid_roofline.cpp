// Fluid-kernel benchmark: MLUPS of the D3Q19 AA-pattern TRT step with forcing
// on, as a fraction of the memory-bandwidth roofline measured in the same run.
//
// roofline MLUPS = measured bandwidth / bytes per cell update, with
// bytes per cell = 2 * 19 * sizeof(Real) (each population read once and written
// once in place; no write-allocate, no second grid) plus 3 * sizeof(Real) when
// the per-cell (immersed-boundary) force field is read.
// Usage: bench_fluid [--size N] [--reps R] [--steps S] [--json FILE]
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench/memory_bandwidth.hpp"
#include "engine/lattice/fluid_lattice.hpp"

using namespace flocsim;

namespace {

struct KernelFigure {
  std::string precision;
  bool force_field;
  int threads;
  double mlups;      // median over repetitions
  double bandwidth;  // median of the best memory-probe figure, bytes/s
  double fraction;   // median over repetitions of MLUPS / roofline MLUPS
  double bytes_per_cell;
};

// Best memory-bandwidth figure of all probes, measured now with `threads`.
double roofline_bandwidth(int threads) {
  double best = 0;
  for (const auto& f : bench::measure_memory_bandwidth(threads, 256u << 20, 1))
    best = std::max(best, f.bytes_per_second);
  return best;
}

// The machine is shared and its bandwidth drifts by tens of per cent within a
// minute, so every kernel repetition is paired with a bandwidth measurement
// taken just before it and the fraction is formed per pair.
template <class Real>
KernelFigure time_kernel(int n, int threads, bool force_field, int steps, int reps) {
  omp_set_num_threads(threads);
  lattice::FluidLattice<Real> fluid({n, n, n}, {0.01, 0.25});
  fluid.set_body_force({1e-6, 0, 0});
  if (force_field) fluid.enable_force_field();
  const double k = 2 * M_PI / n;
  fluid.initialise_equilibrium([&](int x, int, int) {
    return lattice::Macroscopic{1.0, {0, 0.02 * std::sin(k * x), 0}};
  });
  for (int s = 0; s < 2; ++s) fluid.step();  // warm-up: one even and one odd step
  const double bytes = static_cast<double>(fluid.bytes_per_cell_update());
  std::vector<double> rates, bandwidths, fractions;
  for (int r = 0; r < reps; ++r) {
    const double bw = roofline_bandwidth(threads);
    const auto t0 = std::chrono::steady_clock::now();
    for (int s = 0; s < steps; ++s) fluid.step();
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double mlups = static_cast<double>(fluid.extent().cells()) * steps / sec / 1e6;
    rates.push_back(mlups);
    bandwidths.push_back(bw);
    fractions.push_back(mlups * 1e6 * bytes / bw);
  }
  const auto m = fluid.macroscopic(0, 0, 0);
  if (!std::isfinite(m.velocity.y)) {
    std::fprintf(stderr, "bench_fluid: non-finite velocity, kernel broken\n");
    std::exit(1);
  }
  return {sizeof(Real) == 8 ? "double" : "float",
          force_field,
          threads,
          bench::median(rates),
          bench::median(bandwidths),
          bench::median(fractions),
          bytes};
}

}  // namespace

int main(int argc, char** argv) {
  int n = 192, reps = 5, steps = 10, only_threads = 0;
  std::string json_path, only_precision = "all", only_forcing = "all";
  for (int a = 1; a < argc; ++a) {
    std::string arg = argv[a];
    auto next = [&] {
      if (a + 1 >= argc) {
        std::fprintf(stderr, "bench_fluid: %s needs a value\n", arg.c_str());
        std::exit(2);
      }
      return std::string(argv[++a]);
    };
    if (arg == "--size")
      n = std::stoi(next());
    else if (arg == "--reps")
      reps = std::stoi(next());
    else if (arg == "--steps")
      steps = std::stoi(next());
    else if (arg == "--json")
      json_path = next();
    else if (arg == "--threads")
      only_threads = std::stoi(next());
    else if (arg == "--precision")
      only_precision = next();
    else if (arg == "--forcing")
      only_forcing = next();
    else {
      std::fprintf(stderr,
                   "usage: bench_fluid [--size N] [--reps R] [--steps S] [--json FILE]\n"
                   "                   [--threads T] [--precision double|float|all]\n"
                   "                   [--forcing uniform|per-cell|all]\n");
      return 2;
    }
  }
  const int max_threads = omp_get_max_threads();
  std::vector<int> thread_counts = {1};
  if (max_threads > 1) thread_counts.push_back(max_threads);
  if (only_threads > 0) thread_counts = {only_threads};

  std::printf("flocsim fluid benchmark: %d^3 periodic box, D3Q19 TRT + Guo forcing, AA pattern\n",
              n);
  std::printf("median of %d repetitions of %d steps each\n\n", reps, steps);

  nlohmann::json out;
  std::printf("%-22s %8s %12s\n", "memory probe", "threads", "GB/s");
  for (int threads : thread_counts)
    for (const auto& f : bench::measure_memory_bandwidth(threads, 256u << 20, reps)) {
      std::printf("%-22s %8d %12.1f\n", f.kernel.c_str(), f.threads, f.bytes_per_second / 1e9);
      out["bandwidth"].push_back(
          {{"probe", f.kernel}, {"threads", f.threads}, {"GBps", f.bytes_per_second / 1e9}});
    }
  std::printf(
      "\nroofline MLUPS = best memory probe (measured again before every repetition) / bytes per "
      "cell\nbytes per cell = 2 x 19 x sizeof(Real) [+ 3 x sizeof(Real) for the per-cell force "
      "field]\n\n");
  std::printf("%-9s %-12s %8s %10s %11s %10s %14s %9s\n", "precision", "force field", "threads",
              "MLUPS", "bytes/cell", "GB/s roof", "roofline MLUPS", "fraction");
  for (int threads : thread_counts)
    for (bool ff : {false, true})
      for (int prec = 0; prec < 2; ++prec) {
        if (only_forcing != "all" && only_forcing != (ff ? "per-cell" : "uniform")) continue;
        if (only_precision != "all" && only_precision != (prec == 0 ? "double" : "float")) continue;
        const KernelFigure k = prec == 0 ? time_kernel<double>(n, threads, ff, steps, reps)
                                         : time_kernel<float>(n, threads, ff, steps, reps);
        const double roof = k.bandwidth / k.bytes_per_cell / 1e6;
        std::printf("%-9s %-12s %8d %10.1f %11.0f %10.1f %14.1f %8.0f%%\n", k.precision.c_str(),
                    ff ? "per-cell" : "uniform", k.threads, k.mlups, k.bytes_per_cell,
                    k.bandwidth / 1e9, roof, 100 * k.fraction);
        out["kernel"].push_back({{"precision", k.precision},
                                 {"force_field", ff},
                                 {"threads", k.threads},
                                 {"MLUPS", k.mlups},
                                 {"bytes_per_cell", k.bytes_per_cell},
                                 {"roofline_GBps", k.bandwidth / 1e9},
                                 {"roofline_MLUPS", roof},
                                 {"fraction", k.fraction}});
      }
  if (!json_path.empty()) std::ofstream(json_path) << out.dump(2) << "\n";
  return 0;
}
