// The force noise each coupling scheme puts on a moving sphere: one sphere
// dragged at a constant velocity U through a periodic box of liquid (a body
// force returns to the liquid what the sphere gives it, so the liquid stays
// at rest on average), so that in the sphere's frame the
// flow is steady and every fluctuation of the drag comes from the sphere
// crossing the lattice (the staircase of solid fractions, the markers'
// kernels moving over the cells). The spectrum's line at the crossing
// frequency U / dx and the rms fluctuation of the force against its mean
// are what the scheme adds to a settling suspension's agitation.
//
//   bench_coupling_noise [--radius A] [--viscosity NU] [--reynolds RE] [--box L]
//                        [--steps N] [--options OPTION,...] [--series PREFIX]
//                        [--input-radius AG]
//
// For each option (as bench_coupling: direct:KERNEL:SPACING:SWEEPS,
// control:KERNEL:SPACING[:G:P], psm), with the input radius the shipped
// calibration gives for a and nu (or --input-radius, for a scheme not
// shipped at a): the sphere is dragged along x, slightly
// off the lattice's axes (U (1, 0.13, 0.07) / |...|), at Re = 2 a U / nu, in
// an L x L/2 x L/2 box, for N steps. Over the second half it prints the mean
// drag, its rms fluctuation relative to the mean, and the rms of the part of
// the fluctuation at the crossing frequency (the largest component of U over
// dx) and its harmonics. --series writes the force per step to
// PREFIX<option>.txt.
#include <omp.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/coupling/scheme.hpp"
#include "engine/coupling_schemes/make_coupling.hpp"
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

std::optional<coupling::Scheme> parse_option(const std::string& text) {
  if (text == "psm") return coupling::kPartiallySaturatedScheme;
  auto parts = split(text, ':');
  coupling::Scheme s;
  if (!parts.empty() && (parts[0] == "direct" || parts[0] == "control")) {
    s.forcing = *coupling::forcing_from_name(parts[0]);
    parts.erase(parts.begin());
  }
  if (parts.size() < 2) return std::nullopt;
  const auto kernel = coupling::kernel_from_name(parts[0]);
  if (!kernel) return std::nullopt;
  s.kernel = *kernel;
  try {
    s.marker_spacing = std::stod(parts[1]);
    s.sweeps = s.control() ? 1 : (parts.size() > 2 ? std::stoi(parts[2]) : 1);
    if (s.control() && parts.size() == 4) s.gains = {std::stod(parts[2]), std::stod(parts[3])};
  } catch (const std::exception&) {
    return std::nullopt;
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  double a = 4, nu = 0.02, re = 10, given_radius = 0;
  int L = 32;
  long steps = 6000;
  std::string options = "direct:roma3:0.7:2,direct:roma3:1:1,control:roma3:0.7,psm", series;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string arg = argv[i], v = argv[i + 1];
    if (arg == "--radius")
      a = std::stod(v);
    else if (arg == "--viscosity")
      nu = std::stod(v);
    else if (arg == "--reynolds")
      re = std::stod(v);
    else if (arg == "--box")
      L = std::stoi(v);
    else if (arg == "--steps")
      steps = std::stol(v);
    else if (arg == "--options")
      options = v;
    else if (arg == "--series")
      series = v;
    else if (arg == "--input-radius")
      given_radius = std::stod(v);
    else {
      std::fprintf(stderr, "bench_coupling_noise: unknown option %s\n", arg.c_str());
      return 2;
    }
  }
  const double U = re * nu / (2 * a);
  const Vec3 direction = Vec3(1, 0.13, 0.07).normalized();
  const int W = L / 2;
  std::printf(
      "# one sphere dragged at U = %.4g (Re %g) through %d x %d x %d, a = %g, nu = %g, %ld steps\n",
      U, re, L, W, W, a, nu, steps);
  std::printf("# %-58s %9s %10s %12s %12s\n", "option", "a_g", "F/(6pi nu a U)", "rms/mean",
              "crossing rms");
  for (const std::string& text : split(options, ',')) {
    const auto scheme = parse_option(text);
    if (!scheme) {
      std::fprintf(stderr, "bench_coupling_noise: --options entry %s not understood\n",
                   text.c_str());
      return 2;
    }
    double ag = given_radius;
    try {
      if (ag <= 0) ag = calibration::CalibrationTable::shipped().input_radius(a, nu, *scheme);
    } catch (const std::exception& e) {
      std::printf("  %-58s not calibrated at a = %g\n", scheme->describe().c_str(), a);
      continue;
    }
    lattice::FluidLattice<float> fluid({L, W, W}, {nu, 0.25});
    auto coupling = coupling::make_coupling<float>(*scheme, ag);
    spheres::SphereSet s;
    s.radius = a;
    s.density_ratio = 4;
    s.resize(1);
    s.position[0] = Vec3(0.3 * L, 0.5 * W + 0.21, 0.5 * W - 0.37);
    s.velocity[0] = U * direction;
    const spheres::PeriodicBox box{Vec3(L, W, W)};
    std::vector<double> force;
    for (long n = 0; n < steps; ++n) {
      coupling->apply(fluid, s);
      fluid.step();
      coupling->after_liquid_step(fluid, s);
      // the drag along the motion; the inside liquid's momentum change too,
      // as the sphere equations see it
      force.push_back(
          -(coupling->force()[0] + coupling->internal_momentum_change()[0]).dot(direction));
      // a body force returning what the sphere gave the liquid, so that the
      // liquid's mean momentum stays at rest
      const Vec3 back = coupling->force()[0] / (static_cast<double>(L) * W * W);
      fluid.set_body_force({back.x(), back.y(), back.z()});
      spheres::advance_positions(s, box);
    }
    if (!series.empty()) {
      std::FILE* f = std::fopen((series + text + ".txt").c_str(), "w");
      for (double x : force) std::fprintf(f, "%.9e\n", x);
      std::fclose(f);
    }
    const std::size_t h = force.size() / 2, m = force.size() - h;
    double mean = 0;
    for (std::size_t k = h; k < force.size(); ++k) mean += force[k];
    mean /= static_cast<double>(m);
    double var = 0;
    for (std::size_t k = h; k < force.size(); ++k) var += (force[k] - mean) * (force[k] - mean);
    // the part at the crossing frequency f_c = max |U_d| (cells per step) and its harmonics
    const double fc = U * direction.cwiseAbs().maxCoeff();
    double line = 0;
    for (int harmonic = 1; harmonic <= 4; ++harmonic) {
      std::complex<double> c = 0;
      for (std::size_t k = h; k < force.size(); ++k)
        c +=
            (force[k] - mean) * std::polar(1.0, -2 * M_PI * harmonic * fc * static_cast<double>(k));
      line += 2 * std::norm(c) / (static_cast<double>(m) * m);
    }
    std::printf("  %-58s %9.4f %10.4f %12.3e %12.3e\n", scheme->describe().c_str(), ag,
                mean / (6 * M_PI * nu * a * U), std::sqrt(var / m) / std::abs(mean),
                std::sqrt(line) / std::abs(mean));
    std::fflush(stdout);
  }
  return 0;
}
