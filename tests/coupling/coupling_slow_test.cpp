// Long checks of the coupling schemes (label slow).
#include <gtest/gtest.h>

#include <cstdio>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/coupling_schemes/make_coupling.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "tests/coupling/coupling_test_support.hpp"

namespace flocsim {
namespace {

using spheres::Vec3;

// Control forcing at the lowest viscosity of the paper's range (a = 6:
// nu = 0.005; cases offer it at a = 4, where the floor is 0.01), a sphere settling at Re 12 for 1e5
// steps with the default gains and at the two edges of the accepted region (integral 3; integral 1
// with proportional 1): bounded, the marker slip below 1e-2 U
// (docs/coupling.md: 6e-4 measured with the defaults). About 2 minutes per
// gain on one core.
TEST(ControlForcingSlow, SettlingSphereStaysBoundedFor1e5StepsAtTheLowestViscosity) {
  for (const coupling::ControlGains g : {coupling::ControlGains{2, 0}, {3, 0}, {1, 1}}) {
    const auto r = testing_support::settle_with_control(5.612, 0.005, 32, 100000, g);
    std::printf("gains %g, %g: %ld steps, slip %.2e U, u_p / U %.3f\n", g.integral, g.proportional,
                r.steps, r.slip, r.speed);
    EXPECT_EQ(r.steps, 100000);
    EXPECT_LT(r.slip, 1e-2);
  }
}

// Partially saturated cells on a sphere held rotating at omega in a periodic
// cube of 8a (as RotatingSphere.TorqueMatchesStokes for the immersed
// boundary): the torque from the same blended collision that gives the force
// must be the Stokes value -8 pi mu a^3 omega (periodic images: 0.2 %),
// averaged over a node-centred and a mid-cell sphere as the calibration is.
// Tolerance 5 %, as there: the radius is calibrated for translation, and a
// rotational radius 1.7 % of a different changes a^3 by 5 %. At the paper's
// resolution, a = 6: +3.3 % and +2.5 % measured. (At a = 4 the same
// measurement gives +6.4 % and +4.7 %, a rotational radius 0.07 dx above the
// translational one, beyond this bar, where the immersed boundary's is -4.2 %;
// docs/coupling.md.) About a minute on one core.
double psm_rotating_torque_over_stokes(double a, const Vec3& centre) {
  const int L = static_cast<int>(8 * a);
  const double nu = 1.0 / 6.0;
  const coupling::Scheme scheme = coupling::kPartiallySaturatedScheme;
  const double ag = calibration::CalibrationTable::shipped().input_radius(a, nu, scheme);
  lattice::FluidLattice<double> fluid({L, L, L}, {nu, 0.25});
  auto psm = coupling::make_coupling<double>(scheme, ag);
  spheres::SphereSet s;
  s.radius = a;
  s.resize(1);
  s.position[0] = centre;
  const double omega = 2e-5;  // surface speed 8e-5, Re = 0.002
  s.angular_velocity[0] = Vec3(0, 0, omega);
  double previous = 0, T = 0;
  int step = 0;
  for (; step < 20000; ++step) {
    psm->apply(fluid, s);
    fluid.step();
    psm->after_liquid_step(fluid, s);
    T = psm->torque()[0].z() + psm->internal_angular_momentum_change()[0].z();
    if (step % 200 == 199) {
      if (std::abs(T - previous) < 1e-6 * std::abs(T)) break;
      previous = T;
    }
  }
  const double stokes = -8 * M_PI * nu * a * a * a * omega;
  std::printf(
      "partially saturated cells, rotating sphere a = %g at (%g, %g, %g): T = %.6e after "
      "%d steps, Stokes %.6e (ratio %.4f), |F| a / |T| %.1e\n",
      a, centre.x(), centre.y(), centre.z(), T, step, stokes, T / stokes,
      psm->force()[0].norm() * a / std::abs(T));
  return T / stokes;
}

TEST(PartiallySaturatedCells, RotatingSphereTorqueMatchesStokes) {
  const double node = psm_rotating_torque_over_stokes(6, Vec3(24, 24, 24));
  const double mid = psm_rotating_torque_over_stokes(6, Vec3(24.5, 24.5, 24.5));
  EXPECT_NEAR(0.5 * (node + mid), 1.0, 0.05);
}

}  // namespace
}  // namespace flocsim
