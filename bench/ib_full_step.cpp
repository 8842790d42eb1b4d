// Full-step benchmark: one time step of the settling suspension (immersed
// boundary + fluid + sphere update) against the fluid step alone, measured in
// the same run on the same lattice. Default scene: phi = 0.20, a = 6 dx
// (a_g from --input-radius, default the shipped calibration 5.612), box
// 48a x 24a x 24a = 288 x 144 x 144 cells, N = 1320 spheres placed randomly
// without overlap, density ratio 4, single precision lattice.
//
// Printed: the median over repetitions of the fluid-only rate (MLUPS, with
// the per-cell force field enabled, as the full step runs it), of the full
// step rate, their ratio (the figure the issue asks for: target >= 60 %), and
// the median time of each part of the full step.
// Usage: bench_ib_full_step [--scale S] [--reps R] [--steps K] [--input-radius AG] [--sweeps N]
//   --scale S shrinks the box to (48a x 24a x 24a) / S at the same phi.
//   --sweeps N direct-forcing sweeps per step (default 2, the calibrated scheme;
//   other values measure what a different scheme would cost, not its accuracy).
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "bench/memory_bandwidth.hpp"
#include "engine/immersed_boundary/immersed_boundary.hpp"
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

}  // namespace

int main(int argc, char** argv) {
  double scale = 1, input_radius = 5.612;
  int reps = 5, steps = 4, sweeps = 2;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (i + 1 >= argc) {
      std::fprintf(stderr, "bench_ib_full_step: %s needs a value\n", arg.c_str());
      return 2;
    }
    const std::string v = argv[++i];
    if (arg == "--scale")
      scale = std::stod(v);
    else if (arg == "--reps")
      reps = std::stoi(v);
    else if (arg == "--steps")
      steps = std::stoi(v);
    else if (arg == "--input-radius")
      input_radius = std::stod(v);
    else if (arg == "--sweeps")
      sweeps = std::stoi(v);
    else {
      std::fprintf(
          stderr,
          "usage: bench_ib_full_step [--scale S] [--reps R] [--steps K] [--input-radius AG] "
          "[--sweeps N]\n");
      return 2;
    }
  }
  if (sweeps < 1 || sweeps > 20) {
    std::fprintf(stderr, "bench_ib_full_step: --sweeps %d: must be in [1, 20]\n", sweeps);
    return 2;
  }
  const double a = 6.0, phi = 0.20, ratio = 4.0;
  const int nx = static_cast<int>(std::lround(48 * a / scale));
  const int ny = static_cast<int>(std::lround(24 * a / scale));
  const spheres::PeriodicBox box{Vec3(nx, ny, ny)};
  const std::size_t n =
      static_cast<std::size_t>(std::lround(phi * box.volume() / (4.0 / 3.0 * M_PI * a * a * a)));
  const double nu = 0.01, re_inf = 12;
  const double u_inf = re_inf * nu / (2 * a);
  const double cd = 24 / re_inf * (1 + 0.15 * std::pow(re_inf, 0.687));
  const double g = 0.375 * cd / (ratio - 1) * u_inf * u_inf / a;

  lattice::FluidLattice<float> fluid({nx, ny, ny}, {nu, 0.25});
  immersed_boundary::ImmersedBoundary<float> ib({input_radius, 0.7, sweeps, false});
  spheres::SphereSet s;
  s.radius = a;
  s.density_ratio = ratio;
  s.resize(n);
  s.position = random_positions(n, a, box, 2013);
  spheres::SphereDynamicsSettings dyn;
  dyn.external = spheres::settling_forces(n, a, ratio, box.volume(), g);
  fluid.set_body_force({dyn.external.liquid_body_force.x(), 0, 0});
  fluid.enable_force_field();

  const int threads = omp_get_max_threads();
  std::printf(
      "flocsim full-step benchmark: %d x %d x %d cells, N = %zu spheres, a = %g (a_g = %g), "
      "phi = %.3f, %d markers/sphere, %d sweeps, float, %d threads\n",
      nx, ny, ny, n, a, input_radius, n * 4.0 / 3.0 * M_PI * a * a * a / box.volume(),
      ib.markers_per_sphere(), sweeps, threads);
  std::printf("median of %d repetitions of %d steps each\n\n", reps, steps);

  // Warm-up: some full steps, so the spheres move and the flow is not at rest.
  auto full_step = [&](double& t_ib, double& t_fluid, double& t_dyn) {
    auto t0 = std::chrono::steady_clock::now();
    ib.apply(fluid, s);
    t_ib += seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    fluid.step();
    t_fluid += seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    spheres::advance_velocities(s,
                                {ib.force(), ib.torque(), ib.internal_momentum_change(),
                                 ib.internal_angular_momentum_change()},
                                dyn);
    spheres::advance_positions(s, box);
    t_dyn += seconds_since(t0);
  };
  double w0 = 0, w1 = 0, w2 = 0;
  for (int i = 0; i < 4; ++i) full_step(w0, w1, w2);

  const double cells = static_cast<double>(fluid.extent().cells());
  std::vector<double> fluid_rate, full_rate, ratio_v, ib_ms, fluid_ms, dyn_ms;
  for (int r = 0; r < reps; ++r) {
    // Fluid only: the same lattice stepping with the force field as it is.
    auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < steps; ++k) fluid.step();
    const double fluid_only = cells * steps / seconds_since(t0) / 1e6;
    double t_ib = 0, t_fluid = 0, t_dyn = 0;
    t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < steps; ++k) full_step(t_ib, t_fluid, t_dyn);
    const double full = cells * steps / seconds_since(t0) / 1e6;
    fluid_rate.push_back(fluid_only);
    full_rate.push_back(full);
    ratio_v.push_back(full / fluid_only);
    ib_ms.push_back(1e3 * t_ib / steps);
    fluid_ms.push_back(1e3 * t_fluid / steps);
    dyn_ms.push_back(1e3 * t_dyn / steps);
    std::printf("rep %d: fluid only %.1f MLUPS, full step %.1f MLUPS (%.0f %%)\n", r, fluid_only,
                full, 100 * full / fluid_only);
    std::fflush(stdout);
  }
  if (!std::isfinite(s.velocity[0].x())) {
    std::fprintf(stderr, "bench_ib_full_step: non-finite sphere velocity\n");
    return 1;
  }
  std::printf("\n%-34s %10.1f MLUPS\n", "fluid step only (force field on)",
              bench::median(fluid_rate));
  std::printf("%-34s %10.1f MLUPS\n", "full step", bench::median(full_rate));
  std::printf("%-34s %10.0f %%   (target >= 60 %%)\n", "full step / fluid only",
              100 * bench::median(ratio_v));
  std::printf(
      "parts of the full step (median ms/step): immersed boundary %.1f, fluid %.1f, spheres %.2f\n",
      bench::median(ib_ms), bench::median(fluid_ms), bench::median(dyn_ms));
  std::printf(
      "immersed boundary: %.0f markers/step, %.1f M markers/s\n",
      static_cast<double>(n) * ib.markers_per_sphere(),
      static_cast<double>(n) * ib.markers_per_sphere() / (bench::median(ib_ms) * 1e-3) / 1e6);
  return 0;
}
