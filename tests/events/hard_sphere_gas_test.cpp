// An elastic hard-sphere gas without fluid (e = 1, mu_f = 0, no wells):
// docs/model.md section 5 asks for kinetic energy and momentum conserved to round-off
// over millions of events, no overlaps, and the collision rate of kinetic
// theory for a dense gas.
//
// Reference (Enskog; exact in equilibrium given the contact value of the pair
// distribution): collisions per sphere per unit time
//   Gamma = 4 n sigma^2 g(sigma) sqrt(pi k T / m),   sigma = 2a,
// with the Carnahan-Starling contact value g(sigma) = (1 - phi/2) / (1 - phi)^3.
// At phi = 0.3 Carnahan-Starling matches the simulated hard-sphere equation of
// state to ~0.05 % (Kolafa et al. 2004), so the reference is that good.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "engine/events/direct_interactions.hpp"
#include "engine/observables/aggregates.hpp"
#include "tests/events/gas_support.hpp"

namespace flocsim::events {
namespace {

using namespace testing_gas;

TEST(HardSphereGas, ConservesEnergyAndMomentumAndMatchesEnskogCollisionRate) {
  const double phi = 0.3, a = 1.0, dt = 0.05;
  Gas g = fcc_gas(6, a, phi, 2024);  // 864 spheres
  SphereSet& s = g.spheres;
  const int n = static_cast<int>(s.size());
  const double energy0 = kinetic_energy(s);
  const double momentum_scale = s.mass() * std::sqrt(2 * energy0 / s.mass());  // sqrt(2 m E)
  DirectInteractions contacts;

  // Melt the lattice: ~40 collisions per sphere forget the fcc start.
  while (contacts.counters().collisions < 20u * n) contacts.advance(s, g.box, dt);

  // Measure over at least 10^6 collisions, checking for overlaps as we go.
  const std::uint64_t start = contacts.counters().collisions;
  double time = 0, min_distance = std::numeric_limits<double>::infinity();
  int steps = 0;
  std::vector<double> batch_rates;
  std::uint64_t batch_start = start;
  double batch_time = 0;
  while (contacts.counters().collisions - start < 1'000'000u) {
    contacts.advance(s, g.box, dt);
    time += dt;
    batch_time += dt;
    if (++steps % 500 == 0) {
      min_distance = std::min(min_distance, closest_pair(s, g.box));
      batch_rates.push_back((contacts.counters().collisions - batch_start) / batch_time);
      batch_start = contacts.counters().collisions;
      batch_time = 0;
    }
  }
  const std::uint64_t collisions = contacts.counters().collisions - start;
  const std::uint64_t all_events = contacts.counters().events();

  // Round-off: each collision rounds the velocities of two spheres with
  // relative error ~1e-16; a linear (worst-case) accumulation over all events
  // bounds the drift by events * 2.2e-16.
  const double energy_bound = static_cast<double>(all_events) * 2.2e-16;
  const double energy_drift = std::abs(kinetic_energy(s) / energy0 - 1);
  EXPECT_LT(energy_drift, energy_bound);
  EXPECT_LT(momentum(s).norm() / momentum_scale, energy_bound);
  EXPECT_GE(min_distance, 2 * a * (1 - 1e-12));
  EXPECT_LE(contacts.worst_overlap(), 1e-12 * a);

  // Temperature with the 3N - 3 degrees of freedom left by zero momentum.
  const double kT_over_m = 2 * kinetic_energy(s) / (3.0 * n - 3) / s.mass();
  const double density = n / g.box.volume(), sigma = 2 * a;
  const double contact_value = (1 - phi / 2) / std::pow(1 - phi, 3);
  const double enskog =
      0.5 * n * 4 * density * sigma * sigma * contact_value * std::sqrt(M_PI * kT_over_m);
  const double measured = collisions / time;
  // Batch-means standard error of the rate.
  double mean = 0, var = 0;
  for (double r : batch_rates) mean += r / batch_rates.size();
  for (double r : batch_rates) var += (r - mean) * (r - mean) / (batch_rates.size() - 1);
  const double standard_error = std::sqrt(var / batch_rates.size()) / measured;
  std::printf(
      "hard-sphere gas: N %d, phi %.2f, %llu collisions over t = %.1f; rate %.2f vs Enskog-CS "
      "%.2f (ratio %.4f, batch-means standard error %.4f); energy drift %.2e (bound %.2e); "
      "closest pair %.15f a\n",
      n, phi, static_cast<unsigned long long>(collisions), time, measured, enskog,
      measured / enskog, standard_error, energy_drift, energy_bound, min_distance / a);
  // Tolerance 1.5 %: Carnahan-Starling <= 0.1 %, finite N = 864 in a periodic
  // box ~0.3 % (O(1/N) corrections to g(sigma)), statistics ~0.2 % (printed).
  EXPECT_NEAR(measured / enskog, 1.0, 0.015);
  EXPECT_LT(standard_error, 0.005);  // the statistics really are that good
}

// The contact number C_sph, the paper's aggregation metric, on a gas whose pair
// structure is known: in equilibrium the number of other centres within
// 2a (1 + eps) of a sphere is n * integral over that shell of g(r) 4 pi r^2 dr,
// which for a thin shell is 8 phi g(sigma) ((1 + eps)^3 - 1) with the
// Carnahan-Starling g(sigma). This is the "random arrangement" against which
// docs/validation/paper-case.md sets a settling suspension's baseline clustering.
TEST(HardSphereGas, ContactsPerSphereMatchTheCarnahanStarlingContactValue) {
  const double phi = 0.2, a = 1.0, dt = 0.05, eps = 0.003;
  Gas g = fcc_gas(6, a, phi, 7);  // 864 spheres
  SphereSet& s = g.spheres;
  const int n = static_cast<int>(s.size());
  DirectInteractions contacts;
  while (contacts.counters().collisions < 20u * n) contacts.advance(s, g.box, dt);

  // A sphere crosses the shell (width 0.006 a) in about 0.01 of the time unit
  // and collides about twice per unit, so snapshots dt apart are nearly
  // independent; 4000 of them hold about 4e4 pairs (statistics ~0.5 %).
  const int snapshots = 4000, per_batch = 200;
  std::vector<double> batch_means;
  double sum = 0, batch_sum = 0;
  for (int k = 1; k <= snapshots; ++k) {
    contacts.advance(s, g.box, dt);
    const double c =
        observables::find_aggregates(s.position, g.box, 2 * a * (1 + eps)).contacts_per_sphere;
    sum += c;
    batch_sum += c;
    if (k % per_batch == 0) {
      batch_means.push_back(batch_sum / per_batch);
      batch_sum = 0;
    }
  }
  const double measured = sum / snapshots;
  double var = 0;
  for (double b : batch_means) var += (b - measured) * (b - measured) / (batch_means.size() - 1);
  const double standard_error = std::sqrt(var / batch_means.size()) / measured;
  const double contact_value = (1 - phi / 2) / std::pow(1 - phi, 3);
  const double expected = 8 * phi * contact_value * (std::pow(1 + eps, 3) - 1);
  std::printf(
      "hard-sphere gas: C_sph within 2a(1 + %.3f) %.5f vs Carnahan-Starling %.5f (ratio %.4f, "
      "batch-means standard error %.4f)\n",
      eps, measured, expected, measured / expected, standard_error);
  // Tolerance 2 %: g(r) falls by about 0.3 % on average across the shell (its
  // slope at contact is about -3 g per sigma at phi = 0.2), finite N ~0.5 %,
  // statistics ~0.5 % (printed; checked below). Seeds 7-10 gave 0.995-1.000.
  EXPECT_NEAR(measured / expected, 1.0, 0.02);
  EXPECT_LT(standard_error, 0.01);
}

}  // namespace
}  // namespace flocsim::events
