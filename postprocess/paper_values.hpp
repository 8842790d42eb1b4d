#pragma once
// Numbers the paper (Derksen 2013) states in its text, for the tables' and figures'
// side-by-side. Only what is written as a number is here; values read off its
// figures are not (their reading error would pass for a published value).
#include <cmath>
#include <optional>
#include <vector>

namespace flocsim::postprocess {

struct PaperAggregateSize {
  double du_over_Uinf, n_a;
};

// Mass-weighted mean aggregate sizes <n_a> of the paper's Fig. 9 caption:
// phi = 0.20, Re_inf = 12, N = 1320, a = 6 dx, 600 realisations 4 a/U_inf apart
// after steady state; no error given. Empty for any other (phi, Re_inf).
inline std::vector<PaperAggregateSize> paper_aggregate_sizes(double phi, double re_inf) {
  auto same = [](double x, double y) { return std::abs(x - y) <= 1e-9 * std::abs(y); };
  if (!same(phi, 0.2) || !same(re_inf, 12)) return {};
  return {{0.01, 4.88}, {0.02, 11.9}, {0.03, 59.4}};
}

// The paper's <n_a> at exactly this case, if its text states one.
inline std::optional<double> paper_mean_aggregate_size(double phi, double re_inf, double du) {
  for (const PaperAggregateSize& p : paper_aggregate_sizes(phi, re_inf))
    if (std::abs(du - p.du_over_Uinf) <= 1e-9 * p.du_over_Uinf) return p.n_a;
  return std::nullopt;
}

}  // namespace flocsim::postprocess
