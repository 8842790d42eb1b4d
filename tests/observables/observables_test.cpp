// Observables on configurations with known answers: hand-built clusters across
// periodic boundaries, an ideal gas (g = 1, h = 1), exact sphere-slab volumes,
// hand-worked slip velocity, drag and granular temperature, and batch-means
// errors against the analytic standard error of correlated series.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "engine/observables/aggregates.hpp"
#include "engine/observables/pair_structure.hpp"
#include "engine/observables/suspension_averages.hpp"

namespace flocsim::observables {
namespace {

using spheres::PeriodicBox;
using spheres::Vec3;

TEST(Aggregates, HandBuiltClustersAcrossPeriodicBoundaries) {
  // Box 20^3, bond distance 2.1. A chain of 3 across the x = 0 face
  // (x = 19, 0.9 wrapped -> 20.9, 2.8 wrapped -> 22.8: bonds 1.9 and 1.9),
  // a pair across the z face, a triangle (3 bonds) and 2 singles: N = 10.
  const PeriodicBox box{Vec3(20, 20, 20)};
  const std::vector<Vec3> x = {
      {19.0, 5, 5},   {0.9, 5, 5},   {2.8, 5, 5},                   // chain (ids 0-2)
      {10, 10, 19.5}, {10, 10, 1.0},                                // pair across z (3-4)
      {10, 3, 10},    {12, 3, 10},   {11, 3 + std::sqrt(3.0), 10},  // triangle, sides 2 (5-7)
      {5, 15, 15},    {15, 15, 5}};                                 // singles (8-9)
  const Aggregates a = find_aggregates(x, box, 2.1);
  ASSERT_EQ(a.aggregate_size.size(), 5u);
  EXPECT_EQ(a.aggregate_of[0], a.aggregate_of[2]);
  EXPECT_EQ(a.aggregate_of[3], a.aggregate_of[4]);
  EXPECT_EQ(a.aggregate_of[5], a.aggregate_of[7]);
  EXPECT_NE(a.aggregate_of[0], a.aggregate_of[5]);
  // p(1) = 2/10, p(2) = 2/10, p(3) = 6/10; <n_a> = 0.2 + 0.4 + 1.8 = 2.4
  EXPECT_DOUBLE_EQ(a.size_distribution[1], 0.2);
  EXPECT_DOUBLE_EQ(a.size_distribution[2], 0.2);
  EXPECT_DOUBLE_EQ(a.size_distribution[3], 0.6);
  EXPECT_NEAR(a.mean_size, 2.4, 1e-14);
  // bonds: chain 2 + pair 1 + triangle 3 = 6; C_sph = 2 * 6 / 10
  EXPECT_NEAR(a.contacts_per_sphere, 1.2, 1e-14);
}

TEST(Aggregates, AllSinglesGiveMeanSizeOne) {
  const PeriodicBox box{Vec3(30, 30, 30)};
  const std::vector<Vec3> x = {{1, 1, 1}, {10, 10, 10}, {20, 20, 20}};
  const Aggregates a = find_aggregates(x, box, 2.1);
  EXPECT_DOUBLE_EQ(a.mean_size, 1.0);
  EXPECT_DOUBLE_EQ(a.contacts_per_sphere, 0.0);
}

// Uniform random centres without exclusion: an ideal gas.
std::vector<Vec3> ideal_gas(int n, const PeriodicBox& box, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> x(static_cast<std::size_t>(n));
  for (auto& p : x)
    p = Vec3(u(rng) * box.length.x(), u(rng) * box.length.y(), u(rng) * box.length.z());
  return x;
}

TEST(PairStructure, IdealGasHasFlatRadialAndAngularDistributions) {
  // g(r) = 1 and h(theta) = 1 up to counting noise: each bin must lie within
  // 4 standard deviations (Poisson, 1/sqrt(expected count)) of 1.
  const PeriodicBox box{Vec3(24, 12, 12)};
  const int n = 400, configurations = 200;
  const double dr = 0.25, dtheta = M_PI / 60;
  PairStructure s(5.5, dr, 3.0, dtheta);
  std::mt19937 rng(42);
  for (int c = 0; c < configurations; ++c) s.add_configuration(ideal_gas(n, box, rng), box);
  const auto g = s.radial_distribution();
  const auto r = s.radial_bin_centres();
  const double density = (n - 1) / box.volume();
  for (std::size_t b = 1; b < g.size(); ++b) {  // first bin holds too few pairs to test
    const double r0 = b * dr, r1 = r0 + dr;
    const double expected =
        configurations * n * density * 4.0 / 3.0 * M_PI * (r1 * r1 * r1 - r0 * r0 * r0);
    // each pair enters twice: relative error 1/sqrt(expected / 2)
    EXPECT_NEAR(g[b], 1.0, 4.0 / std::sqrt(expected / 2)) << "r = " << r[b];
  }
  const auto h = s.angular_distribution();
  ASSERT_EQ(h.size(), 60u);
  const double pairs = configurations * n * density * 4.0 / 3.0 * M_PI * 27.0 / 2;
  for (std::size_t b = 0; b < h.size(); ++b) {
    const double fraction = 0.5 * (std::cos(b * dtheta) - std::cos((b + 1) * dtheta));
    EXPECT_NEAR(h[b], 1.0, 4.0 / std::sqrt(pairs * fraction)) << "theta bin " << b;
  }
}

TEST(PairStructure, AngleIsMeasuredFromTheGravityAxis) {
  // one pair aligned with x: all weight in the first and last theta bins
  const PeriodicBox box{Vec3(20, 20, 20)};
  PairStructure s(4.0, 0.5, 3.0, M_PI / 60);
  s.add_configuration({{5, 5, 5}, {7.5, 5, 5}}, box);
  const auto h = s.angular_distribution();
  EXPECT_GT(h.front(), 0.0);
  EXPECT_GT(h.back(), 0.0);
  for (std::size_t b = 1; b + 1 < h.size(); ++b) EXPECT_EQ(h[b], 0.0);
}

TEST(SlabSolidsFraction, ExactVolumesAndConservation) {
  // A sphere of radius 2 centred at x = 5 in slabs of width 2 (box 10 x 4 x 5):
  // the slab [4, 6) holds the central section, volume pi (a^2 t - t^3/3) from
  // t = -1 to 1 = pi (8 - 2/3) = 22 pi / 3; slabs [2,4) and [6,8) the caps,
  // each (32 pi / 3 - 22 pi / 3) / 2 = 5 pi / 3.
  const PeriodicBox box{Vec3(10, 4, 5)};
  const double slab_volume = 2 * 4 * 5;
  auto phi = slab_solids_fraction({{5, 2, 2}}, 2.0, box, 5);
  EXPECT_NEAR(phi[2], 22 * M_PI / 3 / slab_volume, 1e-14);
  EXPECT_NEAR(phi[1], 5 * M_PI / 3 / slab_volume, 1e-14);
  EXPECT_NEAR(phi[3], 5 * M_PI / 3 / slab_volume, 1e-14);
  EXPECT_EQ(phi[0], 0.0);
  // across the periodic boundary: same numbers, shifted
  phi = slab_solids_fraction({{9.5, 2, 2}}, 2.0, box, 10);
  double total = 0;
  for (double p : phi) total += p * slab_volume / 2;
  EXPECT_NEAR(total, 32 * M_PI / 3, 1e-12);
  EXPECT_GT(phi[0], 0.0);
  // random configuration: the slab average is the overall solids fraction
  std::mt19937 rng(3);
  const PeriodicBox big{Vec3(48, 24, 24)};
  const auto x = ideal_gas(50, big, rng);
  const auto p48 = slab_solids_fraction(x, 3.0, big, 48);
  double mean = 0;
  for (double p : p48) mean += p / 48;
  EXPECT_NEAR(mean, 50 * 4.0 / 3.0 * M_PI * 27 / big.volume(), 1e-13);
}

TEST(SuspensionAverages, SlipVelocityDragAndGranularTemperatureByHand) {
  // U = (1 - phi)(<u> - <u_p>) = 0.8 * (0.01 + 0.04) = 0.04
  EXPECT_NEAR(superficial_slip_velocity(0.01, -0.04, 0.2), 0.04, 1e-15);
  // F = f (4/3) pi a^3 (1/phi - 1) / (6 pi a nu U)
  //   = 1e-5 * 4/3 * 216 * 4 / (6 * 6 * 0.01 * 0.04) = 0.8
  EXPECT_NEAR(dimensionless_drag(1e-5, 6.0, 0.2, 0.01, 0.04), 0.8, 1e-13);
  // velocities +-(1, 0, 0) about a mean of (0, 2, 0): |du|^2 = 1 each -> T = 1/3
  EXPECT_NEAR(granular_temperature({{1, 2, 0}, {-1, 2, 0}}), 1.0 / 3.0, 1e-15);
}

// AR(1) series x_k = rho x_{k-1} + sqrt(1 - rho^2) e_k with unit variance:
// the standard error of the mean of n samples is sqrt((1 + rho)/(1 - rho) / n).
std::vector<double> ar1(long n, double rho, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> e(0.0, 1.0);
  std::vector<double> x(static_cast<std::size_t>(n));
  double v = e(rng);
  for (auto& s : x) s = v = rho * v + std::sqrt(1 - rho * rho) * e(rng);
  return x;
}

TEST(BatchMeans, ErrorMatchesAnalyticStandardErrorOfCorrelatedSeries) {
  // 20 batches: the error estimate itself scatters by 1/sqrt(2 * 19) = 16 %;
  // averaging the ratio over 10 series brings that to 5 %, so 15 % is 3 sigma.
  for (double rho : {0.0, 0.9}) {
    const long n = 200000;
    const double analytic = std::sqrt((1 + rho) / (1 - rho) / n);
    double ratio = 0;
    for (unsigned seed = 1; seed <= 10; ++seed)
      ratio += batch_means(ar1(n, rho, seed), 20).error / analytic / 10;
    EXPECT_NEAR(ratio, 1.0, 0.15) << "rho = " << rho;
  }
}

TEST(SteadyAverage, BatchesSpanFiveCorrelationTimesAndGiveTheAnalyticError) {
  // AR(1) with rho = 0.9: tau = (1 + rho)/(1 - rho) = 19 samples. With 20,000
  // samples, 10 batches of 2,000 samples (105 tau) fit: the error must match
  // the analytic sqrt(tau / n) (scatter 1/sqrt(2 * 9) = 24 % per series, 7.5 %
  // averaged over 10 series, so 25 % is over 3 sigma) and be flagged reliable.
  const long n = 20000;
  const double tau = (1 + 0.9) / (1 - 0.9);
  double ratio = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const SteadyAverage a = steady_average(ar1(n, 0.9, seed));
    EXPECT_EQ(a.batches, 10);
    EXPECT_TRUE(a.error_reliable);
    ratio += a.error / std::sqrt(tau / n) / 10;
  }
  EXPECT_NEAR(ratio, 1.0, 0.25);
  // 800 samples (42 tau, like a 400 a/U_inf window with a 10 a/U_inf
  // correlation time sampled every 0.5): each batch holds n / batches >= 5
  // measured tau samples (the measured tau of so short a series reads 15-20 %
  // low, so the batches usually number 9-10 rather than 8)
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const auto x = ar1(800, 0.9, seed);
    const SteadyAverage a = steady_average(x);
    ASSERT_GE(a.batches, 2) << seed;
    EXPECT_GE(static_cast<double>(800 / a.batches), 5 * a.correlation_samples) << seed;
    EXPECT_EQ(a.error_reliable, a.batches >= 5) << seed;
  }
}

