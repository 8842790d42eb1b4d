#pragma once
// Shared set-up of the immersed-boundary physics tests.
#include <gtest/gtest.h>

#include <string>

#include "engine/calibration/hydrodynamic_radius.hpp"

namespace flocsim::test {

// Input radius for hydrodynamic radius a from the calibration table compiled
// into the build (engine/calibration/hydrodynamic_radius.json), interpolated in
// log nu: the very call the solver makes (suspension_case.cpp).
inline double calibrated_input_radius(double a, double viscosity,
                                      const coupling::Scheme& scheme = {}) {
  return calibration::CalibrationTable::shipped().input_radius(a, viscosity, scheme);
}

}  // namespace flocsim::test
