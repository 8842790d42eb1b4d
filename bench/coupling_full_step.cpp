// Full-step benchmark of every coupling option: one time step of the settling
// suspension (coupling + fluid + sphere update) against the fluid step alone,
// measured in the same run. Default scene: the paper's case, phi = 0.20,
// a = 6 dx, box 48a x 24a x 24a = 288 x 144 x 144 cells, N = 1320 spheres
// placed randomly without overlap, density ratio 4, single precision lattice.
//
// Each option runs on its own lattice with its own copy of the spheres; the
// fluid-only steps run on a plain lattice with the per-cell force field
// enabled (as the immersed boundary's step reads it: 164 bytes per cell in
// float). Options and the fluid-only steps are interleaved repetition by
// repetition, so that a busy neighbour slows all of them alike. Printed per
// option: the median over repetitions of the fluid-only rate (MLUPS), of the
// full-step rate, of their ratio (targets: >= 60 % for partially saturated
// cells, 50 % the floor; >= 50 % for the fastest immersed-boundary option,
// >= 30 % for the paper's markers), and of the time of each part of the step.
//
// Usage: bench_coupling [--scale S] [--reps R] [--steps K] [--phi PHI]
//                       [--options OPTION,...]
//   --scale S shrinks the box to (48a x 24a x 24a) / S at the same phi.
//   --phi PHI solids fraction (default 0.2).
//   --options the schemes to time (default: all offered), each one of
//     direct:KERNEL:SPACING:SWEEPS   immersed boundary, direct forcing
//                                    (also KERNEL:SPACING:SWEEPS)
//     control:KERNEL:SPACING[:G:P]   immersed boundary, control forcing
//     psm                            partially saturated cells
//   The cost hardly depends on the input radius; the immersed boundary uses
//   5.612 (the paper method's a_g at a = 6), the partially saturated cells 6.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench/coupling_options.hpp"
#include "bench/memory_bandwidth.hpp"
#include "engine/coupling/scheme.hpp"
#include "engine/coupling_schemes/make_coupling.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/spheres/sphere_dynamics.hpp"

using namespace flocsim;
using spheres::Vec3;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Random sequential addition: N non-overlapping spheres of radius a.
std::vector<Vec3> random_positions(std::size_t n, double a, const spheres::PeriodicBox& box,
                                   unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> out;
  const double min_sq = 4 * a * a * 1.0001;
  while (out.size() < n) {
    const Vec3 x(u(rng) * box.length[0], u(rng) * box.length[1], u(rng) * box.length[2]);
    bool ok = true;
    for (const Vec3& y : out)
      if (box.minimum_image(x - y).squaredNorm() < min_sq) {
        ok = false;
        break;
      }
    if (ok) out.push_back(x);
  }
  return out;
}

struct Option {
  coupling::Scheme scheme;
  std::unique_ptr<lattice::FluidLattice<float>> fluid;
  std::unique_ptr<coupling::SphereCoupling<float>> coupling;
  spheres::SphereSet s;
  std::vector<double> full_rate, ratio, coupling_ms, fluid_ms, dyn_ms;
};

}  // namespace

