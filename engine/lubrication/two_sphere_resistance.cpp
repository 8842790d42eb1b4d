#include "engine/lubrication/two_sphere_resistance.hpp"

#include <cmath>
#include <stdexcept>

namespace flocsim::lubrication {

double brenner_pair_resistance(double gap_over_a) {
  if (!(gap_over_a > 0) || !std::isfinite(gap_over_a))
    throw std::invalid_argument("brenner_pair_resistance: the gap must be positive");
  // bipolar coordinates: the midplane sits at distance h = a + s/2 from each
  // centre, cosh(alpha) = h / a
  const double alpha = std::acosh(1 + 0.5 * gap_over_a);
  const double sh = std::sinh(alpha);
  double sum = 0;
  for (long n = 1; n < 10000000; ++n) {
    const double m = 2.0 * n + 1;
    // beyond this the hyperbolic terms overflow and the bracket is 0 to double
    if (m * alpha > 700) break;
    const double k = static_cast<double>(n) * (n + 1) / ((2.0 * n - 1) * (2.0 * n + 3));
    const double c = std::cosh(0.5 * m * alpha);
    const double bracket =
        (4 * c * c + m * m * sh * sh) / (2 * std::sinh(m * alpha) - m * std::sinh(2 * alpha)) - 1;
    sum += k * bracket;
    if (std::abs(k * bracket) < 1e-17 * std::abs(sum)) break;
  }
  return 4.0 / 3.0 * sh * sum;
}

}  // namespace flocsim::lubrication
