// Square-well gas, default size: energy bookkeeping and escape statistics
// (the reference is derived in square_well_gas.hpp).
#include "tests/events/square_well_gas.hpp"

#include <gtest/gtest.h>

namespace flocsim::events {
namespace {

using namespace testing_gas;

// Tolerances. Energy: linear accumulation of one rounding per event bounds
// the drift by events * 2.2e-16 (relative). Escape fraction: the
// microcanonical gas of N spheres differs from the canonical reference by
// O(1/N) (~0.2 % at N = 500), kT is measured to ~0.1 %; 3 % relative leaves
// room for ~4 batch-means standard errors (printed, and required below 0.6 %).
TEST(SquareWellGas, EnergyBookkeepingAndEscapeFractionMatchBoltzmannFactor) {
  const GasFigures r = run_square_well_gas(1.0, 5, 0.2, 8000);
  EXPECT_LT(r.energy_drift, r.energy_bound);
  EXPECT_LT(r.worst_overlap, 1e-12);
  EXPECT_GT(r.arrivals, 100000u);
  EXPECT_LT(r.standard_error / r.boltzmann, 0.006);
  EXPECT_NEAR(r.escape_fraction / r.boltzmann, 1.0, 0.03);
}

}  // namespace
}  // namespace flocsim::events
