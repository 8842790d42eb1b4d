// Liquid-averages benchmark: what one sample of a suspension run costs on the
// CPU (observables::liquid_averages: the solid mask of the spheres, then one
// pass over the lattice for <u>, the momentum, the mass and the largest
// speeds), against the memory it must move, measured in the same run.
//
// roofline time = bytes / (read bandwidth), bytes per cell = 19 x sizeof(Real)
// populations read + 3 x sizeof(Real) of the per-cell force field read + the
// one-byte mask written and read again; the read bandwidth is a read-only
// stream with the same thread count, measured before every repetition (the
// machine is shared and drifts). Printed beside it: the mask alone, and the
// whole call in units of the lattice step (measured in the same run), which is
// what a sample costs a run per sample_every.
//
// Default case: the paper's box, 288 x 144 x 144 cells, N = 1320 spheres of
// a = 6 (phi 0.2) placed at random without overlap, a random-ish flow.
// Usage: bench_liquid_averages [--scale S] [--reps R] [--json FILE]
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
#include "engine/observables/liquid_averages.hpp"
#include "engine/placement/random_placement.hpp"

using namespace flocsim;
using spheres::Vec3;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

template <class Real>
nlohmann::json time_averages(lattice::Extent e, const spheres::SphereSet& s, int reps) {
  const int threads = omp_get_max_threads();
  lattice::FluidLattice<Real> fluid(e, {0.02, 0.25});
  fluid.set_body_force({1e-6, 0, 0});
  fluid.enable_force_field();
  const double k = 2 * M_PI / e.nx;
  fluid.initialise_equilibrium([&](int x, int y, int z) {
    return lattice::Macroscopic{
        1.0, {0.01 * std::sin(k * y), 0.02 * std::sin(k * x), 0.005 * std::cos(k * z)}};
  });
  for (int i = 0; i < 2; ++i) fluid.step();  // warm-up: both AA parities
  const double cells = static_cast<double>(e.cells());
  const double bytes = cells * (22.0 * sizeof(Real) + 2.0);
  std::vector<std::uint8_t> solid;
  (void)observables::liquid_averages(fluid, s, solid);  // warm-up: the mask allocated
  std::vector<double> call_s, mask_s, step_s, fraction;
  double liquid_fraction = 0;
  for (int r = 0; r < reps; ++r) {
    const double read_bw = bench::measure_read_bandwidth(threads, 256u << 20, 1);
    auto t0 = std::chrono::steady_clock::now();
    const observables::LiquidAverages a = observables::liquid_averages(fluid, s, solid);
    call_s.push_back(seconds_since(t0));
    if (!std::isfinite(a.mass)) {
      std::fprintf(stderr, "bench_liquid_averages: the lattice's mass is not finite\n");
      std::exit(1);
    }
    liquid_fraction = static_cast<double>(a.liquid_cells) / cells;
    t0 = std::chrono::steady_clock::now();
    observables::mark_solid_cells(e, s.position, s.radius, solid);
    mask_s.push_back(seconds_since(t0));
    t0 = std::chrono::steady_clock::now();
    fluid.step();
    step_s.push_back(seconds_since(t0));
    fraction.push_back(bytes / read_bw / call_s.back());
  }
  return {{"precision", sizeof(Real) == 8 ? "double" : "float"},
          {"threads", threads},
          {"cells", cells},
          {"spheres", s.size()},
          {"liquid_fraction", liquid_fraction},
          {"bytes_per_cell", 22.0 * sizeof(Real) + 2.0},
          {"averages_ms", 1e3 * bench::median(call_s)},
          {"mask_ms", 1e3 * bench::median(mask_s)},
          {"fluid_step_ms", 1e3 * bench::median(step_s)},
          {"averages_over_fluid_step", bench::median(call_s) / bench::median(step_s)},
          {"fraction_of_roofline", bench::median(fraction)}};
}

}  // namespace

int main(int argc, char** argv) {
  double scale = 1;
  int reps = 5;
  std::string json_file;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--scale" && has_value)
      scale = std::atof(argv[++i]);
    else if (arg == "--reps" && has_value)
      reps = std::atoi(argv[++i]);
    else if (arg == "--json" && has_value)
      json_file = argv[++i];
    else {
      std::fprintf(stderr, "usage: bench_liquid_averages [--scale S] [--reps R] [--json FILE]\n");
      return 2;
    }
  }
  if (!(scale >= 1 && scale <= 8) || reps < 1) {
    std::fprintf(stderr, "bench_liquid_averages: --scale must be in [1, 8], --reps at least 1\n");
    return 2;
  }
  const lattice::Extent e{static_cast<int>(std::lround(288 / scale)),
                          static_cast<int>(std::lround(144 / scale)),
                          static_cast<int>(std::lround(144 / scale))};
  spheres::SphereSet s;
  s.radius = 6.0;
  const spheres::PeriodicBox box{Vec3(e.nx, e.ny, e.nz)};
  const int n = static_cast<int>(std::lround(0.2 * static_cast<double>(e.cells()) / s.volume()));
  s.resize(static_cast<std::size_t>(n));
  s.position = placement::place_randomly({.count = n, .radius = s.radius, .seed = 5}, box);

  std::printf(
      "flocsim liquid-averages benchmark: %d x %d x %d cells, N = %d spheres of a = 6, "
      "%d threads, median of %d repetitions\n",
      e.nx, e.ny, e.nz, n, omp_get_max_threads(), reps);
  std::printf(
      "roofline = (22 x sizeof(Real) + 2) bytes per cell / read-only stream bandwidth, "
      "measured before each repetition\n\n");
  std::printf("%-9s %12s %10s %14s %16s %10s\n", "precision", "averages ms", "mask ms",
              "fluid step ms", "averages/step", "roofline");
  nlohmann::json all = nlohmann::json::array();
  for (const std::string p : {"float", "double"}) {
    const nlohmann::json r =
        p == "float" ? time_averages<float>(e, s, reps) : time_averages<double>(e, s, reps);
    std::printf("%-9s %12.1f %10.1f %14.1f %16.2f %9.0f%%\n", p.c_str(),
                r["averages_ms"].get<double>(), r["mask_ms"].get<double>(),
                r["fluid_step_ms"].get<double>(), r["averages_over_fluid_step"].get<double>(),
                100 * r["fraction_of_roofline"].get<double>());
    all.push_back(r);
  }
  std::printf(
      "\nlimit: the averages' pass at >= 50 %% of the read roofline; one sample costs a run "
      "averages/step lattice steps every sample_every (0.5 a/U_inf: 150 steps at the "
      "paper's U_inf)\n");
  if (!json_file.empty()) std::ofstream(json_file) << nlohmann::json{{"results", all}}.dump(2);
  return 0;
}
