// Immersed-boundary spheres against independent references: conservation of
// the momentum of liquid + spheres (docs/model.md section 1), Sangani & Acrivos drag of
// simple cubic arrays with the calibrated radius, the terminal velocity of a
// sphere settling in creeping flow with the periodic hindrance, and the Stokes
// torque on a rotating sphere.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/immersed_boundary/immersed_boundary.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/spheres/sphere_dynamics.hpp"
#include "ib_test_support.hpp"

namespace flocsim {
namespace {

using spheres::Vec3;

template <class Real>
double force_field_sum(const lattice::FluidLattice<Real>& fluid) {
  double s = 0;
  for (long c = 0; c < fluid.extent().cells(); ++c) s += fluid.force_field_if_set().component[0][c];
  return s;
}

// One step of the coupled time loop for free spheres without contacts: the
// immersed boundary, the liquid, then the spheres' velocities and positions.
template <class Real>
void coupled_step(lattice::FluidLattice<Real>& fluid, immersed_boundary::ImmersedBoundary<Real>& ib,
                  spheres::SphereSet& s, const spheres::SphereDynamicsSettings& dyn,
                  const spheres::PeriodicBox& box) {
  ib.apply(fluid, s);
  fluid.step();
  spheres::advance_velocities(s,
                              {ib.force(), ib.torque(), ib.internal_momentum_change(),
                               ib.internal_angular_momentum_change()},
                              dyn);
  spheres::advance_positions(s, box);
}

// Settling spheres with the balancing body force: the lattice momentum (the
// raw sum of c_i f_i, i.e. without the half-force shift of the force just
// applied) plus sum (m_p u_p - P_in) cannot change (docs/model.md section 1; P_in the
// momentum of the liquid inside the spheres, which the lattice already holds,
// sphere_dynamics.hpp). Three spheres, density ratio 4, 600 steps. With the
// rigid-body inside liquid the sphere is moved by H / (m_p - rho V_p) and
// the lattice by -H, so lattice momentum + sum (m_p - rho V_p) u_p is the
// conserved sum instead.
template <class Real>
void momentum_balance(double tolerance, const coupling::Scheme& scheme = {},
                      bool rigid_inside_liquid = false) {
  const lattice::Extent e{40, 24, 24};
  lattice::FluidLattice<Real> fluid(e, {0.1, 0.25});
  immersed_boundary::ImmersedBoundary<Real> ib({.input_radius = 3.6, .scheme = scheme});
  spheres::SphereSet s;
  s.radius = 4.0;
  s.density_ratio = 4.0;
  s.position = {{8.3, 6.1, 12.0}, {21.7, 17.9, 5.2}, {33.0, 11.4, 18.6}};
  s.velocity.assign(3, Vec3::Zero());
  s.angular_velocity.assign(3, Vec3::Zero());
  const spheres::PeriodicBox box{Vec3(e.nx, e.ny, e.nz)};
  spheres::SphereDynamicsSettings dyn;
  dyn.external = spheres::settling_forces(s.size(), s.radius, s.density_ratio, box.volume(), 5e-5);
  dyn.rigid_inside_liquid = rigid_inside_liquid;
  fluid.set_body_force({dyn.external.liquid_body_force.x(), 0, 0});
  const double inside_mass = s.volume();  // liquid density 1
  double drift = 0, scale = 0, initial = 0;
  for (int step = 0; step < 600; ++step) {
    coupled_step(fluid, ib, s, dyn, box);
    if (step % 50 != 0 && step != 599) continue;
    // Lattice momentum read with half of the force of this step; remove it.
    const double applied =
        dyn.external.liquid_body_force.x() * box.volume() + force_field_sum(fluid);
    double inside = 0;
    if (rigid_inside_liquid)
      for (const Vec3& u : s.velocity) inside += inside_mass * u.x();
    else
      for (const Vec3& p : ib.internal_momentum()) inside += p.x();
    const double total =
        fluid.total_momentum().x - 0.5 * applied + spheres::sphere_momentum(s).x() - inside;
    if (step == 0) initial = total;  // the liquid inside starts with momentum 0 too: initial = 0
    drift = std::max(drift, std::abs(total - initial));
    scale = std::max(scale, std::abs(spheres::sphere_momentum(s).x()));
  }
  // The spheres really settled (the test is not trivially satisfied).
  EXPECT_LT(s.velocity[0].x(), -1e-3);
  std::printf(
      "momentum balance (%s, %s%s): max |P_total| = %.3e, sphere momentum %.3e, ratio %.3e\n",
      sizeof(Real) == 8 ? "double" : "float", scheme.describe().c_str(),
      rigid_inside_liquid ? ", rigid-body inside liquid" : "", drift, scale, drift / scale);
  EXPECT_LT(drift / scale, tolerance);
}

// Double: round-off of sums over 23 000 cells and 600 steps, ~1e-13.
TEST(MomentumBalance, SettlingSpheresDoNotDrift_Double) {
  momentum_balance<double>(1e-10);
}
// Float: the populations and force field are stored in single precision
// (relative round-off 6e-8 per operation, accumulated over 600 steps).
TEST(MomentumBalance, SettlingSpheresDoNotDrift_Float) {
  momentum_balance<float>(1e-3);
}
TEST(MomentumBalance, RigidBodyInsideLiquidConservesItsOwnSum) {
  momentum_balance<double>(1e-10, {}, true);
}
// A kick in a closed box: a sphere (density ratio 4) given u_p = v0 in liquid
// at rest, no gravity, comes to rest with the liquid at one common velocity.
// The real sphere owns m_p v0, shared with the liquid outside it:
// V = m_p v0 / (m_p + rho (V_box - V_p)). The rigid-body form counts its
// inside liquid as moving with it, so only (m_p - rho V_p) v0 is shared:
// V = (m_p - rho V_p) v0 / (m_p - rho V_p + rho V_box), 3/4 of the first
// here: that form keeps 1 - rho/rho_p of any sudden change of u_p (a
// collision, a square-well event). The kick comes after 20 steps at rest, as
// an event does in a run (the measured form needs a previous step to measure
// the inside momentum's change from). Box 24^3, nu 0.1: the slowest mode
// decays in L^2 / (4 pi^2 nu) = 146 steps; 1500 steps. Tolerance: 1e-3 for the
// rigid-body form (exact); 1 % for the measured one, whose inside liquid is
// summed within the marker radius a_g = 3.6, not a = 4 (0.5 % of V here).
void kicked_sphere(bool rigid_inside_liquid) {
  const int L = 24;
  lattice::FluidLattice<double> fluid({L, L, L}, {0.1, 0.25});
  immersed_boundary::ImmersedBoundary<double> ib({.input_radius = 3.6});
  spheres::SphereSet s;
  s.radius = 4.0;
  s.density_ratio = 4.0;
  s.resize(1);
  s.position[0] = Vec3(11.3, 12.2, 11.9);
  const double v0 = 1e-3;
  const spheres::PeriodicBox box{Vec3(L, L, L)};
  spheres::SphereDynamicsSettings dyn;
  dyn.external = spheres::settling_forces(1, s.radius, s.density_ratio, box.volume(), 0.0);
  dyn.rigid_inside_liquid = rigid_inside_liquid;
  for (int step = 0; step < 1500; ++step) {
    if (step == 20) s.velocity[0] = Vec3(v0, 0, 0);
    coupled_step(fluid, ib, s, dyn, box);
  }
  const double mp = s.mass(), vp = s.volume(), vbox = box.volume();
  const double expected =
      rigid_inside_liquid ? (mp - vp) * v0 / (mp - vp + vbox) : mp * v0 / (mp + vbox - vp);
  std::printf("kicked sphere (%s inside liquid): u_p = %.6e, expected %.6e (%+.3f %%)\n",
              rigid_inside_liquid ? "rigid-body" : "measured", s.velocity[0].x(), expected,
              100 * (s.velocity[0].x() / expected - 1));
  EXPECT_NEAR(s.velocity[0].x() / expected, 1.0, rigid_inside_liquid ? 1e-3 : 1e-2);
}

TEST(KickedSphere, SharesItsMomentumWithTheLiquidOutside) {
  kicked_sphere(false);
}
TEST(KickedSphere, RigidBodyInsideLiquidKeepsThreeQuartersOfTheKick) {
  kicked_sphere(true);
}

// The other immersed-boundary options spread exactly the reaction of the
// forces they apply, whatever the kernel or the number of sweeps.
TEST(MomentumBalance, EveryKernelAndSweepCountConserves) {
  using coupling::Kernel;
  for (const coupling::Scheme& scheme :
       {coupling::Scheme{1.0, 1, Kernel::roma3}, coupling::Scheme{1.0, 1, Kernel::linear2},
        coupling::Scheme{0.7, 2, Kernel::linear2}})
    momentum_balance<double>(1e-10, scheme);
}

// Simple cubic arrays at a = 6 dx with the calibrated input radius: K within
// 2 % of Sangani & Acrivos (the accuracy asked of the calibrated IB) at phi = 0.18 and 0.10.
// The calibration fits one a over chi = 0.35 - 0.7; this checks the fit at
// box sizes it did not use.
void array_drag(double a, int L) {
  calibration::ArrayDragSettings s;
  const double ag = test::calibrated_input_radius(a, s.viscosity);
  const auto r = calibration::simple_cubic_array_drag(ag, L, s);
  const double chi = 2 * a / L;
  const double K = r.drag_coefficient(a, s.viscosity);
  const double K_ref = calibration::sangani_acrivos_drag(chi);
  std::printf(
      "simple cubic array a = %g (a_g = %.4f), L = %d, phi = %.4f: K = %.4f, Sangani-Acrivos %.4f, "
      "error %+.2f %%\n",
      a, ag, L, M_PI / 6 * chi * chi * chi, K, K_ref, 100 * (K / K_ref - 1));
  EXPECT_NEAR(K / K_ref, 1.0, 0.02);
  // Steady state: the sphere holds the whole body force, f L^3.
  EXPECT_NEAR(r.ib_force / (r.body_force * L * L * L), 1.0, 1e-4);
}

TEST(SimpleCubicArray, DragMatchesSanganiAcrivos_a6_phi018) {
  array_drag(6.0, 17);
}
TEST(SimpleCubicArray, DragMatchesSanganiAcrivos_a6_phi010) {
  array_drag(6.0, 21);
}

// A sphere (density ratio 4) settling from rest in a periodic cube, Re = 0.01.
// Settling is a fixed array seen from the sphere: the liquid body force f
// drives a superficial slip U = f L^3 / (6 pi mu a K(chi)) (Sangani & Acrivos),
// and zero total momentum gives the sphere's own velocity u_p = -U rho / rho_bar.
// Tolerance 2 %: the calibration accuracy (K within 2 %).
// rigid_inside_liquid: the rigid-body approximation of the inside liquid
// instead of its measured momentum; the steady state must be the same.
void creeping_settling(double a, int L, Vec3 start, int steps, bool rigid_inside_liquid = false) {
  const double nu = 1.0 / 6.0;
  const double ag = test::calibrated_input_radius(a, nu);
  lattice::FluidLattice<double> fluid({L, L, L}, {nu, 0.25});
  immersed_boundary::ImmersedBoundary<double> ib({.input_radius = ag});
  spheres::SphereSet s;
  s.radius = a;
  s.density_ratio = 4.0;
  s.resize(1);
  s.position[0] = start;
  const spheres::PeriodicBox box{Vec3(L, L, L)};
  const double V = box.volume(), phi = s.volume() / V;
  const double rho_bar = phi * s.density_ratio + 1 - phi;
  // Slip U with Re = 2 a U / nu = 0.01.
  const double chi = 2 * a / L, K = calibration::sangani_acrivos_drag(chi);
  const double U = 0.01 * nu / (2 * a), f = 6 * M_PI * nu * a * K * U / V;
  const double g = f / (rho_bar - 1.0);
  spheres::SphereDynamicsSettings dyn;
  dyn.external = spheres::settling_forces(1, a, s.density_ratio, V, g);
  dyn.rigid_inside_liquid = rigid_inside_liquid;
  ASSERT_NEAR(dyn.external.liquid_body_force.x(), f, 1e-15);
  fluid.set_body_force({f, 0, 0});
  const double expected = -U / rho_bar;
  // Steady after half the steps (see the callers); average the second half
  // (the drag varies slightly as the sphere moves over the lattice).
  double mean = 0;
  for (int step = 0; step < steps; ++step) {
    coupled_step(fluid, ib, s, dyn, box);
    if (step >= steps / 2) mean += s.velocity[0].x() / (steps - steps / 2);
  }
  std::printf(
      "creeping settling a = %g, L = %d (chi = %.3f): u_p = %.6e, expected %.6e (error %+.2f %%)\n",
      a, L, chi, mean, expected, 100 * (mean / expected - 1));
  EXPECT_NEAR(mean / expected, 1.0, 0.02);
  EXPECT_LT(s.velocity[0].tail<2>().norm(), 1e-3 * std::abs(expected));
}

// a = 4, L = 24: velocity relaxation time m_p / (6 pi mu a K) = 270 steps,
// momentum diffusion across the box L^2 / (4 pi^2 nu) = 90 steps: steady after
// 2000 steps.
TEST(SettlingSphere, CreepingTerminalVelocityWithPeriodicHindrance) {
  creeping_settling(4.0, 24, Vec3(10.3, 12.1, 11.8), 4000);
}

// The rigid-body inside liquid (a comparison option) only changes how the
// sphere accelerates, not where it ends: the same Sangani-Acrivos velocity.
TEST(SettlingSphere, CreepingTerminalVelocityWithRigidBodyInsideLiquid) {
  creeping_settling(4.0, 24, Vec3(10.3, 12.1, 11.8), 4000, true);
}

// The paper's resolution, a = 6 at the same chi = 1/3: times scale with a^2,
// so steady after 4500 steps.
TEST(SettlingSphere, CreepingTerminalVelocityWithPeriodicHindrance_a6) {
  creeping_settling(6.0, 36, Vec3(15.4, 18.2, 17.7), 9000);
}

// A sphere held rotating at omega in a large periodic cube: the torque must be
// the Stokes value -8 pi mu a^3 omega. The periodic images change it by
// O((a/L)^3) = 0.2 % here. Tolerance 5 %: the radius is calibrated for
// translation; a rotational radius that differs by 0.07 dx (1.7 % of a)
// changes a^3 by 5 %.
TEST(RotatingSphere, TorqueMatchesStokes) {
  const int L = 32;
  const double a = 4.0, nu = 1.0 / 6.0;
  const double ag = test::calibrated_input_radius(a, nu);
  lattice::FluidLattice<double> fluid({L, L, L}, {nu, 0.25});
  immersed_boundary::ImmersedBoundary<double> ib({.input_radius = ag});
  spheres::SphereSet s;
  s.radius = a;
  s.resize(1);
  s.position[0] = Vec3(15.7, 16.2, 16.0);
  const double omega = 2e-5;  // surface speed 8e-5, Re = 0.002
  s.angular_velocity[0] = Vec3(0, 0, omega);
  double previous = 0, T = 0;
  int step = 0;
  for (; step < 20000; ++step) {
    ib.apply(fluid, s);
    fluid.step();
    T = ib.torque()[0].z();
    if (step % 200 == 199) {
      if (std::abs(T - previous) < 1e-6 * std::abs(T)) break;
      previous = T;
    }
  }
  const double stokes = -8 * M_PI * nu * a * a * a * omega;
  std::printf(
      "rotating sphere a = %g: T = %.6e after %d steps, Stokes %.6e (ratio %.4f, a_rot = %.4f)\n",
      a, T, step, stokes, T / stokes, std::cbrt(T / (-8 * M_PI * nu * omega)));
  EXPECT_NEAR(T / stokes, 1.0, 0.05);
  EXPECT_LT(ib.force()[0].norm(), 1e-3 * std::abs(stokes) / a);
}

}  // namespace
}  // namespace flocsim
