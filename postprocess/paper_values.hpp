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

// What the paper states about the normalised aggregate size <n_a>/<n_a>0 (its
// discussion of Fig. 12): at phi = 0.12 the cases (Re_inf, du/U_inf) = (72, 0.03),
// (24, 0.025), (12, 0.02) and (6, 0.05) all have about 2.3; at phi = 0.20 the
// cases (48, 0.03), (12, 0.025) and (6, 0.02) about 7.6. <n_a> grows with du at
// fixed phi and Re_inf (the paper's Figs. 9 and 10: 4.88 < 11.9 < 59.4) while
// <n_a>0 does not depend on du, so one stated point bounds the ratio at every
// other du of its (phi, Re_inf): at most the stated value below that du, at
// least above it. That is all the text gives; a bound, never a value.
struct PaperNormalisedSize {
  enum class Relation { kAbout, kAtMost, kAtLeast };
  Relation relation;
  double value;      // the stated <n_a>/<n_a>0
  double du_stated;  // the du/U_inf of the stated case
};

inline std::optional<PaperNormalisedSize> paper_normalised_size(double phi, double re_inf,
                                                                double du) {
  struct Stated {
    double phi, re_inf, du, value;
  };
  static constexpr Stated kStated[] = {
      {0.12, 72, 0.03, 2.3}, {0.12, 24, 0.025, 2.3}, {0.12, 12, 0.02, 2.3}, {0.12, 6, 0.05, 2.3},
      {0.2, 48, 0.03, 7.6},  {0.2, 12, 0.025, 7.6},  {0.2, 6, 0.02, 7.6}};
  auto same = [](double x, double y) { return std::abs(x - y) <= 1e-9 * std::abs(y); };
  if (!(du > 0)) return std::nullopt;  // the ratio is 1 by definition at du = 0
  for (const Stated& s : kStated) {
    if (!same(phi, s.phi) || !same(re_inf, s.re_inf)) continue;
    using R = PaperNormalisedSize::Relation;
    const R relation = same(du, s.du) ? R::kAbout : du < s.du ? R::kAtMost : R::kAtLeast;
    return PaperNormalisedSize{relation, s.value, s.du};
  }
  return std::nullopt;
}

}  // namespace flocsim::postprocess
