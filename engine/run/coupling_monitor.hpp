#pragma once
// Watches the explicit sphere-liquid coupling for its numerical instability:
// a sphere whose hydrodynamic load (immersed-boundary force plus the change of
// the liquid momentum inside it, per step) is large against its net weight and
// reverses direction from one step to the next. That period-2 flip is how the
// coupling fails (docs/numerics.md, "The coupling's period-2 oscillation"):
// with the paper's IB method at a = 4 dx and nu = 0.01 it grew over thousands
// of steps, to a blow-up with the calibrated close pairs and to a bounded
// shaking of 40 % of the spheres with Nguyen-Ladd's, which no speed limit
// catches and which inflates the granular temperature and breaks bonds.
//
// A flip: |H| > kLargeLoad W and H . H_prev < -|H| |H_prev| / 2. Counted per
// window of kWindowSteps steps: the fraction of sphere-steps that are the
// kSustainedFlips-th (or later) flip in a row, a held period-2 oscillation;
// a collision's spike and return are two flips and do not count. Measured
// with single flips counted: clean runs stayed below 2e-4 per window, the
// failing ones passed 4e-3 thousands of steps before they blew up and reached
// 0.1-0.5. A window above kFlipLimit (and kMinimumCount) stops the run with a
// diagnosis; the last checkpoint written before is kept (it may already carry
// the onset: resume it only with a remedy).
#include <cstddef>
#include <string>
#include <vector>

#include "engine/spheres/sphere_set.hpp"

namespace flocsim::run {

class CouplingMonitor {
 public:
  static constexpr double kLargeLoad = 10.0;  // |H| over the net weight W
  static constexpr int kWindowSteps = 500;
  static constexpr int kSustainedFlips = 3;
  // Clean runs' single reversals stayed below 2e-4 per window (sustained ones,
  // a subset, can only be fewer); failing runs crossed 1e-3 of sustained ones
  // at t = 28 a/U_inf (a = 4, nu = 0.01, N = 391).
  static constexpr double kFlipLimit = 1e-3;
  // And at least this many counts in the window, so that few spheres (one
  // settling sphere) are not stopped by a single event.
  static constexpr long kMinimumCount = 50;

  // One step's hydrodynamic loads H_s (force per step, the inside-momentum
  // change included) and the spheres' net weight |W| (the external force a
  // settling sphere's load holds up, spheres::external_force_per_sphere).
  // Returns a diagnosis when a window closes above the limit, else empty.
  std::string observe(const std::vector<spheres::Vec3>& loads, double net_weight);

  // The largest fraction of any closed window (since this start).
  double worst_window() const { return worst_; }

 private:
  std::vector<spheres::Vec3> previous_;
  std::vector<unsigned char> run_;  // flips in a row, per sphere
  long flips_ = 0, steps_ = 0;
  double worst_ = 0;
};

}  // namespace flocsim::run
