// Full-step benchmark: one time step of the settling suspension (immersed
// boundary + fluid + sphere update) against the fluid step alone, measured in
// the same run on the same lattice. Default scene: phi = 0.20, a = 6 dx
// (a_g from --input-radius, default the shipped calibration 5.612), box
// 48a x 24a x 24a = 288 x 144 x 144 cells, N = 1320 spheres placed randomly
// without overlap, density ratio 4, single precision lattice.
//
// Every immersed-boundary option is measured in the same run, on the same
// lattice and spheres, interleaved repetition by repetition so that a busy
// neighbour slows all of them alike. Printed per option: the median over
// repetitions of the fluid-only rate (MLUPS, with the per-cell force field
// enabled, as the full step runs it), of the full-step rate, their ratio
// (targets: >= 50 % for the fastest validated option, >= 30 % for the paper's
// method), and the median time of each part of the full step.
// Usage: bench_ib_full_step [--scale S] [--reps R] [--steps K] [--input-radius AG]
//                           [--options K:S:N,...]
//   --scale S shrinks the box to (48a x 24a x 24a) / S at the same phi.
//   --phi PHI solids fraction (default 0.2): a dilute box checks the thread
//   balance when few spheres share the colours.
//   --options the schemes to time, each kernel:marker_spacing:sweeps
//   (default roma3:0.7:2,roma3:1:1,linear2:1:1: the paper's method and the
//   offered fast options). The cost hardly depends on a_g, so one input
//   radius serves them all; their accuracy is in docs/accuracy-cost.md.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "bench/memory_bandwidth.hpp"
#include "engine/immersed_boundary/immersed_boundary.hpp"
#include "engine/immersed_boundary/scheme.hpp"
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

