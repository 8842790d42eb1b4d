// The lattice's own radial resistance of a close pair of immersed-boundary
// spheres, against Brenner's exact value: the measurement behind the
// close-pair calibration (docs/contacts.md, "What the lattice resolves").
//
// Two spheres of hydrodynamic radius a sit at surface gap s on the x axis of a
// periodic box and are held there while moving at +-V along the line of
// centres (towards each other, or apart with --separating); the liquid starts
// at rest and the run goes on until the force on each sphere is steady
// (relative change below 1e-5 over 200 steps). No lubrication correction acts.
// lambda_IB = -F . e / (6 pi rho nu a V), e the direction of the sphere's
// motion. Creeping flow: Re = 2aV/nu = 0.01 or below.
//
// The periodic box adds a far-field part to the lattice's figure; the program
// prints it as lambda_IB - lambda_exact at the largest gap, which the
// calibration subtracts at every gap (the images of a force dipole change
// little over s << L).
//
// Usage: measure_pair_resistance --radius A [--viscosity NU] [--box L] [--separating]
//                                [--gaps s1,s2,...]   (gaps in units of a)
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/immersed_boundary/immersed_boundary.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/lubrication/two_sphere_resistance.hpp"

using namespace flocsim;

namespace {

struct Measured {
  double lambda = 0;
  long steps = 0;
};

Measured measure(double a, double nu, int box, double gap, bool separating) {
  lattice::FluidLattice<double> fluid({box, box / 2, box / 2}, {nu, 0.25});
  fluid.initialise_equilibrium([](int, int, int) { return lattice::Macroscopic{}; });
  const double a_g = calibration::CalibrationTable::shipped().input_radius(a, nu);
  immersed_boundary::ImmersedBoundary<double> ib({.input_radius = a_g});
  spheres::SphereSet s;
  s.radius = a;
  s.resize(2);
  const double V = 0.005 * nu / a;  // Re = 2aV/nu = 0.01
  const double cx = 0.5 * box, cy = 0.25 * box + 0.37, cz = 0.25 * box + 0.21;
  s.position[0] = {cx - a - 0.5 * gap * a, cy, cz};
  s.position[1] = {cx + a + 0.5 * gap * a, cy, cz};
  const double towards = separating ? -1.0 : 1.0;
  s.velocity[0] = {towards * V, 0, 0};
  s.velocity[1] = {-towards * V, 0, 0};
  Measured m;
  double last = 0;
  for (long step = 1; step <= 200000; ++step) {
    ib.apply(fluid, s);
    fluid.step();
    if (step % 200 == 0) {
      // the force on sphere 0 opposes its motion, which is +x when approaching
      const double lambda = -towards * ib.force()[0].x() / (6 * M_PI * nu * a * V);
      m.lambda = lambda;
      m.steps = step;
      if (step > 1000 && std::abs(lambda - last) < 1e-5 * std::abs(lambda)) break;
      last = lambda;
    }
  }
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  double a = 4, nu = 1.0 / 6.0;
  int box = 0;
  bool separating = false;
  std::vector<double> gaps = {0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0};
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    if (k == "--radius" && i + 1 < argc)
      a = std::atof(argv[++i]);
    else if (k == "--viscosity" && i + 1 < argc)
      nu = std::atof(argv[++i]);
    else if (k == "--box" && i + 1 < argc)
      box = std::atoi(argv[++i]);
    else if (k == "--separating")
      separating = true;
    else if (k == "--gaps" && i + 1 < argc) {
      gaps.clear();
      std::stringstream list(argv[++i]);
      for (std::string g; std::getline(list, g, ',');) gaps.push_back(std::atof(g.c_str()));
    }
  }
  if (box == 0) box = static_cast<int>(16 * a);
  std::printf("# a = %g, nu = %g, box %d x %d x %d, %s, %d threads\n", a, nu, box, box / 2, box / 2,
              separating ? "separating" : "approaching", omp_get_max_threads());
  std::printf("# s/a  lambda_IB  lambda_exact  exact-IB  steps\n");
  for (double g : gaps) {
    const Measured m = measure(a, nu, box, g, separating);
    const double exact = lubrication::brenner_pair_resistance(g);
    std::printf("%6.3f  %9.4f  %12.4f  %8.4f  %ld\n", g, m.lambda, exact, exact - m.lambda,
                m.steps);
    std::fflush(stdout);
  }
  return 0;
}
