// The close-pair calibration at the paper's viscosities and at a = 6 (slow:
// low viscosities take long to reach a steady flow). docs/contacts.md.
#include "tests/lubrication/close_pair_total.hpp"

namespace flocsim::lubrication {
namespace {

const std::vector<double> kGaps = {0.01, 0.015, 0.03, 0.07, 0.12, 0.2};

TEST(ClosePairSlow, TotalResistanceNearBrennerAtA4PaperViscosity) {
  expect_total_near_brenner(4, 0.02, kGaps);
}

TEST(ClosePairSlow, TotalResistanceNearBrennerAtA4LowViscosity) {
  expect_total_near_brenner(4, 0.013, kGaps);
}

TEST(ClosePairSlow, TotalResistanceNearBrennerAtA6) {
  expect_total_near_brenner(6, 0.03, kGaps);
}

}  // namespace
}  // namespace flocsim::lubrication
