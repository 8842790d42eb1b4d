#pragma once
// Hydrodynamic radius of immersed-boundary spheres.
//
// Markers on a sphere of input radius a_g do not produce exactly the drag of
// a sphere of radius a_g: the kernel smears the surface over about 1.5 dx and
// the liquid inside moves with the surface. The effective (hydrodynamic)
// radius a is measured once per (a_g, viscosity, immersed-boundary settings):
// one fixed sphere in a periodic cube of edge L (a simple cubic array,
// chi = 2a/L) is driven by a small body force f until the creeping flow is
// steady; the drag coefficient K = F / (6 pi rho nu a U), with F = f L^3 and U
// the superficial velocity (lattice momentum / lattice mass), must then equal
// the Sangani & Acrivos (1982) value K(chi). That equation has one root in a,
// the hydrodynamic radius seen in that box. The calibration averages it over
// several chi and inverts a(a_g) so that the solver can ask for the input
// radius that gives a wanted hydrodynamic radius.
#include <string>
#include <vector>

#include "engine/coupling/scheme.hpp"

namespace flocsim::calibration {

// Sangani & Acrivos (1982) eq. 60, 31-term series in chi = 2a/L, for the
// Stokes drag of a simple cubic array, K = F / (6 pi mu a U). Valid for
// 0 <= chi < 1 (touching spheres at chi = 1).
double sangani_acrivos_drag(double chi);

// Hasimoto (1959) small-concentration form of the same: 1/K = 1 -
// 1.7601 phi^(1/3) + phi - 1.5593 phi^2, phi = (pi/6) chi^3.
double hasimoto_drag(double chi);

struct ArrayDragSettings {
  double viscosity = 1.0 / 6.0;  // lattice viscosity of the calibration runs
  coupling::Scheme scheme;
  double superficial_velocity = 1e-4;  // sets the body force through the reference K; Re << 1
  double tolerance = 1e-6;             // relative change of U per 100 steps at steady state
  long max_steps = 400000;
  // Where the sphere sits on the grid. Empty: at the cube's centre, 0.5 L in
  // each direction (how the direct-forcing entries were made). Otherwise one
  // run per value d, the centre at floor(L/2) + d in each direction (d = 0: on
  // a lattice node, 0.5: in the middle of a cell), and a box's hydrodynamic
  // radius is the mean over them: the radius a moving sphere has on average,
  // for schemes whose boundary depends on where it sits on the grid.
  std::vector<double> grid_offsets;
};

struct ArrayDragResult {
  double input_radius = 0;
  int box = 0;                      // L
  double grid_offset = -1;          // d of ArrayDragSettings::grid_offsets; -1: centred at 0.5 L
  double body_force = 0;            // f
  double superficial_velocity = 0;  // U
  double ib_force = 0;              // |H_x| on the sphere at the end (equals f L^3 when steady)
  long steps = 0;  // steps of this run (a calibration pass starts from the last flow)
  double hydrodynamic_radius = 0;  // root of K_measured(a) = K_SA(2a/L)
  // K for a given radius a: F / (6 pi nu a U).
  double drag_coefficient(double a, double viscosity) const;
};

// One fixed sphere of input radius a_g centred in a periodic cube of edge L
// (at floor(L/2) + grid_offset when that is >= 0), creeping flow driven along
// x, run to a steady state (double precision).
ArrayDragResult simple_cubic_array_drag(double input_radius, int box,
                                        const ArrayDragSettings& settings, double grid_offset = -1);

// The radius a for which F / (6 pi nu a U) = K_SA(2a/L).
double hydrodynamic_radius_from_drag(double force, double superficial_velocity, double viscosity,
                                     int box);

// One calibrated resolution: input radius that gives hydrodynamic radius a.
struct CalibrationEntry {
  double hydrodynamic_radius = 0;  // a (dx)
  double viscosity = 0;
  double input_radius = 0;  // a_g (dx)
  coupling::Scheme scheme;
  std::vector<ArrayDragResult> checks;  // the runs with the final a_g
  // The hydrodynamic radius each box gave: the mean over its runs (one per
  // grid offset), in the order the boxes were first run.
  std::vector<std::pair<int, double>> box_radii() const;
};

// Finds a_g for the wanted a: runs the boxes with a first guess, shifts a_g by
// the mean offset a - a_g measured, runs again, and goes on while the boxes'
// mean misses the wanted a by more than 0.01 dx (up to six passes; from the
// third on a secant step, for schemes whose offset moves with a_g).
// `progress` (may be empty) receives one line per run.
CalibrationEntry calibrate_input_radius(double hydrodynamic_radius, const std::vector<int>& boxes,
                                        const ArrayDragSettings& settings,
                                        void (*progress)(const ArrayDragResult&) = nullptr);

// The table the solver reads (JSON): entries by (a, nu).
class CalibrationTable {
 public:
  static CalibrationTable load(const std::string& filename);
  // The table as JSON text; `origin` names it in errors.
  static CalibrationTable parse(const std::string& json_text, const std::string& origin);
  // The table shipped with this build (engine/calibration/hydrodynamic_radius.json
  // at build time, compiled in).
  static const CalibrationTable& shipped();
  void save(const std::string& filename) const;
  void add(const CalibrationEntry& entry);
  const std::vector<CalibrationEntry>& entries() const { return entries_; }
  // The input radius for hydrodynamic radius a at viscosity nu: the entry with
  // the same a (within 1e-6 dx) and immersed-boundary scheme whose viscosity
  // is nearest to nu. Throws std::out_of_range, naming what exists, when no
  // entry has that a and scheme.
  const CalibrationEntry& lookup(double hydrodynamic_radius, double viscosity,
                                 const coupling::Scheme& scheme = {}) const;
  // Whether any entry has this a and scheme.
  bool has(double hydrodynamic_radius, const coupling::Scheme& scheme) const;
  // The input radius for a at nu: between the two entries (same a and
  // scheme) whose viscosities bracket nu, a_g interpolated linearly in
  // log(nu) (the offset a - a_g varies smoothly with log nu: 0.431 to 0.388 dx
  // from nu = 0.005 to 1/6 at a = 6); outside the calibrated viscosities, the
  // nearest entry's a_g (no extrapolation). Throws like lookup().
  double input_radius(double hydrodynamic_radius, double viscosity,
                      const coupling::Scheme& scheme = {}) const;
  std::string note;  // how the table was made

 private:
  std::vector<CalibrationEntry> entries_;
};

}  // namespace flocsim::calibration
