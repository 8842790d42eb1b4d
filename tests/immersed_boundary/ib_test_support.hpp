#pragma once
// Shared set-up of the immersed-boundary physics tests.
#include <gtest/gtest.h>

#include <string>

#include "engine/calibration/hydrodynamic_radius.hpp"

namespace flocsim::test {

// Input radius for hydrodynamic radius a from the shipped calibration table
// (engine/calibration/hydrodynamic_radius.json), interpolated in log nu as the
// solver does (CalibrationTable::input_radius).
inline double calibrated_input_radius(double a, double viscosity) {
  static const calibration::CalibrationTable table =
      calibration::CalibrationTable::load(FLOCSIM_CALIBRATION_TABLE);
  return table.input_radius(a, viscosity);
}

}  // namespace flocsim::test
