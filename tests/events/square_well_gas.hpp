// A gas of spheres with square wells and elastic hard cores, no fluid.
//
// 1. Energy bookkeeping (docs/model.md section 5): kinetic energy minus the pair depth
//    m du^2 per attached pair is conserved to round-off.
// 2. Escape statistics against the Boltzmann factor of the pair depth. In
//    equilibrium the relative velocity of any pair is Maxwellian with the
//    reduced mass m/2, whatever the positions, so pairs reach the well edge
//    from inside with the flux-weighted radial speed distribution
//    p(v_r) ~ v_r exp(-(m/2) v_r^2 / (2 kT)). The fraction of those arrivals
//    that escape (v_r >= 2 du) is therefore
//       P_escape = exp(-(m/4)(2 du)^2 / kT) = exp(-m du^2 / kT),
//    the Boltzmann factor of the pair depth: an exact equilibrium result that
//    the event rules know nothing about.
#pragma once
#include <cmath>
#include <cstdio>
#include <vector>

#include "engine/events/direct_interactions.hpp"
#include "tests/events/gas_support.hpp"

namespace flocsim::events::testing_gas {

struct GasFigures {
  double energy_drift, energy_bound;
  double escape_fraction, boltzmann, standard_error;
  std::uint64_t arrivals, entries;
  double worst_overlap;
};

// depth_over_kT: m du^2 / kT of the initial state (the measured kT is used
// for the reference). Returns the figures both tests check.
inline GasFigures run_square_well_gas(double depth_over_kT, int cells, double phi,
                                      int measure_steps) {
  const double a = 1.0, dt = 0.05;
  Gas g = fcc_gas(cells, a, phi, 99);
  SphereSet& s = g.spheres;
  const int n = static_cast<int>(s.size());
  const double du = std::sqrt(depth_over_kT);  // kT / m = 1 initially
  DirectInteractions contacts({.escape_velocity = du, .well_width = 0.1 * a});
  auto total_energy = [&] { return kinetic_energy(s) + contacts.well_energy(s); };
  const double energy0 = total_energy();

  // Equilibrate: the fcc start has no attached pairs; wells fill and the gas warms.
  for (int step = 0; step < 2000; ++step) contacts.advance(s, g.box, dt);

  const std::uint64_t esc0 = contacts.counters().escapes, bnc0 = contacts.counters().edge_bounces;
  double kinetic_sum = 0;
  std::vector<double> batch_fraction;
  std::uint64_t esc_b = esc0, bnc_b = bnc0;
  for (int step = 1; step <= measure_steps; ++step) {
    contacts.advance(s, g.box, dt);
    kinetic_sum += kinetic_energy(s);
    if (step % 1000 == 0) {
      const double e = contacts.counters().escapes - esc_b,
                   b = contacts.counters().edge_bounces - bnc_b;
      batch_fraction.push_back(e / (e + b));
      esc_b = contacts.counters().escapes;
      bnc_b = contacts.counters().edge_bounces;
    }
  }
  GasFigures r;
  r.energy_drift = std::abs(total_energy() - energy0) / kinetic_energy(s);
  r.energy_bound = static_cast<double>(contacts.counters().events()) * 2.2e-16;
  const double escapes = contacts.counters().escapes - esc0;
  const double arrivals = escapes + (contacts.counters().edge_bounces - bnc0);
  r.arrivals = static_cast<std::uint64_t>(arrivals);
  r.entries = contacts.counters().well_entries;
  r.escape_fraction = escapes / arrivals;
  // kT from the time-averaged kinetic energy, 3N - 3 translational degrees of
  // freedom (mu_f = 0: rotation never exchanges energy).
  const double kT = 2 * (kinetic_sum / measure_steps) / (3.0 * n - 3);
  r.boltzmann = std::exp(-s.mass() * du * du / kT);
  double mean = 0, var = 0;
  for (double f : batch_fraction) mean += f / batch_fraction.size();
  for (double f : batch_fraction) var += (f - mean) * (f - mean) / (batch_fraction.size() - 1);
  r.standard_error = std::sqrt(var / batch_fraction.size());
  r.worst_overlap = contacts.worst_overlap();
  std::printf(
      "square-well gas: N %d, phi %.2f, depth/kT0 %.2f: %llu edge arrivals, %llu entries; escape "
      "fraction %.5f vs Boltzmann exp(-m du^2/kT) %.5f (kT %.4f m, batch-means error %.5f); "
      "energy drift %.2e (bound %.2e)\n",
      n, phi, depth_over_kT, static_cast<unsigned long long>(r.arrivals),
      static_cast<unsigned long long>(r.entries), r.escape_fraction, r.boltzmann, kT / s.mass(),
      r.standard_error, r.energy_drift, r.energy_bound);
  return r;
}

}  // namespace flocsim::events::testing_gas
