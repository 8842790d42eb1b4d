// flocsim calibrate: hydrodynamic radius of the immersed-boundary spheres.
//
//   flocsim calibrate --radius 4 6 8 12 --viscosity 0.1667 --table FILE
//
// For each wanted hydrodynamic radius a, runs one fixed sphere in periodic
// cubes (simple cubic arrays at chi = 2a/L of about 0.35, 0.5 and 0.7 unless
// --boxes is given) in creeping flow, finds the input radius a_g whose drag
// matches Sangani & Acrivos, and adds the entry to the table (read first when
// it exists, so tables grow one resolution at a time).
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "apps/flocsim/command_registry.hpp"
#include "engine/calibration/hydrodynamic_radius.hpp"

namespace flocsim::app {
namespace {

struct CalibrateOptions {
  std::vector<double> radii;
  std::vector<int> boxes;
  std::vector<double> chis = {0.35, 0.5, 0.7};
  double viscosity = 1.0 / 6.0;
  double marker_spacing = 0.7;
  int iterations = 2;
  double tolerance = 1e-6;
  std::string table;
};

void print_run(const calibration::ArrayDragResult& r) {
  std::printf(
      "  a_g = %.4f  L = %3d  chi = %.3f  steps = %6ld  U = %.6e  a = %.4f  (a - a_g = %+.4f)\n",
      r.input_radius, r.box, 2.0 * r.hydrodynamic_radius / r.box, r.steps, r.superficial_velocity,
      r.hydrodynamic_radius, r.hydrodynamic_radius - r.input_radius);
  std::fflush(stdout);
}

int run_calibrate(const CalibrateOptions& o) {
  calibration::CalibrationTable table;
  if (std::filesystem::exists(o.table)) table = calibration::CalibrationTable::load(o.table);
  table.note =
      "Hydrodynamic radius a of immersed-boundary spheres (Roma 3-point kernel, multi-direct "
      "forcing) "
      "against input radius a_g. Made by `flocsim calibrate`: one fixed sphere in periodic cubes "
      "(simple cubic arrays), creeping flow (U = 1e-4, Re < 0.02), steady to 1e-6 per 100 steps; a "
      "is "
      "the radius for which F/(6 pi nu a U) equals the Sangani-Acrivos (1982) K(2a/L), averaged "
      "over the "
      "boxes listed in each entry. See docs/immersed-boundary.md.";
  calibration::ArrayDragSettings s;
  s.viscosity = o.viscosity;
  s.marker_spacing = o.marker_spacing;
  s.iterations = o.iterations;
  s.tolerance = o.tolerance;
  for (double a : o.radii) {
    std::vector<int> boxes = o.boxes;
    if (boxes.empty())
      for (double chi : o.chis) boxes.push_back(static_cast<int>(std::lround(2.0 * a / chi)));
    std::printf("hydrodynamic radius a = %g dx, nu = %g:\n", a, o.viscosity);
    const auto entry = calibration::calibrate_input_radius(a, boxes, s, print_run);
    double spread = 0;
    for (const auto& c : entry.checks)
      spread = std::max(spread, std::abs(c.hydrodynamic_radius - a));
    std::printf("=> a_g = %.4f for a = %g (largest box deviation %.4f dx)\n", entry.input_radius, a,
                spread);
    table.add(entry);
    table.save(o.table);  // after every radius, so a long calibration keeps what it has
  }
  std::printf("table written to %s\n", o.table.c_str());
  return kExitOk;
}

const bool registered = register_command(
    {"calibrate",
     "Calibrate the hydrodynamic radius of immersed-boundary spheres (simple cubic arrays)",
     [](CLI::App& cmd) -> CommandHandler {
       auto o = std::make_shared<CalibrateOptions>();
       cmd.add_option("--radius", o->radii, "wanted hydrodynamic radii a (dx)")
           ->required()
           ->check(CLI::Range(2.0, 40.0));
       cmd.add_option("--viscosity", o->viscosity, "lattice viscosity of the calibration runs")
           ->check(CLI::Range(0.005, 0.5));
       cmd.add_option("--boxes", o->boxes,
                      "cube edges L (dx); default: chi = 2a/L of 0.35, 0.5, 0.7")
           ->check(CLI::Range(8, 400));
       cmd.add_option("--marker-spacing", o->marker_spacing, "marker spacing (dx)")
           ->check(CLI::Range(0.3, 1.0));
       cmd.add_option("--iterations", o->iterations, "direct-forcing iterations per step")
           ->check(CLI::Range(1, 20));
       cmd.add_option("--tolerance", o->tolerance,
                      "steady state: relative change of U per 100 steps")
           ->check(CLI::Range(1e-10, 1e-3));
       cmd.add_option("--table", o->table, "calibration table (JSON), read and extended")
           ->required();
       return [o] { return run_calibrate(*o); };
     }});

}  // namespace
}  // namespace flocsim::app
