// Long checks of the coupling schemes (label slow).
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/coupling/coupling_test_support.hpp"

namespace flocsim {
namespace {

// Control forcing at the lowest viscosity it is offered at (a = 6:
// nu = 0.005), a sphere settling at Re 12 for 1e5 steps with the default
// gains and at the two edges of the accepted region (integral 3; integral 1
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

}  // namespace
}  // namespace flocsim
