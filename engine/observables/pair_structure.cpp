#include "engine/observables/pair_structure.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "engine/neighbours/pair_search.hpp"

namespace flocsim::observables {

PairStructure::PairStructure(double r_max_g, double dr, double r_max_h, double dtheta)
    : r_max_g_(r_max_g), dr_(dr), r_max_h_(r_max_h), dtheta_(dtheta) {
  g_counts_.assign(static_cast<std::size_t>(std::ceil(r_max_g / dr - 1e-9)), 0.0);
  h_counts_.assign(static_cast<std::size_t>(std::lround(M_PI / dtheta)), 0.0);
}

void PairStructure::add_configuration(const std::vector<spheres::Vec3>& position,
                                      const spheres::PeriodicBox& box) {
  const double n = static_cast<double>(position.size());
  const double cutoff = std::max(r_max_g_, r_max_h_);
  for (const auto& p : neighbours::pairs_within(position, box, cutoff)) {
    const spheres::Vec3 d = position[p.j] - position[p.i] + p.shift;
    const double r = d.norm();
    if (r < r_max_g_) {
      const auto bin = static_cast<std::size_t>(r / dr_);
      if (bin < g_counts_.size()) g_counts_[bin] += 2.0;  // both spheres are a reference
    }
    if (r < r_max_h_ && r > 0) {
      const double theta = std::acos(std::clamp(d.x() / r, -1.0, 1.0));
      const auto last = h_counts_.size() - 1;
      h_counts_[std::min(static_cast<std::size_t>(theta / dtheta_), last)] += 1.0;
      h_counts_[std::min(static_cast<std::size_t>((M_PI - theta) / dtheta_), last)] += 1.0;
      h_pairs_ += 2.0;
    }
  }
  g_normalisation_ += n * (n - 1) / box.volume();
  ++configurations_;
}

void PairStructure::restore(const Accumulated& a) {
  if (a.g_counts.size() != g_counts_.size() || a.h_counts.size() != h_counts_.size())
    throw std::invalid_argument(
        "PairStructure::restore: bin counts differ from this accumulator's");
  g_counts_ = a.g_counts;
  h_counts_ = a.h_counts;
  g_normalisation_ = a.g_normalisation;
  h_pairs_ = a.h_pairs;
  configurations_ = a.configurations;
}

std::vector<double> PairStructure::radial_distribution() const {
  std::vector<double> g(g_counts_.size(), 0.0);
  if (g_normalisation_ <= 0) return g;
  for (std::size_t b = 0; b < g.size(); ++b) {
    const double r0 = b * dr_, r1 = (b + 1) * dr_;
    const double shell = 4.0 / 3.0 * M_PI * (r1 * r1 * r1 - r0 * r0 * r0);
    g[b] = g_counts_[b] / (g_normalisation_ * shell);
  }
  return g;
}

std::vector<double> PairStructure::angular_distribution() const {
  std::vector<double> h(h_counts_.size(), 0.0);
  if (h_pairs_ <= 0) return h;
  for (std::size_t b = 0; b < h.size(); ++b) {
    const double t0 = b * dtheta_, t1 = std::min(M_PI, (b + 1) * dtheta_);
    const double solid_angle_fraction = 0.5 * (std::cos(t0) - std::cos(t1));
    h[b] = h_counts_[b] / h_pairs_ / solid_angle_fraction;
  }
  return h;
}

std::vector<double> PairStructure::radial_bin_centres() const {
  std::vector<double> r(g_counts_.size());
  for (std::size_t b = 0; b < r.size(); ++b) r[b] = (b + 0.5) * dr_;
  return r;
}

std::vector<double> PairStructure::angular_bin_centres() const {
  std::vector<double> t(h_counts_.size());
  for (std::size_t b = 0; b < t.size(); ++b) t[b] = (b + 0.5) * dtheta_;
  return t;
}

}  // namespace flocsim::observables
