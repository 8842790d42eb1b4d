// The cell-list pair search against the all-pairs loop (the definition):
// same pairs, and the recorded shift gives the minimum-image separation.
#include "engine/neighbours/pair_search.hpp"

#include <gtest/gtest.h>

#include <random>
#include <set>

namespace flocsim::neighbours {
namespace {

TEST(PairSearch, CellListFindsExactlyThePairsOfTheAllPairsLoop) {
  std::mt19937_64 rng(5);
  const PeriodicBox box{Vec3(96, 48, 60)};
  std::vector<Vec3> x(3000);
  for (auto& p : x)
    for (int k = 0; k < 3; ++k)
      p[k] = std::uniform_real_distribution<double>(0, box.length[k])(rng);
  for (double cutoff : {4.0, 12.3, 15.9}) {
    std::set<std::pair<int, int>> want;
    for (int i = 0; i < static_cast<int>(x.size()); ++i)
      for (int j = i + 1; j < static_cast<int>(x.size()); ++j)
        if (box.minimum_image(x[j] - x[i]).norm() < cutoff) want.insert({i, j});
    std::set<std::pair<int, int>> got;
    for (const auto& p : pairs_within(x, box, cutoff)) {
      got.insert({p.i, p.j});
      const Vec3 r = x[p.j] - x[p.i] + p.shift;
      EXPECT_NEAR((r - box.minimum_image(x[p.j] - x[p.i])).norm(), 0.0, 1e-12);
    }
    EXPECT_EQ(got, want) << "cutoff " << cutoff;
  }
  EXPECT_THROW(pairs_within(x, box, 30.0), std::invalid_argument);
}

}  // namespace
}  // namespace flocsim::neighbours
