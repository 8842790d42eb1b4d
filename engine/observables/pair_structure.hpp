#pragma once
// Microstructure (paper Fig. 2): the radial distribution function g(r) and the
// angular distribution function h(theta), accumulated over many
// configurations. Both are normalised by a homogeneous, isotropic
// distribution of centres, so an ideal gas gives g = 1 and h = 1.
//  g(r): pairs in shell [r, r + dr) / ((N - 1)/V * shell volume) per sphere.
//  h(theta): pairs with |r| < r_max (3a) whose separation makes an angle in
//  [theta, theta + dtheta) with +x (gravity axis), divided by the fraction of
//  the solid angle that conical shell covers, (cos theta - cos(theta+dtheta))/2.
//  Both orientations of a pair count, so h(theta) = h(pi - theta).
#include <vector>

#include "engine/spheres/sphere_set.hpp"

namespace flocsim::observables {

class PairStructure {
 public:
  // g(r) on [0, r_max_g) with bin dr; h(theta) with bin dtheta for pairs closer than r_max_h.
  PairStructure(double r_max_g, double dr, double r_max_h, double dtheta);

  void add_configuration(const std::vector<spheres::Vec3>& position,
                         const spheres::PeriodicBox& box);

  std::vector<double> radial_distribution() const;   // g per bin
  std::vector<double> angular_distribution() const;  // h per bin
  std::vector<double> radial_bin_centres() const;
  std::vector<double> angular_bin_centres() const;
  long configurations() const { return configurations_; }

  // The raw accumulators, for checkpoints.
  struct Accumulated {
    std::vector<double> g_counts, h_counts;
    double g_normalisation = 0, h_pairs = 0;
    long configurations = 0;
  };
  Accumulated accumulated() const {
    return {g_counts_, h_counts_, g_normalisation_, h_pairs_, configurations_};
  }
  void restore(const Accumulated& a);

 private:
  double r_max_g_, dr_, r_max_h_, dtheta_;
  std::vector<double> g_counts_, h_counts_;
  double g_normalisation_ = 0;  // sum over configurations of N (N - 1) / V
  double h_pairs_ = 0;          // ordered pairs counted for h
  long configurations_ = 0;
};

}  // namespace flocsim::observables
