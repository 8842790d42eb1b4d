#pragma once
// The exact resistance of two equal spheres moving apart or together along
// their line of centres in creeping flow: Brenner (1961) for a sphere
// approaching a plane free surface, which is the midplane of the symmetric
// pair (no normal velocity, no shear stress there). Each sphere of radius a
// moves at U towards (or away from) the other; the force on each is
// F = 6 pi mu a U lambda(s / a), s the surface gap, so lambda -> 1 far apart
// and lambda ~ a / (2 s) at contact, the squeeze film that the lubrication
// correction stands in for (docs/contacts.md). The reference against which
// the lattice's own share of the close-pair resistance is calibrated.
namespace flocsim::lubrication {

// lambda at gap_over_a = s / a > 0, summed to convergence (relative 1e-15).
double brenner_pair_resistance(double gap_over_a);

}  // namespace flocsim::lubrication