TEST(SteadyAverage, AWindowShorterThanTwoBatchesFallsBackToTheCorrelationTime) {
  // One slow swing across the window, x_k = cos(pi k / n) plus AR(1) noise of
  // a tenth of its amplitude: the autocorrelation stays positive to about lag
  // n / 2, so tau is of order n / 4 and two batches of 5 tau cannot fit. No
  // batch-means error then: the error is the sample standard deviation times
  // sqrt(tau / n) with the measured tau, recomputed here by hand, flagged
  // unreliable.
  const long n = 600;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    auto x = ar1(n, 0.5, seed);
    for (long k = 0; k < n; ++k) x[k] = std::cos(M_PI * k / n) + 0.1 * x[k];
    const SteadyAverage a = steady_average(x);
    EXPECT_GT(a.correlation_samples, n / 10.0) << seed;
    EXPECT_EQ(a.batches, 0) << seed;
    EXPECT_FALSE(a.error_reliable) << seed;
    double mean = 0, var = 0;
    for (double v : x) mean += v / n;
    for (double v : x) var += (v - mean) * (v - mean) / (n - 1);
    EXPECT_NEAR(a.mean, mean, 1e-12) << seed;
    EXPECT_NEAR(a.error, std::sqrt(var * a.correlation_samples / n), 1e-12) << seed;
  }
  // white noise: tau ~ 1, so the 10 batches of the cap fit and the error is
  // sigma / sqrt(n) = 0.01: 24 % scatter per series over 10 batches, 7.5 %
  // averaged over 10 series, so 25 % is over 3 sigma
  double white = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const SteadyAverage w = steady_average(ar1(10000, 0.0, seed));
    EXPECT_EQ(w.batches, 10) << seed;
    white += w.error / 0.01 / 10;
  }
  EXPECT_NEAR(white, 1.0, 0.25);
  // a non-finite sample leaves no average
  std::vector<double> broken = ar1(100, 0.0, 1);
  broken[50] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(std::isnan(steady_average(broken).error));
}

