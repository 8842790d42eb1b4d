#include "engine/lubrication/radial_lubrication.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "engine/lubrication/two_sphere_resistance.hpp"
#include "engine/neighbours/pair_search.hpp"

namespace flocsim::lubrication {

namespace {

void require(bool ok, const char* field, double value, const char* allowed) {
  if (ok) return;
  std::ostringstream os;
  os << "lubrication: " << field << " = " << value << " is outside the allowed range " << allowed;
  throw std::invalid_argument(os.str());
}

}  // namespace

void LubricationParams::check() const {
  require(viscosity > 0 && std::isfinite(viscosity), "viscosity", viscosity, "(0, inf)");
  require(liquid_density > 0 && std::isfinite(liquid_density), "liquid_density", liquid_density,
          "(0, inf)");
  require(onset_gap > 0 && std::isfinite(onset_gap), "onset_gap", onset_gap, "(0, inf)");
  require(saturation_gap > 0 && saturation_gap < onset_gap, "saturation_gap", saturation_gap,
          "(0, onset_gap)");
  for (std::size_t k = 0; k < lattice_share.size(); ++k) {
    require(lattice_share[k].first > 0 && std::isfinite(lattice_share[k].first),
            "lattice_share gap", lattice_share[k].first, "(0, inf)");
    require(k == 0 || lattice_share[k].first > lattice_share[k - 1].first, "lattice_share gap",
            lattice_share[k].first, "increasing");
    require(lattice_share[k].second > 0 && std::isfinite(lattice_share[k].second),
            "lattice_share lambda", lattice_share[k].second, "(0, inf)");
  }
}

RadialLubrication::RadialLubrication(LubricationParams params) : params_(params) {
  params_.check();
  if (params_.lattice_share.empty()) return;
  log_first_ = std::log(params_.saturation_gap);
  log_step_ = (std::log(params_.onset_gap) - log_first_) / (kExactPoints - 1);
  gap_times_exact_.resize(kExactPoints);
  for (int k = 0; k < kExactPoints; ++k) {
    const double e = std::exp(log_first_ + k * log_step_);
    gap_times_exact_[k] = e * brenner_pair_resistance(e);
  }
}

double RadialLubrication::exact_resistance(double e) const {
  // the cubic through points k-1 .. k+2 (shifted inwards at the ends), in the
  // grid coordinate t = x - k
  const double x = (std::log(e) - log_first_) / log_step_;
  const int k = std::clamp(static_cast<int>(std::floor(x)), 1, kExactPoints - 3);
  const double t = x - k;
  const double* g = &gap_times_exact_[k - 1];
  const double w0 = -t * (t - 1) * (t - 2) / 6, w1 = (t + 1) * (t - 1) * (t - 2) / 2,
               w2 = -(t + 1) * t * (t - 2) / 2, w3 = (t + 1) * t * (t - 1) / 6;
  return (w0 * g[0] + w1 * g[1] + w2 * g[2] + w3 * g[3]) / e;
}

double RadialLubrication::coefficient(double gap, double radius) const {
  const double s0 = params_.onset_gap * radius;
  const double s1 = params_.saturation_gap * radius;
  if (gap > s0) return 0.0;
  const double s = std::max(gap, s1);
  if (!params_.lattice_share.empty()) {
    const auto& t = params_.lattice_share;
    const double e = s / radius;
    double share = t.front().second;
    if (e >= t.back().first) {
      share = t.back().second;
    } else if (e > t.front().first) {
      std::size_t k = 1;
      while (t[k].first < e) ++k;
      const double f = (e - t[k - 1].first) / (t[k].first - t[k - 1].first);
      share = t[k - 1].second + f * (t[k].second - t[k - 1].second);
    }
    // Brenner's lambda is per sphere speed U (F = 6 pi mu a U lambda); the
    // coefficient multiplies the relative radial velocity w = 2U, so half that.
    // Negative where the lattice alone resists more than the exact value (it
    // does at small viscosity from about 0.07a up: docs/contacts.md): the
    // correction then takes the excess off, and the pair's total is still the
    // exact, positive resistance.
    const double excess = exact_resistance(e) - share;
    return 3.0 * M_PI * params_.liquid_density * params_.viscosity * radius * excess;
  }
  return 1.5 * M_PI * params_.liquid_density * params_.viscosity * radius * radius *
         (1.0 / s - 1.0 / s0);
}

int RadialLubrication::apply(SphereSet& spheres, const PeriodicBox& box, double dt) const {
  if (!(dt > 0 && std::isfinite(dt)))
    throw std::invalid_argument("lubrication: time step must be positive");
  const double a = spheres.radius;
  const double mass = spheres.mass() * params_.liquid_density;
  const double reach = 2.0 * a + params_.onset_gap * a;
  int interacting = 0;
  for (const auto& p : neighbours::pairs_within(spheres.position, box, reach)) {
    const Vec3 r = spheres.position[p.j] - spheres.position[p.i] + p.shift;
    const double distance = r.norm();
    const double c = coefficient(distance - 2.0 * a, a);
    if (c == 0.0) continue;
    const Vec3 n = r / distance;
    Vec3& u_i = spheres.velocity[p.i];
    Vec3& u_j = spheres.velocity[p.j];
    const double w = (u_j - u_i).dot(n);
    // Backward Euler in w: the force c w' uses the radial velocity at the end
    // of the step, so w' = w / (1 + 2 c dt / m) has the sign of w. Forward
    // Euler (the paper's) uses w at the start and overshoots past 2 c dt / m = 1.
    // A negative (calibrated) coefficient takes off resistance the lattice
    // already over-counts: forward Euler, w (1 + |2 c dt / m|), keeps the sign
    // of w at any dt, where backward Euler would not past |2 c dt / m| = 1.
    const double decay = 2.0 * c * dt / mass;
    const double w_after =
        params_.explicit_euler || decay < 0 ? w * (1.0 - decay) : w / (1.0 + decay);
    const double half_change = 0.5 * (w - w_after);
    u_i += half_change * n;
    u_j -= half_change * n;
    ++interacting;
  }
  return interacting;
}

}  // namespace flocsim::lubrication
