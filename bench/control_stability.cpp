// Where control forcing is stable (docs/coupling.md, "Control forcing: where
// it is stable"): one sphere in a periodic cube, driven for a long time, for
// each combination of viscosity and gains asked for.
//
//   bench_control_stability --input-radius AG --viscosities NU,... --gains G:P,...
//                           [--box L] [--steps N] [--mode fixed|settling] [--reynolds RE]
//                           [--marker-spacing S]
//
// fixed: the sphere held at rest (off the lattice's symmetry planes), the
// liquid driven past it by a body force that a sphere of radius a_g would
// balance at the superficial velocity U = RE nu / (2 a_g) (Sangani-Acrivos
// drag of the simple cubic array). settling: the sphere free to move and
// rotate (density ratio 4) under the net gravity that makes it settle at
// about that U, the liquid held by the balancing body force.
//
// Per combination, one line: the steps run; whether the run stayed bounded
// (every marker's slip finite and below U, the sphere's speed below 0.3);
// the marker slip (rms over the markers, in units of U) at the end and its
// growth factor per 1000 steps over the last fifth of the run (a loop at the
// edge of stability neither grows nor decays: growth near 1 with a large
// slip); and the force on the sphere against the body force on the liquid
// (fixed: F / (f L^3), 1 at a steady state; settling: the sphere's velocity
// over U).
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/immersed_boundary/immersed_boundary.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/spheres/sphere_dynamics.hpp"

using namespace flocsim;
using spheres::Vec3;

namespace {

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string p; std::getline(in, p, sep);) parts.push_back(p);
  return parts;
}

struct Outcome {
  long steps = 0;
  bool bounded = true;
  double slip_end = 0, growth = 0, load = 0;
};

Outcome run(double ag, double nu, coupling::ControlGains gains, int L, long steps, bool settling,
            double reynolds, double spacing) {
  coupling::Scheme scheme = coupling::kControlScheme;
  scheme.gains = gains;
  scheme.marker_spacing = spacing;
  lattice::FluidLattice<float> fluid({L, L, L}, {nu, 0.25});
  immersed_boundary::ImmersedBoundary<float> ib({ag, scheme, true});
  spheres::SphereSet s;
  s.radius = ag;
  s.density_ratio = 4;
  s.resize(1);
  s.position[0] = Vec3(0.5 * L + 0.31, 0.5 * L + 0.17, 0.5 * L - 0.23);
  const double U = reynolds * nu / (2 * ag);
  const double cells = static_cast<double>(L) * L * L;
  const double drag =
      6 * M_PI * nu * ag * calibration::sangani_acrivos_drag(std::min(0.95, 2 * ag / L)) * U;
  spheres::SphereDynamicsSettings dyn;
  const spheres::PeriodicBox box{Vec3(L, L, L)};
  if (settling) {
    // net gravity g with (rho_p - rho_bar) V_p g = drag, the liquid's balancing body force
    const double V = 4.0 / 3.0 * M_PI * ag * ag * ag;
    const double phi = V / cells;
    const double g = drag / ((1 - phi) * (s.density_ratio - 1) * V);
    dyn.external = spheres::settling_forces(1, ag, s.density_ratio, cells, g);
    fluid.set_body_force({dyn.external.liquid_body_force.x(), 0, 0});
  } else {
    fluid.set_body_force({drag / cells, 0, 0});
  }
  Outcome o;
  std::vector<double> slips;
  for (long n = 1; n <= steps; ++n) {
    ib.apply(fluid, s);
    fluid.step();
    if (settling) {
      spheres::advance_velocities(s, ib.loads(), dyn);
      spheres::advance_positions(s, box);
    }
    o.steps = n;
    const double slip = ib.rms_slip() / U;
    const double speed = s.velocity[0].norm();
    if (!std::isfinite(slip) || slip > 1.0 || !(speed < 0.3)) {
      o.bounded = false;
      o.slip_end = slip;
      return o;
    }
    if (n % 1000 == 0) slips.push_back(slip);
  }
  o.slip_end = slips.back();
  const std::size_t k = slips.size(), from = k - std::max<std::size_t>(1, k / 5);
  o.growth = std::pow(slips.back() / std::max(1e-300, slips[from - 1]),
                      1.0 / static_cast<double>(k - from));
  o.load = settling ? -s.velocity[0].x() / U : ib.force()[0].x() / (drag);
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  double ag = 3.5, reynolds = 1.0, spacing = coupling::kControlScheme.marker_spacing;
  int L = 24;
  long steps = 100000;
  std::string viscosities = "0.01", gains_text = "0.5:0", mode = "fixed";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string arg = argv[i], v = argv[i + 1];
    if (arg == "--input-radius")
      ag = std::stod(v);
    else if (arg == "--viscosities")
      viscosities = v;
    else if (arg == "--gains")
      gains_text = v;
    else if (arg == "--box")
      L = std::stoi(v);
    else if (arg == "--steps")
      steps = std::stol(v);
    else if (arg == "--mode")
      mode = v;
    else if (arg == "--reynolds")
      reynolds = std::stod(v);
    else if (arg == "--marker-spacing")
      spacing = std::stod(v);
    else {
      std::fprintf(stderr, "bench_control_stability: unknown option %s\n", arg.c_str());
      return 2;
    }
  }
  if ((argc - 1) % 2 != 0 || (mode != "fixed" && mode != "settling") || steps < 5000 ||
      !(ag >= 1) || L <= 2 * ag + 4) {
    std::fprintf(stderr,
                 "usage: bench_control_stability --input-radius AG --viscosities NU,... "
                 "--gains G:P,... [--box L > 2 AG + 4] [--steps N >= 5000] "
                 "[--mode fixed|settling] [--reynolds RE]\n");
    return 2;
  }
  std::printf(
      "# control forcing, a_g = %g, box %d^3, %s sphere, Re = 2 a_g U / nu = %g, %ld steps\n", ag,
      L, mode.c_str(), reynolds, steps);
  std::printf("# %8s %6s %6s %8s %8s %10s %9s %8s\n", "nu", "G", "P", "steps", "bounded", "slip/U",
              "growth", mode == "fixed" ? "F/fL3" : "u_p/U");
  for (const std::string& nu_text : split(viscosities, ','))
    for (const std::string& g : split(gains_text, ',')) {
      const auto gp = split(g, ':');
      const double nu = std::stod(nu_text);
      const coupling::ControlGains gains{std::stod(gp.at(0)), gp.size() > 1 ? std::stod(gp[1]) : 0};
      const Outcome o = run(ag, nu, gains, L, steps, mode == "settling", reynolds, spacing);
      std::printf("  %8g %6g %6g %8ld %8s %10.3e %9.4f %8.4f\n", nu, gains.integral,
                  gains.proportional, o.steps, o.bounded ? "yes" : "NO", o.slip_end, o.growth,
                  o.load);
      std::fflush(stdout);
    }
  return 0;
}
