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
//                        [--input-radius AG] [--held 1]
//
// For each option (as bench_coupling: direct:KERNEL:SPACING:SWEEPS,
// control:KERNEL:SPACING[:G:P], psm), with the input radius the shipped
// calibration gives for a and nu (or --input-radius, for a scheme not
// shipped at a): the sphere is dragged along x, slightly
// off the lattice's axes (U (1, 0.13, 0.07) / |...|), at Re = 2 a U / nu, in
// an L x L/2 x L/2 box, for N steps. Over the second half it prints the mean
// drag, its rms fluctuation relative to the mean, and the rms of the part of
// the fluctuation at the crossing frequency (the largest component of U over
// dx) and its harmonics. --held 1 also runs the sphere held in the liquid
// moving past it (at a node-aligned and a mid-cell place, averaged) and
// prints that drag and dragged / held: 1 for a Galilean-invariant scheme, and
// the held sphere's own fluctuation in a steady flow (rms / mean, and the
// strongest spectral line: its frequency in cycles per step and amplitude /
// mean): what the scheme itself rings with when nothing crosses the grid.
// --series writes the dragged force per step to PREFIX<option>.txt.
#include <omp.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "bench/coupling_options.hpp"
#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/coupling/scheme.hpp"
#include "engine/coupling_schemes/make_coupling.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/spheres/sphere_dynamics.hpp"

using namespace flocsim;
using spheres::Vec3;

int main(int argc, char** argv) {
  double a = 4, nu = 0.02, re = 10, given_radius = 0;
  bool held = false;
  int L = 32;
  long steps = 6000;
  std::string options = "direct:roma3:0.7:2,direct:roma3:1:1,control:roma3:1,psm", series;
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
    else if (arg == "--held")
      held = v == "1" || v == "yes";
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
  std::printf("# %-58s %9s %10s %12s %12s%s\n", "option", "a_g", "F/(6pi nu a U)", "rms/mean",
              "crossing rms",
              held ? "       held  dragged/held held rms/mean  peak f/step  peak a/mean" : "");
  for (const std::string& text : bench::split(options, ',')) {
    const auto scheme = bench::parse_option(text);
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
    // one run: the drag per step along the motion (the inside liquid's momentum
    // change included, as the sphere equations see it)
    auto drag_series = [&](bool still, double shift) {
      lattice::FluidLattice<float> fluid({L, W, W}, {nu, 0.25});
      auto coupling = coupling::make_coupling<float>(*scheme, ag);
      spheres::SphereSet s;
      s.radius = a;
      s.density_ratio = 4;
      s.resize(1);
      s.position[0] = Vec3(0.3 * L, 0.5 * W + 0.21, 0.5 * W - 0.37) + Vec3::Constant(shift);
      if (still) {
        const Vec3 v = -U * direction;
        fluid.initialise_equilibrium([&](int, int, int) {
          return lattice::Macroscopic{1.0, {v.x(), v.y(), v.z()}};
        });
      } else {
        s.velocity[0] = U * direction;
      }
      const spheres::PeriodicBox box{Vec3(L, W, W)};
      std::vector<double> force;
      for (long n = 0; n < steps; ++n) {
        coupling->apply(fluid, s);
        fluid.step();
        coupling->after_liquid_step(fluid, s);
        force.push_back(
            -(coupling->force()[0] + coupling->internal_momentum_change()[0]).dot(direction));
        // a body force returning what the sphere gave the liquid, so that the
        // liquid's mean momentum stays as it started
        const Vec3 back = coupling->force()[0] / (static_cast<double>(L) * W * W);
        fluid.set_body_force({back.x(), back.y(), back.z()});
        spheres::advance_positions(s, box);
      }
      return force;
    };
    const std::vector<double> force = drag_series(false, 0.0);
    if (!series.empty()) {
      std::FILE* f = std::fopen((series + text + ".txt").c_str(), "w");
      for (double x : force) std::fprintf(f, "%.9e\n", x);
      std::fclose(f);
    }
    const std::size_t h = force.size() / 2, m = force.size() - h;
    auto second_half_mean = [&](const std::vector<double>& f) {
      double sum = 0;
      for (std::size_t k = h; k < f.size(); ++k) sum += f[k];
      return sum / static_cast<double>(m);
    };
    const double mean = second_half_mean(force);
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
    const double unit = 6 * M_PI * nu * a * U;
    std::printf("  %-58s %9.4f %10.4f %12.3e %12.3e", scheme->describe().c_str(), ag, mean / unit,
                std::sqrt(var / m) / std::abs(mean), std::sqrt(line) / std::abs(mean));
    if (held) {
      // the same sphere held in the liquid moving past it, at a node-aligned and
      // a mid-cell place (the dragged sphere averages over the cells it crosses)
      const std::vector<double> node = drag_series(true, 0.0);
      const double still =
          0.5 * (second_half_mean(node) + second_half_mean(drag_series(true, 0.5)));
      std::printf(" %10.4f %10.4f", still / unit, mean / still);
      // what the held (node-aligned) sphere's drag still does over the second
      // half, where the flow past it is steady: its rms fluctuation and the
      // strongest line of its spectrum (frequency in cycles per step, scanned
      // from 1/m to 1/2 in steps of 1/m; amplitude relative to the mean)
      const double node_mean = second_half_mean(node);
      double node_var = 0;
      for (std::size_t k = h; k < node.size(); ++k)
        node_var += (node[k] - node_mean) * (node[k] - node_mean);
      double peak_f = 0, peak_a = 0;
      for (std::size_t j = 1; j <= m / 2; ++j) {
        const double fr = static_cast<double>(j) / static_cast<double>(m);
        std::complex<double> c = 0;
        for (std::size_t k = h; k < node.size(); ++k)
          c += (node[k] - node_mean) * std::polar(1.0, -2 * M_PI * fr * static_cast<double>(k - h));
        const double amplitude = 2 * std::abs(c) / static_cast<double>(m);
        if (amplitude > peak_a) peak_a = amplitude, peak_f = fr;
      }
      std::printf(" %12.3e %10.4f %12.3e", std::sqrt(node_var / m) / std::abs(node_mean), peak_f,
                  peak_a / std::abs(node_mean));
    }
    std::printf("\n");
    std::fflush(stdout);
  }
  return 0;
}
