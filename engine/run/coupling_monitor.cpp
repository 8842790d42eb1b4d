#include "engine/run/coupling_monitor.hpp"

#include <algorithm>
#include <cstdio>

namespace flocsim::run {

std::string CouplingMonitor::observe(const std::vector<spheres::Vec3>& loads, double net_weight) {
  if (previous_.size() != loads.size()) {
    previous_.assign(loads.size(), spheres::Vec3::Zero());
    run_.assign(loads.size(), 0);
  }
  for (std::size_t s = 0; s < loads.size(); ++s) {
    const spheres::Vec3& h = loads[s];
    const double size = h.norm(), before = previous_[s].norm();
    const bool flip = size > kLargeLoad * net_weight && h.dot(previous_[s]) < -0.5 * size * before;
    run_[s] = flip ? static_cast<unsigned char>(std::min(run_[s] + 1, 255)) : 0;
    if (run_[s] >= kSustainedFlips) ++flips_;
    previous_[s] = h;
  }
  if (++steps_ < kWindowSteps || loads.empty()) return {};
  const long count = flips_;
  const double fraction = static_cast<double>(count) /
                          (static_cast<double>(steps_) * static_cast<double>(loads.size()));
  worst_ = std::max(worst_, fraction);
  flips_ = steps_ = 0;
  if (fraction <= kFlipLimit || count < kMinimumCount) return {};
  char text[320];
  std::snprintf(text, sizeof text,
                "the sphere-liquid coupling oscillates: in the last %d steps %.3g of the "
                "sphere-steps had a hydrodynamic load above %g times the net weight that had "
                "reversed %d steps in a row (limit %g)",
                kWindowSteps, fraction, kLargeLoad, kSustainedFlips, kFlipLimit);
  return text;
}

}  // namespace flocsim::run
