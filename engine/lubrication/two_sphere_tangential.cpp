#include "engine/lubrication/two_sphere_tangential.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace flocsim::lubrication {

namespace {

// Highest power of t = 2a / r kept. The closed-form near-contact parts leave
// coefficients that fall as 1/m^3, so the truncation is felt only near
// contact: order 100 against 200 differs by at most 4.4e-5 (at s = 1e-5 a),
// 1.6e-5 at 0.02a and 3e-7 at 0.1a (measured by building this file with
// kOrder = 200); order 200 takes 4 s to set up, order 100 0.2 s.
constexpr int kOrder = 100;

// Jeffrey & Onishi's twin-multipole coefficients P, Q, V(n, p, q) for equal
// spheres, one problem at a time: `rotation` false for a sphere translating
// (P_100 = V_100 = 1), true for one rotating (Q_100 = 1). Each entry depends
// only on entries of smaller n + p + q, memoised.
class Multipoles {
 public:
  explicit Multipoles(bool rotation) : rotation_(rotation), size_(kOrder + 3) {
    const std::size_t cells = static_cast<std::size_t>(size_) * size_ * size_;
    P_.assign(cells, NAN);
    Q_.assign(cells, NAN);
    V_.assign(cells, NAN);
    binomial_.assign(static_cast<std::size_t>(2 * size_) * (2 * size_), 0.0);
    for (int n = 0; n < 2 * size_; ++n) {
      binomial_[index2(n, 0)] = 1;
      for (int k = 1; k <= n; ++k)
        binomial_[index2(n, k)] = binomial_[index2(n - 1, k - 1)] + binomial_[index2(n - 1, k)];
    }
  }

  double P(int n, int p, int q) {
    return memoised(P_, n, p, q, [&] {
      if (p == 0 && q == 0) return !rotation_ && n == 1 ? 1.0 : 0.0;
      const double N = n;
      double sum = 0;
      for (int s = 1; s <= q; ++s) {
        const double S = s;
        const double term =
            (2 * N + 1) / (2 * (N + 1)) * (3 * (N + S) - (N * S + 1) * (2 * N * S - S - N + 2)) /
                (S * (N + S) * (2 * S - 1)) * P(s, q - s, p - n + 1) +
            N * (2 * N - 1) / (2 * (N + 1)) * P(s, q - s, p - n - 1) +
            N * (4 * N * N - 1) / (2 * (N + 1) * (2 * S + 1)) * V(s, q - s - 2, p - n + 1) -
            2 * (4 * N * N - 1) / (3 * (N + 1)) * Q(s, q - s - 1, p - n + 1);
        sum += choose(n + s, n + 1) * term;
      }
      return sum;
    });
  }

  double Q(int n, int p, int q) {
    return memoised(Q_, n, p, q, [&] {
      if (p == 0 && q == 0) return rotation_ && n == 1 ? 1.0 : 0.0;
      const double N = n;
      double sum = 0;
      for (int s = 1; s <= q; ++s)
        sum += choose(n + s, n + 1) * (s / (N + 1) * Q(s, q - s - 1, p - n) -
                                       3 / (2 * N * s * (N + 1)) * P(s, q - s, p - n));
      return sum;
    });
  }

  double V(int n, int p, int q) {
    return memoised(V_, n, p, q, [&] {
      if (p == 0 && q == 0) return !rotation_ && n == 1 ? 1.0 : 0.0;
      const double N = n;
      double sum = 0;
      for (int s = 1; s <= q; ++s) sum += choose(n + s, n + 1) * P(s, q - s, p - n - 1);
      return P(n, p, q) + 2 * N / ((N + 1) * (2 * N + 3)) * sum;
    });
  }

 private:
  // table's entry (n, p, q), computed once; 0 where p or q is negative (the
  // recurrences reach past the edge of the index space). The tables never
  // grow, so a reference into one outlives the recursion below it.
  template <class Compute>
  double memoised(std::vector<double>& table, int n, int p, int q, Compute compute) {
    if (p < 0 || q < 0) return 0;
    double& memo = table[index3(n, p, q)];
    if (std::isnan(memo)) memo = compute();
    return memo;
  }

  std::size_t index3(int n, int p, int q) const {
    if (n >= size_ || p >= size_ || q >= size_)
      throw std::logic_error("two-sphere series: coefficient beyond its order");
    return (static_cast<std::size_t>(n) * size_ + p) * size_ + q;
  }
  std::size_t index2(int n, int k) const { return static_cast<std::size_t>(n) * 2 * size_ + k; }
  double choose(int n, int k) const { return binomial_[index2(n, k)]; }