TEST(Stationarity, DetectsTheEndOfAnExponentialRelaxation) {
  // x(t) = exp(-t / 1000) + noise 0.01: with windows of 500 samples the drift
  // between windows (~exp(-t/1000) * 0.4) exceeds 2 standard errors (~1e-3)
  // until t ~ 6000; by t = 12000 it is far below.
  std::mt19937 rng(9);
  std::normal_distribution<double> e(0.0, 0.01);
  std::vector<double> x;
  for (int t = 0; t < 3000; ++t) x.push_back(std::exp(-t / 1000.0) + e(rng));
  EXPECT_FALSE(is_stationary(x, 500));
  for (int t = 3000; t < 12000; ++t) x.push_back(std::exp(-t / 1000.0) + e(rng));
  EXPECT_TRUE(is_stationary(x, 500));
  EXPECT_FALSE(is_stationary(std::vector<double>(600, 1.0), 500));  // too short to judge
}

TEST(WindowDrift, AcceptsStationaryAr1AndRejectsASlowDrift) {
  // AR(1) with rho = 0.9 (tau = 19 samples), 20,000 samples: by hand the
  // standard error of the change over the window is sqrt(12 tau / n) = 0.107
  // noise units, so a drift of one noise standard deviation over the window
  // (which moves the mean by 0.5 where the batch-means error is about 0.03)
  // gives z ~ 9, and no drift gives |z| <= 3 but for 0.3 % of series.
  const long n = 20000;
  int accepted = 0, rejected = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const std::vector<double> still = ar1(n, 0.9, seed);
    accepted += window_drift(still).stationary;
    std::vector<double> drifting = still;
    for (long k = 0; k < n; ++k) drifting[k] += static_cast<double>(k) / (n - 1);
    const Drift d = window_drift(drifting);
    rejected += !d.stationary;
    EXPECT_NEAR(d.change, 1.0, 4 * 0.107) << seed;  // the trend is measured, within 4 se
  }
  EXPECT_EQ(accepted, 20);
  EXPECT_EQ(rejected, 20);
  // a rising but saturating series (an aggregate size still growing) is a trend
  std::vector<double> rising(4000);
  for (std::size_t k = 0; k < rising.size(); ++k)
    rising[k] = 10 * (1 - std::exp(-static_cast<double>(k) / 4000.0)) + 0.3 * ar1(4000, 0.5, 3)[k];
  EXPECT_FALSE(window_drift(rising).stationary);
  // a deterministic flow converging by 5e-8 of its mean (a fixed array's drag,
  // float: no noise, so z is huge) is steady; the same shape at 1e-3 is not
  std::vector<double> settled(20), converging(20);
  for (std::size_t k = 0; k < settled.size(); ++k) {
    settled[k] = 4.56 * (1 - 5e-8 * static_cast<double>(k) / 19);
    converging[k] = 4.56 * (1 - 1e-3 * static_cast<double>(k) / 19);
  }
  EXPECT_TRUE(window_drift(settled).stationary);
  EXPECT_GT(std::abs(window_drift(settled).z), 3.0);
  EXPECT_FALSE(window_drift(converging).stationary);
  // the floor is relative to |mean|: the same with the sign flipped; a series
  // about zero has no floor, so its drift is judged by z alone; NaN is no steady state
  for (auto& x : settled) x = -x;
  for (auto& x : converging) x = -x;
  EXPECT_TRUE(window_drift(settled).stationary);
  EXPECT_FALSE(window_drift(converging).stationary);
  std::vector<double> about_zero(20);
  for (std::size_t k = 0; k < about_zero.size(); ++k)
    about_zero[k] = 1e-9 * (static_cast<double>(k) - 9.5);
  EXPECT_FALSE(window_drift(about_zero).stationary);
  settled[7] = std::nan("");
  EXPECT_FALSE(window_drift(settled).stationary);
}

}  // namespace
}  // namespace flocsim::observables