// "roma3:0.7:2" -> Scheme; nullopt when malformed.
std::optional<immersed_boundary::Scheme> parse_option(const std::string& text) {
  const auto c1 = text.find(':'), c2 = text.rfind(':');
  if (c1 == std::string::npos || c2 == c1) return std::nullopt;
  const auto kernel = immersed_boundary::kernel_from_name(text.substr(0, c1));
  if (!kernel) return std::nullopt;
  try {
    const double spacing = std::stod(text.substr(c1 + 1, c2 - c1 - 1));
    const int sweeps = std::stoi(text.substr(c2 + 1));
    if (!(spacing >= 0.3 && spacing <= 1.5) || sweeps < 1 || sweeps > 20) return std::nullopt;
    return immersed_boundary::Scheme{spacing, sweeps, *kernel};
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

// Scheme -> "roma3:0.7:2", the inverse of parse_option.
std::string option_text(const immersed_boundary::Scheme& s) {
  char spacing[32];
  std::snprintf(spacing, sizeof spacing, "%g", s.marker_spacing);
  return std::string(immersed_boundary::kernel_name(s.kernel)) + ":" + spacing + ":" +
         std::to_string(s.sweeps);
}

struct OptionTimes {
  std::vector<double> fluid_rate, full_rate, ratio, ib_ms, fluid_ms, dyn_ms;
};

}  // namespace

int main(int argc, char** argv) {
  double scale = 1, input_radius = 5.612, phi = 0.20;
  int reps = 5, steps = 4;
  std::string options_text =
      option_text(immersed_boundary::kPaperScheme) + ",roma3:1:1,linear2:1:1";
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
    else if (arg == "--options")
      options_text = v;
    else if (arg == "--phi")
      phi = std::stod(v);
    else {
      std::fprintf(
          stderr,
          "usage: bench_ib_full_step [--scale S] [--reps R] [--steps K] [--input-radius AG] "
          "[--options kernel:spacing:sweeps,...] [--phi PHI]\n");
      return 2;
    }
  }
  std::vector<immersed_boundary::Scheme> schemes;
  for (std::size_t at = 0; at <= options_text.size();) {
    const auto comma = std::min(options_text.find(',', at), options_text.size());
    const std::string one = options_text.substr(at, comma - at);
    const auto scheme = parse_option(one);
    if (!scheme) {
      std::fprintf(stderr,
                   "bench_ib_full_step: --options entry '%s': expected kernel:spacing:sweeps with "
                   "kernel roma3 or linear2, spacing in [0.3, 1.5] dx, sweeps in [1, 20]\n",
                   one.c_str());
      return 2;
    }
    schemes.push_back(*scheme);
    at = comma + 1;
  }
  if (!(phi > 0 && phi <= 0.3)) {
    std::fprintf(stderr, "bench_ib_full_step: --phi %g: must be in (0, 0.3]\n", phi);
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

  lattice::FluidLattice<float> fluid({nx, ny, ny}, {nu, 0.25});
  std::vector<std::unique_ptr<immersed_boundary::ImmersedBoundary<float>>> ibs;
  for (const auto& scheme : schemes)
    ibs.push_back(std::make_unique<immersed_boundary::ImmersedBoundary<float>>(
        immersed_boundary::ImmersedBoundarySettings{input_radius, scheme, false}));
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
      "phi = %.3f, float, %d threads\n",
      nx, ny, ny, n, a, input_radius, n * 4.0 / 3.0 * M_PI * a * a * a / box.volume(), threads);
  std::printf("median of %d repetitions of %d steps each, options interleaved\n\n", reps, steps);

  auto full_step = [&](immersed_boundary::ImmersedBoundary<float>& ib, double& t_ib,
                       double& t_fluid, double& t_dyn) {
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
  // Warm-up: some full steps, so the spheres move and the flow is not at rest.
  double w0 = 0, w1 = 0, w2 = 0;
  for (auto& ib : ibs)
    for (int i = 0; i < 2; ++i) full_step(*ib, w0, w1, w2);

  const double cells = static_cast<double>(fluid.extent().cells());
  std::vector<OptionTimes> times(schemes.size());
  for (int r = 0; r < reps; ++r) {
    for (std::size_t o = 0; o < schemes.size(); ++o) {
      // Fluid only: the same lattice stepping with the force field as it is.
      auto t0 = std::chrono::steady_clock::now();
      for (int k = 0; k < steps; ++k) fluid.step();
      const double fluid_only = cells * steps / seconds_since(t0) / 1e6;
      double t_ib = 0, t_fluid = 0, t_dyn = 0;
      full_step(*ibs[o], w0, w1, w2);  // first step after a switch rebuilds the option's stencils
      t0 = std::chrono::steady_clock::now();
      for (int k = 0; k < steps; ++k) full_step(*ibs[o], t_ib, t_fluid, t_dyn);
      const double full = cells * steps / seconds_since(t0) / 1e6;
      OptionTimes& t = times[o];
      t.fluid_rate.push_back(fluid_only);
      t.full_rate.push_back(full);
      t.ratio.push_back(full / fluid_only);
      t.ib_ms.push_back(1e3 * t_ib / steps);
      t.fluid_ms.push_back(1e3 * t_fluid / steps);
      t.dyn_ms.push_back(1e3 * t_dyn / steps);
      std::printf("rep %d, %-44s fluid only %6.1f MLUPS, full step %5.1f MLUPS (%.0f %%)\n", r,
                  schemes[o].describe().c_str(), fluid_only, full, 100 * full / fluid_only);
      std::fflush(stdout);
    }
  }
  if (!std::isfinite(s.velocity[0].x())) {
    std::fprintf(stderr, "bench_ib_full_step: non-finite sphere velocity\n");
    return 1;
  }
  std::printf("\n%-44s %8s %8s %6s %8s %8s %8s %8s\n", "option (median over repetitions)", "fluid",
              "full", "ratio", "IB", "fluid", "spheres", "markers");
  std::printf("%-44s %8s %8s %6s %8s %8s %8s %8s\n", "", "MLUPS", "MLUPS", "%", "ms", "ms", "ms",
              "/sphere");
  for (std::size_t o = 0; o < schemes.size(); ++o) {
    const OptionTimes& t = times[o];
    std::printf("%-44s %8.1f %8.1f %6.0f %8.1f %8.1f %8.2f %8d\n", schemes[o].describe().c_str(),
                bench::median(t.fluid_rate), bench::median(t.full_rate),
                100 * bench::median(t.ratio), bench::median(t.ib_ms), bench::median(t.fluid_ms),
                bench::median(t.dyn_ms), ibs[o]->markers_per_sphere());
  }
  std::printf(
      "targets: full step / fluid only >= 50 %% for the fastest validated option, >= 30 %% for "
      "the paper's method (%s)\n",
      immersed_boundary::kPaperScheme.describe().c_str());
  return 0;
}