int main(int argc, char** argv) {
  double scale = 1, phi = 0.20;
  int reps = 5, steps = 4;
  std::string options_text = "direct:roma3:0.7:2,direct:roma3:1:1,control:roma3:0.7,psm";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (i + 1 >= argc) {
      std::fprintf(stderr, "bench_coupling: %s needs a value\n", arg.c_str());
      return 2;
    }
    const std::string v = argv[++i];
    if (arg == "--scale")
      scale = std::stod(v);
    else if (arg == "--reps")
      reps = std::stoi(v);
    else if (arg == "--steps")
      steps = std::stoi(v);
    else if (arg == "--options")
      options_text = v;
    else if (arg == "--phi")
      phi = std::stod(v);
    else {
      std::fprintf(stderr,
                   "usage: bench_coupling [--scale S] [--reps R] [--steps K] [--phi PHI] "
                   "[--options OPTION,...]\n");
      return 2;
    }
  }
  std::vector<Option> options;
  for (const std::string& one : bench::split(options_text, ',')) {
    const auto scheme = bench::parse_option(one);
    if (!scheme) {
      std::fprintf(stderr, "bench_coupling: --options entry '%s': expected %s\n", one.c_str(),
                   bench::kOptionsSyntax);
      return 2;
    }
    options.push_back(Option{*scheme, {}, {}, {}, {}, {}, {}, {}, {}});
  }
  if (!(phi > 0 && phi <= 0.3)) {
    std::fprintf(stderr, "bench_coupling: --phi %g: must be in (0, 0.3]\n", phi);
    return 2;
  }
  const double a = 6.0, ratio = 4.0;
  const int nx = static_cast<int>(std::lround(48 * a / scale));
  const int ny = static_cast<int>(std::lround(24 * a / scale));
  const spheres::PeriodicBox box{Vec3(nx, ny, ny)};
  const std::size_t n =
      static_cast<std::size_t>(std::lround(phi * box.volume() / (4.0 / 3.0 * M_PI * a * a * a)));
  const double nu = 0.01, re_inf = 12;
  const double u_inf = re_inf * nu / (2 * a);
  const double cd = 24 / re_inf * (1 + 0.15 * std::pow(re_inf, 0.687));
  const double g = 0.375 * cd / (ratio - 1) * u_inf * u_inf / a;
  spheres::SphereDynamicsSettings dyn;
  dyn.external = spheres::settling_forces(n, a, ratio, box.volume(), g);

  spheres::SphereSet start;
  start.radius = a;
  start.density_ratio = ratio;
  start.resize(n);
  start.position = random_positions(n, a, box, 2013);
  // the fluid-only reference: the plain step with the per-cell force field
  lattice::FluidLattice<float> plain({nx, ny, ny}, {nu, 0.25});
  plain.set_body_force({dyn.external.liquid_body_force.x(), 0, 0});
  plain.enable_force_field();
  for (Option& o : options) {
    o.fluid = std::make_unique<lattice::FluidLattice<float>>(lattice::Extent{nx, ny, ny},
                                                             lattice::Relaxation{nu, 0.25});
    o.fluid->set_body_force({dyn.external.liquid_body_force.x(), 0, 0});
    o.coupling = coupling::make_coupling<float>(o.scheme, o.scheme.immersed_boundary() ? 5.612 : a);
    o.s = start;
  }

  const int threads = omp_get_max_threads();
  std::printf(
      "flocsim coupling benchmark: %d x %d x %d cells, N = %zu spheres, a = %g, phi = %.3f, "
      "float, %d threads\n",
      nx, ny, ny, n, a, n * 4.0 / 3.0 * M_PI * a * a * a / box.volume(), threads);
  std::printf("median of %d repetitions of %d steps each, options interleaved\n\n", reps, steps);

  auto full_step = [&](Option& o, double& t_coupling, double& t_fluid, double& t_dyn) {
    auto t0 = std::chrono::steady_clock::now();
    o.coupling->apply(*o.fluid, o.s);
    t_coupling += seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    o.fluid->step();
    t_fluid += seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    o.coupling->after_liquid_step(*o.fluid, o.s);
    t_coupling += seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    spheres::advance_velocities(o.s, o.coupling->loads(), dyn);
    spheres::advance_positions(o.s, box);
    t_dyn += seconds_since(t0);
  };
  // Warm-up: some full steps, so the spheres move and the flow is not at rest.
  double w0 = 0, w1 = 0, w2 = 0;
  for (Option& o : options)
    for (int i = 0; i < 3; ++i) full_step(o, w0, w1, w2);
  for (int i = 0; i < 2; ++i) plain.step();

  const double cells = static_cast<double>(plain.extent().cells());
  std::vector<double> fluid_rates;
  for (int r = 0; r < reps; ++r) {
    for (Option& o : options) {
      auto t0 = std::chrono::steady_clock::now();
      for (int k = 0; k < steps; ++k) plain.step();
      const double fluid_only = cells * steps / seconds_since(t0) / 1e6;
      fluid_rates.push_back(fluid_only);
      double t_coupling = 0, t_fluid = 0, t_dyn = 0;
      t0 = std::chrono::steady_clock::now();
      for (int k = 0; k < steps; ++k) full_step(o, t_coupling, t_fluid, t_dyn);
      const double full = cells * steps / seconds_since(t0) / 1e6;
      o.full_rate.push_back(full);
      o.ratio.push_back(full / fluid_only);
      o.coupling_ms.push_back(1e3 * t_coupling / steps);
      o.fluid_ms.push_back(1e3 * t_fluid / steps);
      o.dyn_ms.push_back(1e3 * t_dyn / steps);
      std::printf("rep %d, %-60s fluid only %6.1f MLUPS, full step %5.1f MLUPS (%.0f %%)\n", r,
                  o.scheme.describe().c_str(), fluid_only, full, 100 * full / fluid_only);
      std::fflush(stdout);
    }
  }
  for (const Option& o : options)
    if (!std::isfinite(o.s.velocity[0].x())) {
      std::fprintf(stderr, "bench_coupling: non-finite sphere velocity with %s\n",
                   o.scheme.describe().c_str());
      return 1;
    }
  std::printf("\nfluid only (plain step with the per-cell force field): median %.1f MLUPS\n",
              bench::median(fluid_rates));
  std::printf("%-60s %8s %6s %9s %8s %8s\n", "option (median over repetitions)", "full", "ratio",
              "coupling", "fluid", "spheres");
  std::printf("%-60s %8s %6s %9s %8s %8s\n", "", "MLUPS", "%", "ms", "ms", "ms");
  for (const Option& o : options)
    std::printf("%-60s %8.1f %6.0f %9.1f %8.1f %8.2f\n", o.scheme.describe().c_str(),
                bench::median(o.full_rate), 100 * bench::median(o.ratio),
                bench::median(o.coupling_ms), bench::median(o.fluid_ms), bench::median(o.dyn_ms));
  std::printf(
      "targets: full step / fluid only >= 60 %% (50 %% the floor) for partially saturated cells, "
      ">= 50 %% for the fastest immersed-boundary option, >= 30 %% for the paper's method (%s)\n",
      coupling::kPaperScheme.describe().c_str());
  return 0;
}
