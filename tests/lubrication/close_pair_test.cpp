// The shipped close-pair calibration at work: lattice + correction against
// Brenner within 15 % for s/a from 0.01 to 0.2 (docs/contacts.md). Gaps and
// viscosities lie between the calibrated ones, so interpolation is tested too.
#include "tests/lubrication/close_pair_total.hpp"

namespace flocsim::lubrication {
namespace {

TEST(ClosePair, TotalResistanceNearBrennerAtA4) {
  expect_total_near_brenner(4, 0.1, {0.01, 0.04, 0.15});
}

}  // namespace
}  // namespace flocsim::lubrication