  bool rotation_;
  int size_;
  std::vector<double> P_, Q_, V_, binomial_;
};

// The coefficients a_m of t^m of Y^A, Y^B and Y^C (11 at even m, 12 at odd
// m, up to sign), computed once.
struct SeriesCoefficients {
  std::vector<double> A, B, C;
};

const SeriesCoefficients& coefficients() {
  static const SeriesCoefficients coefficients_once = [] {
    SeriesCoefficients c;
    // 2^k / (2 (1 + lambda))^k at lambda = 1
    auto scale = [](int k) { return std::pow(0.5, k); };
    {  // one problem's tables at a time (26 MB each)
      Multipoles translation(false);
      for (int k = 0; k <= kOrder; ++k) {
        double fa = 0, fb = 0;
        for (int q = 0; q <= k; ++q) {
          fa += translation.P(1, k - q, q);
          fb += translation.Q(1, k - q, q);
        }
        c.A.push_back(fa * scale(k));
        c.B.push_back(2 * fb * scale(k));
      }
    }
    Multipoles rotation(true);
    for (int k = 0; k <= kOrder; ++k) {
      double fc = 0;
      for (int q = 0; q <= k; ++q) fc += rotation.Q(1, k - q, q);
      c.C.push_back(fc * scale(k));
    }
    return c;
  }();
  return coefficients_once;
}

// The near-contact singular parts g2 ln(1/xi) + g3 xi ln(1/xi) of each
// function (Jeffrey & Onishi 1984 at lambda = 1, Townsend 2023's corrections)
// show in the coefficients as 2 g2 / m - 4 g3 / (m (m + 2)); those are
// subtracted from the a_m and summed to infinity in closed form.
struct NearContact {
  double g2, g3;
};
constexpr NearContact kYA{1.0 / 6, 0};
constexpr NearContact kYB{-1.0 / 4, -1.0 / 8};
constexpr NearContact kYC11{1.0 / 5, 47.0 / 250};
constexpr NearContact kYC12{1.0 / 20, 31.0 / 500};

// sum over m of the same parity as `odd` of a_m t^m, the near-contact parts
// summed in closed form
double series(const std::vector<double>& a, NearContact g, bool odd, double t) {
  double sum = odd ? 0 : a[0];
  for (int m = odd ? 1 : 2; m < static_cast<int>(a.size()); m += 2)
    sum += (a[m] - 2 * g.g2 / m + 4 * g.g3 / (m * (m + 2.0))) * std::pow(t, m);
  if (odd) {
    const double artanh = 2 * std::atanh(t);  // sum over odd m of 2 t^m / m
    return sum + g.g2 * artanh - g.g3 * (artanh * (1 - 1 / (t * t)) + 2 / t);
  }
  const double log_gap = std::log(1 - t * t);  // minus the sum over even m of 2 t^m / m
  return sum - g.g2 * log_gap - g.g3 * (1 + (1 - t * t) / (t * t) * log_gap);
}

}  // namespace

TangentialFunctions equal_sphere_tangential_functions(double xi) {
  if (!(xi > 0) || !std::isfinite(xi))
    throw std::invalid_argument("two-sphere resistance: the gap s/a must be positive, got " +
                                std::to_string(xi));
  const auto& c = coefficients();
  const double t = 2 / (2 + xi);
  return {.YA11 = series(c.A, kYA, false, t),
          .YA12 = -series(c.A, kYA, true, t),
          .YB11 = series(c.B, kYB, true, t),
          .YB12 = -series(c.B, kYB, false, t),
          .YC11 = series(c.C, kYC11, false, t),
          .YC12 = series(c.C, kYC12, true, t)};
}

double sliding_pair_force(double xi) {
  const auto y = equal_sphere_tangential_functions(xi);
  return y.YA11 - y.YA12;
}
double sliding_pair_torque(double xi) {
  const auto y = equal_sphere_tangential_functions(xi);
  return (y.YB11 - y.YB12) / 2;
}
double rolling_pair_torque(double xi) {
  const auto y = equal_sphere_tangential_functions(xi);
  return y.YC11 - y.YC12;
}
double rolling_pair_force(double xi) {
  const auto y = equal_sphere_tangential_functions(xi);
  return 2.0 / 3 * (y.YB11 + y.YB12);
}

}  // namespace flocsim::lubrication
