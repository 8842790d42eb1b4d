#pragma once
// Numbers the paper (Derksen 2013) states in its text, for the tables' and figures'
// side-by-side. Only what is written as a number is here; values read off its
// figures are not (their reading error would pass for a published value).
#include <algorithm>
#include <cmath>
#include <limits>
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

// What the paper's text fixes about the normalised aggregate size
// <n_a>/<n_a>0. Its discussion of Fig. 12 states about 2.3 at phi = 0.12 for
// (Re_inf, du/U_inf) = (72, 0.03), (24, 0.025), (12, 0.02), (6, 0.05), and about
// 7.6 at phi = 0.20 for (48, 0.03), (12, 0.025), (6, 0.02). The (6, 0.05) point
// is left out: 0.05 lies outside the du/U_inf range the paper simulated
// (0.005-0.03, its Table 1), so it is a misprint of a du we cannot know, and a
// bound from it could point the wrong way (at most 2.3 below 0.05, but at least
// 2.3 above a true 0.005). <n_a> grows with du
// at fixed phi and Re_inf (Figs. 9 and 10: 4.88 < 11.9 < 59.4) and <n_a>0 does
// not depend on du, so at another du of the same (phi, Re_inf):
//  - the ratio is at least 1, at most the stated value below the stated du,
//    at least it above;
//  - where Fig. 9 also gives <n_a> (phi 0.2, Re_inf 12): <n_a>0 is at most the
//    <n_a> of the weakest stated well (4.88), and <n_a>0 = <n_a>(0.025) / 7.6
//    with <n_a>(0.025) between its neighbours 11.9 and 59.4, so <n_a>0 lies in
//    [11.9 / 7.6, 4.88] = [1.57, 4.88]; a stated <n_a> divided by that range
//    bounds the ratio at its du.
// An interval, or "about" the stated value at its own du; never a point read
// off a figure.
struct PaperNormalisedSize {
  bool about = false;  // the paper's own "about" value (low == high)
  double low = 1;      // the ratio is at least this
  double high = std::numeric_limits<double>::infinity();  // and at most this
};

// The bounds on the paper's <n_a>0 its text implies, for (phi, Re_inf) with
// both a stated ratio and stated <n_a> values; empty otherwise.
struct PaperBaselineRange {
  double low, high;
};

// The comparison points of the paper's discussion of Fig. 12, as printed:
// (phi, Re_inf, du/U_inf) and the normalised size it gives them ("about").
// `inside_simulated_range` is false for (0.12, 6, 0.05): drawn beside
// flocsim's run of the same triple in Fig. 12, never used for a bound (above).
struct StatedComparisonPoint {
  double phi, re_inf, du, value;
  bool inside_simulated_range = true;
};
inline constexpr StatedComparisonPoint kStatedComparisonPoints[] = {
    {0.12, 72, 0.03, 2.3},       {0.12, 24, 0.025, 2.3}, {0.12, 12, 0.02, 2.3},
    {0.12, 6, 0.05, 2.3, false}, {0.2, 48, 0.03, 7.6},   {0.2, 12, 0.025, 7.6},
    {0.2, 6, 0.02, 7.6}};

namespace detail {
inline bool same(double x, double y) {
  return std::abs(x - y) <= 1e-9 * std::abs(y);
}
using StatedRatio = StatedComparisonPoint;
inline const StatedRatio* stated_ratio(double phi, double re_inf) {
  for (const StatedRatio& s : kStatedComparisonPoints)
    if (s.inside_simulated_range && same(phi, s.phi) && same(re_inf, s.re_inf)) return &s;
  return nullptr;
}
}  // namespace detail

// The stated comparison points at this phi, as printed (empty for any other).
inline std::vector<StatedComparisonPoint> stated_comparison_points(double phi) {
  std::vector<StatedComparisonPoint> out;
  for (const StatedComparisonPoint& s : kStatedComparisonPoints)
    if (detail::same(phi, s.phi)) out.push_back(s);
  return out;
}

inline std::optional<PaperBaselineRange> paper_baseline_range(double phi, double re_inf) {
  const detail::StatedRatio* r = detail::stated_ratio(phi, re_inf);
  const std::vector<PaperAggregateSize> sizes = paper_aggregate_sizes(phi, re_inf);
  if (!r || sizes.empty()) return std::nullopt;
  double below = 0, above = std::numeric_limits<double>::infinity(),
         weakest = std::numeric_limits<double>::infinity();
  for (const PaperAggregateSize& p : sizes) {
    weakest = std::min(weakest, p.n_a);  // <n_a> grows with du
    if (p.du_over_Uinf <= r->du) below = std::max(below, p.n_a);
    if (p.du_over_Uinf >= r->du) above = std::min(above, p.n_a);
  }
  return PaperBaselineRange{below / r->value, std::min(weakest, above / r->value)};
}

inline std::optional<PaperNormalisedSize> paper_normalised_size(double phi, double re_inf,
                                                                double du) {
  if (!(du > 0)) return std::nullopt;  // the ratio is 1 by definition at du = 0
  const detail::StatedRatio* r = detail::stated_ratio(phi, re_inf);
  if (!r) return std::nullopt;
  PaperNormalisedSize out;
  if (detail::same(du, r->du)) {
    out.about = true;
    out.low = out.high = r->value;
    return out;
  }
  if (du < r->du)
    out.high = r->value;
  else
    out.low = r->value;
  const auto n0 = paper_baseline_range(phi, re_inf);
  const auto n = paper_mean_aggregate_size(phi, re_inf, du);
  if (n0 && n) {
    out.low = std::max(out.low, *n / n0->high);
    out.high = std::min(out.high, *n / n0->low);
  }
  return out;
}

}  // namespace flocsim::postprocess
