#include "engine/observables/reference_correlations.hpp"

#include <cmath>

namespace flocsim::observables {

double beetstra_drag(double phi, double reynolds) {
  const double s = 1 - phi;
  const double stokes = 10 * phi / (s * s) + s * s * (1 + 1.5 * std::sqrt(phi));
  const double inertial = 0.413 * reynolds / (24 * s * s) *
                          (1 / s + 3 * phi * s + 8.4 * std::pow(reynolds, -0.343)) /
                          (1 + std::pow(10.0, 3 * phi) * std::pow(reynolds, -(1 + 4 * phi) / 2));
  return stokes + inertial;
}

double beetstra_velocity_ratio(double phi, double reynolds_inf) {
  const double balance = (1 - phi) * (1 + 0.15 * std::pow(reynolds_inf, 0.687));
  // x F(phi, Re_inf x) grows with x: bisection on (0, 2]
  double lo = 0, hi = 2;
  for (int k = 0; k < 100; ++k) {
    const double x = 0.5 * (lo + hi);
    (x * beetstra_drag(phi, reynolds_inf * x) < balance ? lo : hi) = x;
  }
  return 0.5 * (lo + hi);
}

double wylie_drag(double phi, double reynolds, double reynolds_t) {
  const double base = beetstra_drag(phi, reynolds);
  if (reynolds_t <= 0) return base;
  const double x = reynolds_t / reynolds;
  const double amplitude = reynolds * (0.0336 + 0.106 * phi + 0.0116 / std::pow(1 - phi, 5));
  const double shape = (1 + 2 * x * x - x * x * x * x) * std::erf(1 / (std::sqrt(2.0) * x)) +
                       std::sqrt(2 / M_PI) * x * (1 + x * x) * std::exp(-1 / (2 * x * x));
  return base + amplitude * shape;
}

double richardson_zaki_exponent(double re) {
  if (re < 0.2) return 4.65;
  if (re < 1) return 4.35 * std::pow(re, -0.03);
  if (re < 500) return 4.45 * std::pow(re, -0.1);
  return 2.39;
}

double richardson_zaki_velocity_ratio(double phi, double reynolds_inf) {
  return std::pow(1 - phi, richardson_zaki_exponent(reynolds_inf));
}

}  // namespace flocsim::observables
