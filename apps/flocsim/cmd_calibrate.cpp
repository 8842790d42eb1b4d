// flocsim calibrate: hydrodynamic radius of the immersed-boundary spheres.
//
//   flocsim calibrate --radius 4 6 8 12 --viscosity 0.1667 --table FILE
//
// For each wanted hydrodynamic radius a, runs one fixed sphere in periodic
// cubes (simple cubic arrays at chi = 2a/L of about 0.35, 0.5 and 0.7 unless
// --boxes is given) in creeping flow, finds the input radius a_g whose drag
// matches Sangani & Acrivos, and adds the entry to the table (read first when
// it exists, so tables grow one resolution at a time).
//
//   flocsim calibrate --close-pairs --radius 4 6 --viscosity 0.02 --table FILE
//
// measures instead the lattice's own radial resistance of a held pair of
// spheres at the gaps of --gaps (default 0.005a to 0.5a), approaching (or
// --separating), against Brenner's exact series: the close-pair calibration
// that the lubrication correction subtracts (docs/contacts.md).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "apps/flocsim/command_registry.hpp"
#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/calibration/pair_resistance.hpp"
#include "engine/calibration/table_file.hpp"
#include "engine/input/input_reader.hpp"

namespace flocsim::app {
namespace {

struct CalibrateOptions {
  std::vector<double> radii;
  std::vector<int> boxes;
  std::vector<double> chis = {0.35, 0.5, 0.7};
  double viscosity = 1.0 / 6.0;
  double marker_spacing = coupling::kPaperScheme.marker_spacing;
  int sweeps = coupling::kPaperScheme.sweeps;
  std::string kernel = "roma3";
  std::string method = "immersed-boundary";
  std::string forcing = "direct";
  std::vector<double> gains;  // control forcing: integral, proportional
  std::vector<double> grid_offsets;
  double tolerance = 1e-6;
  std::string table;
  bool close_pairs = false;
  bool separating = false;
  std::vector<double> gaps;
  double pair_box_over_a = 16;
  double input_radius = 0;  // close pairs: a_g by hand (0: the shipped calibration's)
};

coupling::Scheme scheme_of(const CalibrateOptions& o) {
  coupling::Scheme s;
  s.method = *coupling::method_from_name(o.method);
  s.marker_spacing = o.marker_spacing;
  s.sweeps = o.sweeps;
  s.kernel = *coupling::kernel_from_name(o.kernel);
  s.forcing = *coupling::forcing_from_name(o.forcing);
  if (s.control()) {
    s.sweeps = 1;
    if (o.gains.size() == 2) s.gains = {o.gains[0], o.gains[1]};
  }
  return s;
}

void print_pair_point(const calibration::PairResistancePoint& p) {
  std::printf("  s/a = %6.3f  lambda = %9.4f  exact %9.4f  steps %7ld\n", p.gap_over_a,
              p.lambda_measured, p.lambda_exact, p.steps);
  std::fflush(stdout);
}

int run_pair_calibration(const CalibrateOptions& o) {
  const std::string note =
      "The lattice's own radial resistance lambda of two immersed-boundary spheres held at gap s "
      "and moved towards each other at +-V (Re = 2aV/nu = 0.01), box L x L/2 x L/2 (L, the "
      "box field of each entry, is 16a or 12a), double precision, steady to 2e-6 per 200 steps, "
      "against Brenner's (1961) exact lambda. box_offset "
      "(measured minus exact at the largest gap) is the periodic images' share, removed at every "
      "gap. Made by `flocsim calibrate --close-pairs`; see docs/contacts.md.";
  calibration::PairResistanceSettings s;
  s.viscosity = o.viscosity;
  s.scheme = scheme_of(o);
  s.box_over_a = o.pair_box_over_a;
  s.input_radius = o.input_radius;
  const auto gaps = o.gaps.empty() ? calibration::default_pair_gaps() : o.gaps;
  for (double a : o.radii) {
    std::printf("close pair, a = %g dx, nu = %g, %s, %s:\n", a, o.viscosity,
                o.separating ? "separating" : "approaching", s.scheme.describe().c_str());
    const auto e =
        calibration::calibrate_pair_resistance(a, gaps, o.separating, s, print_pair_point);
    std::printf("=> box offset %+.4f (at s/a = %g); lambda_IB = measured - offset\n", e.box_offset,
                gaps.back());
    // under the table's lock, with what other calibrations added meanwhile
    calibration::add_to_table_file(o.table, e, note);
  }
  std::printf("table written to %s\n", printable(o.table).c_str());
  return kExitOk;
}

std::string number_text(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

// The cube edges of the radius calibration at a: --boxes, else chi = 2a/L of
// 0.35, 0.5 and 0.7.
std::vector<int> boxes_of(const CalibrateOptions& o, double a) {
  std::vector<int> boxes = o.boxes;
  if (boxes.empty())
    for (double chi : o.chis) boxes.push_back(static_cast<int>(std::lround(2.0 * a / chi)));
  return boxes;
}

void print_run(const calibration::ArrayDragResult& r) {
  char where[32] = "";
  if (r.grid_offset >= 0) std::snprintf(where, sizeof where, "  d = %.2f", r.grid_offset);
  std::printf(
      "  a_g = %.4f  L = %3d%s  chi = %.3f  steps = %6ld  U = %.6e  a = %.4f  (a - a_g = %+.4f)\n",
      r.input_radius, r.box, where, 2.0 * r.hydrodynamic_radius / r.box, r.steps,
      r.superficial_velocity, r.hydrodynamic_radius, r.hydrodynamic_radius - r.input_radius);
  std::fflush(stdout);
}

int run_radius_calibration(const CalibrateOptions& o) {
  const std::string note =
      "Hydrodynamic radius a of immersed-boundary spheres (multi-direct forcing; each entry names "
      "its marker spacing, sweeps ('iterations') and kernel) against input radius a_g. Made by "
      "`flocsim calibrate`: one fixed sphere in periodic cubes "
      "(simple cubic arrays), creeping flow (U = 1e-4, Re < 0.02), steady to 1e-6 per 100 steps; a "
      "is "
      "the radius for which F/(6 pi nu a U) equals the Sangani-Acrivos (1982) K(2a/L), averaged "
      "over the "
      "boxes listed in each entry. See docs/immersed-boundary.md.";
  calibration::ArrayDragSettings s;
  s.viscosity = o.viscosity;
  s.scheme = scheme_of(o);
  s.tolerance = o.tolerance;
  s.grid_offsets = o.grid_offsets;
  for (double a : o.radii) {
    const std::vector<int> boxes = boxes_of(o, a);
    std::printf("hydrodynamic radius a = %g dx, nu = %g, %s:\n", a, o.viscosity,
                s.scheme.describe().c_str());
    const auto entry = calibration::calibrate_input_radius(a, boxes, s, print_run);
    double spread = 0;
    for (const auto& [box, radius] : entry.box_radii())
      spread = std::max(spread, std::abs(radius - a));
    std::printf("=> a_g = %.4f for a = %g (largest box deviation %.4f dx)\n", entry.input_radius, a,
                spread);
    // the passes stop when the boxes' mean radius is within 0.01 dx of a, or
    // after six; a table entry that missed is kept (the work is not lost) but
    // said to be unconverged, so nobody ships it by mistake
    double mean = 0;
    for (const auto& [box, radius] : entry.box_radii()) mean += radius;
    mean /= static_cast<double>(entry.box_radii().size());
    if (std::abs(mean - a) > 0.01)
      std::fprintf(stderr,
                   "flocsim calibrate: warning: not converged for a = %g: after six passes the "
                   "boxes' mean radius is %.4f (%+.4f dx from a, more than 0.01); the entry is "
                   "written with the last a_g but should not be shipped: rerun, or give --boxes "
                   "or --grid-offsets\n",
                   a, mean, mean - a);
    // after every radius, so a long calibration keeps what it has; under the
    // table's lock, with what other calibrations added meanwhile
    calibration::add_to_table_file(o.table, entry, note);
  }
  std::printf("table written to %s\n", printable(o.table).c_str());
  return kExitOk;
}

// Refuses, before any work, what the chosen calibration would not use or
// could not write: an option of the other calibration, a table that is not
// one of this kind or cannot be written (engine/calibration/table_file.hpp).
void check_before_work(const CalibrateOptions& o, const CLI::App& cmd) {
  const std::vector<const char*> pair_only = {"--separating", "--gaps", "--pair-box",
                                              "--input-radius"};
  const std::vector<const char*> radius_only = {"--boxes", "--tolerance", "--grid-offsets"};
  for (const char* name : o.close_pairs ? radius_only : pair_only)
    if (cmd.get_option(name)->count() > 0)
      throw input::InputError(
          std::string(name) +
          (o.close_pairs ? ": only for the hydrodynamic-radius calibration (without "
                           "--close-pairs); the close-pair calibration does not use it"
                         : ": only with --close-pairs; the hydrodynamic-radius calibration "
                           "does not use it"));
  // options of a scheme other than the one chosen: refused, not ignored
  auto given = [&](const char* name) { return cmd.get_option(name)->count() > 0; };
  const coupling::Scheme scheme = scheme_of(o);
  if (!scheme.immersed_boundary())
    for (const char* name : {"--marker-spacing", "--sweeps", "--kernel", "--forcing", "--gains"})
      if (given(name))
        throw input::InputError(std::string(name) +
                                ": only with --coupling immersed-boundary (partially saturated "
                                "cells have no markers)");
  if (given("--gains") && !scheme.control())
    throw input::InputError("--gains: only with --forcing control");
  if (given("--sweeps") && scheme.control())
    throw input::InputError("--sweeps: control forcing makes one correction per step");
  if (scheme.control() && scheme.marker_spacing < coupling::kSmallestControlMarkerSpacing)
    throw input::InputError("--marker-spacing " + number_text(scheme.marker_spacing) +
                            " with --forcing control: " + coupling::dense_control_markers_why());
  if (scheme.control() && !coupling::stable_gains(scheme.gains))
    throw input::InputError("--gains " + number_text(scheme.gains.integral) + " " +
                            number_text(scheme.gains.proportional) + ": " +
                            coupling::stable_gains_region());
  for (std::size_t k = 1; k < o.gaps.size(); ++k)
    if (!(o.gaps[k] > o.gaps[k - 1]))
      throw input::InputError("--gaps: must increase (the last gives the box offset), got " +
                              number_text(o.gaps[k - 1]) + " then " + number_text(o.gaps[k]));
  // The last gap's measured-minus-exact is taken as the box's own share at
  // every gap, which holds only where the lattice's close-pair share has died
  // out: at 0.1a it still holds most of it (a = 6, control forcing: +2.93
  // against +0.20 at 0.5a).
  const double offset_gap = calibration::default_pair_gaps().back();
  if (!o.gaps.empty() && o.gaps.back() < offset_gap)
    throw input::InputError(
        "--gaps: the last gap, " + number_text(o.gaps.back()) +
        ", gives the box offset (measured minus exact resistance there), which is the box's own "
        "share only where the lattice's close-pair share has died out: the last gap must be >= " +
        number_text(offset_gap) + " (add " + number_text(offset_gap) + ")");
  // a sphere must not reach its own periodic image: the immersed boundary
  // needs L > 2 a_g + 3 (its kernel), partially saturated cells
  // L > 2 (a_g + sqrt(3)/2); checked here for the first pass's a_g = a - 0.3
  // (the couplings refuse it themselves, but only once a run starts)
  if (!o.close_pairs)
    for (double a : o.radii) {
      const double ag = a - 0.3;
      const bool markers = o.method == coupling::method_name(coupling::Method::immersed_boundary);
      const double reach = markers ? 2 * ag + 3 : 2 * (ag + 0.8660254037844386);
      for (int box : boxes_of(o, a))
        if (box <= reach)
          throw input::InputError(
              (o.boxes.empty() ? "the default box " + std::to_string(box) + " (chi = 2a/L of " +
                                     "0.35, 0.5, 0.7)"
                               : "--boxes " + std::to_string(box)) +
              " for --radius " + number_text(a) + ": a cube must exceed " +
              (markers ? "2 a_g + 3 = " : "2 (a_g + sqrt(3)/2) = ") + number_text(reach) +
              " dx with the first input radius tried, a_g = a - 0.3 (a sphere must not reach its "
              "own periodic image); give --boxes with larger edges");
    }
  calibration::check_table_file(o.table, o.close_pairs
                                             ? calibration::TableKind::close_pair
                                             : calibration::TableKind::hydrodynamic_radius);
}

int run_calibrate(const CalibrateOptions& o, const CLI::App& cmd) {
  try {
    check_before_work(o, cmd);
  } catch (const input::InputError& e) {
    std::cerr << "flocsim calibrate: " << printable(e.what()) << "\n";
    return kExitBadInput;
  }
  return o.close_pairs ? run_pair_calibration(o) : run_radius_calibration(o);
}

const bool registered = register_command(
    {"calibrate",
     "Calibrate the hydrodynamic radius of immersed-boundary spheres (simple cubic arrays)",
     [](CLI::App& cmd) -> CommandHandler {
       auto o = std::make_shared<CalibrateOptions>();
       cmd.add_option("--radius", o->radii, "wanted hydrodynamic radii a (dx)")
           ->required()
           ->check(finite_number(2.0, 40.0));
       cmd.add_option("--viscosity", o->viscosity, "lattice viscosity of the calibration runs")
           ->check(finite_number(0.005, 0.5));
       cmd.add_option("--boxes", o->boxes,
                      "cube edges L (dx); default: chi = 2a/L of 0.35, 0.5, 0.7")
           ->check(CLI::Range(8, 400));
       cmd.add_option("--marker-spacing", o->marker_spacing,
                      "marker spacing (dx); default 0.7 (direct forcing), 1 (control forcing)")
           ->check(finite_number(0.3, 1.5));
       cmd.add_option("--sweeps,--iterations", o->sweeps, "direct-forcing sweeps per step")
           ->check(CLI::Range(1, 20));
       cmd.add_option("--kernel", o->kernel, "interpolation/spreading kernel")
           ->check(CLI::IsMember(coupling::kernel_names()));
       cmd.add_option("--coupling", o->method, "coupling scheme of the spheres and the liquid")
           ->check(CLI::IsMember(coupling::method_names()));
       cmd.add_option("--forcing", o->forcing,
                      "immersed boundary: direct forcing (--sweeps) or control forcing (--gains)")
           ->check(CLI::IsMember(coupling::forcing_names()));
       cmd.add_option("--gains", o->gains,
                      "control forcing: integral and proportional gain (docs/coupling.md)")
           ->expected(2)
           ->check(finite_number(0.0, 1e6));
       cmd.add_option("--grid-offsets", o->grid_offsets,
                      "run each box with the sphere's centre at floor(L/2) + d for each d (0: on a "
                      "node, 0.5: mid-cell) and average: for schemes whose boundary depends on "
                      "where it sits on the grid (default: centred at L/2, one run)")
           ->check(finite_number(0.0, 1.0));
       cmd.add_option("--tolerance", o->tolerance,
                      "steady state: relative change of U per 100 steps")
           ->check(finite_number(1e-10, 1e-3));
       cmd.add_flag("--close-pairs", o->close_pairs,
                    "measure the lattice's own close-pair resistance instead (lubrication "
                    "calibration)");
       cmd.add_flag("--separating", o->separating, "with --close-pairs: spheres moving apart");
       cmd.add_option("--gaps", o->gaps,
                      "with --close-pairs: gaps s/a, increasing; the last, >= 0.5, "
                      "gives the box offset (default 0.005 ... 0.5)")
           ->check(finite_number(1e-4, 2.0));
       cmd.add_option("--pair-box", o->pair_box_over_a,
                      "with --close-pairs: box length along the pair in units of a (cross-section "
                      "half of it)")
           ->check(finite_number(8.0, 64.0));
       cmd.add_option("--input-radius", o->input_radius,
                      "with --close-pairs: the spheres' input radius a_g (default: the shipped "
                      "calibration's for the scheme at --radius and --viscosity)")
           ->check(finite_number(1.0, 40.0));
       cmd.add_option("--table", o->table, "calibration table (JSON), read and extended")
           ->required();
       return [o, &cmd] {
         // control forcing's markers default to its own spacing, not the paper's
         if (o->forcing == coupling::forcing_name(coupling::Forcing::control) &&
             cmd.get_option("--marker-spacing")->count() == 0)
           o->marker_spacing = coupling::kControlScheme.marker_spacing;
         return run_calibrate(*o, cmd);
       };
     }});

}  // namespace
}  // namespace flocsim::app
