// The coupling schemes (engine/coupling/scheme.hpp) in the coupled time loop
// against conservation laws and exact steady states: the momentum of liquid
// + spheres does not drift with any scheme; control forcing holds a fixed
// sphere with ever less slip at its markers; control forcing goes unstable
// just beyond the gains cases accept (the slow suite runs the lowest
// viscosity for 1e5 steps).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/coupling_schemes/make_coupling.hpp"
#include "engine/immersed_boundary/immersed_boundary.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/spheres/sphere_dynamics.hpp"
#include "tests/coupling/coupling_test_support.hpp"

namespace flocsim {
namespace {

using spheres::Vec3;
using testing_support::momentum_drift;

// Settling spheres with the balancing body force: lattice momentum plus
// sum (m_p u_p - P_in) cannot change (docs/model.md section 1), whatever the
// scheme: each gives the spheres exactly the momentum it took from the
// liquid. Double: round-off over 23 000 cells and 300 steps.
TEST(MomentumBalance, ControlForcingDoesNotDrift) {
  EXPECT_LT(momentum_drift<double>(coupling::kControlScheme), 1e-10);
  EXPECT_LT(momentum_drift<float>(coupling::kControlScheme), 1e-3);
}
TEST(MomentumBalance, PartiallySaturatedCellsDoNotDrift) {
  EXPECT_LT(momentum_drift<double>(coupling::kPartiallySaturatedScheme), 1e-10);
  EXPECT_LT(momentum_drift<float>(coupling::kPartiallySaturatedScheme), 1e-3);
}

// A sphere held in a creeping flow (a_g = 3.5, 16^3, nu = 1/6): the
// integral action keeps removing the slip at the markers, which direct
// forcing with two sweeps leaves standing: after 3000 steps the control slip
// is still falling (below its value at step 1500) and is below a tenth of
// direct forcing's. (At a steady state it vanishes: 1e-8 U after
// 1e5 steps, docs/coupling.md.)
TEST(ControlForcing, HeldSphereKeepsRemovingTheSlipDirectForcingLeaves) {
  const int L = 16;
  const double nu = 1.0 / 6.0, ag = 3.5, U = 1e-3;
  auto held = [&](const coupling::Scheme& scheme) {
    lattice::FluidLattice<float> fluid({L, L, L}, {nu, 0.25});
    immersed_boundary::ImmersedBoundary<float> ib({ag, scheme, true});
    spheres::SphereSet s;
    s.radius = ag;
    s.resize(1);
    s.position[0] = Vec3(8.31, 7.87, 8.12);
    const double f =
        6 * M_PI * nu * ag * calibration::sangani_acrivos_drag(2 * ag / L) * U / (L * L * L);
    fluid.set_body_force({f, 0, 0});
    double half_way = 0;
    for (int n = 1; n <= 3000; ++n) {
      ib.apply(fluid, s);
      fluid.step();
      if (n == 1500) half_way = ib.rms_slip() / U;
    }
    return std::pair{half_way, ib.rms_slip() / U};
  };
  const auto [half_way, slip] = held(coupling::kControlScheme);
  const auto [direct_half_way, direct_slip] = held(coupling::kPaperScheme);
  std::printf("held sphere: control slip %.2e U (%.2e at half way), direct (2 sweeps) %.2e U\n",
              slip, half_way, direct_slip);
  EXPECT_LT(slip, half_way);
  EXPECT_LT(slip, 0.1 * direct_slip);
}

// The edge of the accepted gains (scheme.hpp) is where the loop goes
// unstable: a sphere settling at Re 12 (a_g = 3.5, 20^3, nu = 0.01) with
// integral gain 4 shakes itself apart in a period-2 mode within 300 steps;
// with 3 (the edge of what cases accept) and 2 (the default) it stays bounded.
TEST(ControlForcing, SettlingSphereGoesUnstableJustBeyondTheAcceptedGains) {
  using testing_support::settle_with_control;
  EXPECT_LT(settle_with_control(3.5, 0.01, 20, 300, {4, 0}).steps, 300);
  for (const coupling::ControlGains g : {coupling::ControlGains{3, 0}, {2, 0}, {1, 1}}) {
    const auto r = settle_with_control(3.5, 0.01, 20, 1000, g);
    EXPECT_EQ(r.steps, 1000) << "gains " << g.integral << ", " << g.proportional;
    EXPECT_LT(r.slip, 0.02);
  }
}

// Galilean invariance: a sphere dragged through the liquid and the same
// sphere held with the liquid moving past it feel the same drag. The lattice
// breaks it at O(Ma^2) (5e-4 here) and by where the sphere sits on the grid,
// which the dragged sphere averages over as it crosses the cells: the held
// drag is averaged over a node-aligned and a mid-cell place (shifts 0 and
// 0.5). Within 1 % with every offered scheme. Control forcing is calibrated
// at nu = 0.02 only: its a = 4 radius there (3.5089) serves.
double dragged_over_held(const coupling::Scheme& scheme, double input_radius = 0) {
  const double dragged = testing_support::drag_at_re1(scheme, false, 0, input_radius);
  const double held = 0.5 * (testing_support::drag_at_re1(scheme, true, 0.0, input_radius) +
                             testing_support::drag_at_re1(scheme, true, 0.5, input_radius));
  std::printf("%s: dragged %.4f, held %.4f, dragged / held %.4f\n", scheme.describe().c_str(),
              dragged, held, dragged / held);
  return dragged / held;
}

TEST(GalileanInvariance, DraggedAndHeldSpheresFeelTheSameDrag) {
  for (const coupling::Scheme& scheme :
       {coupling::kPaperScheme, coupling::kOneSweepScheme, coupling::kPartiallySaturatedScheme})
    EXPECT_NEAR(dragged_over_held(scheme), 1.0, 0.01) << scheme.describe();
  EXPECT_NEAR(dragged_over_held(coupling::kControlScheme, 3.5089), 1.0, 0.01);
}

// Why control forcing refuses markers closer than 1 dx: at the paper's
// 0.7 dx a dragged sphere feels 14-22 % less drag than a held one (0.83
// here; 0.78 and 0.85 in bench_coupling_noise at nu 0.1 and 0.02,
// docs/coupling.md), with the gains and kernel that are invariant to 0.4 % at
// 1 dx above.
TEST(ControlForcing, MarkersCloserThanTheLatticeSpacingAreNotGalileanInvariant) {
  coupling::Scheme dense = coupling::kControlScheme;
  dense.marker_spacing = 0.7;
  EXPECT_LT(dragged_over_held(dense, 2.9287), 0.9);
}

}  // namespace
}  // namespace flocsim
