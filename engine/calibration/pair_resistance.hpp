#pragma once
// The lattice's own radial resistance of a close pair of immersed-boundary
// spheres, measured once per (a, viscosity, immersed-boundary settings) like
// the hydrodynamic radius, so that the lubrication correction adds only what
// the lattice misses (docs/contacts.md, "Calibrated close-pair coefficient").
//
// Two spheres of hydrodynamic radius a sit at surface gap s on the x axis of a
// periodic box of 16a x 8a x 8a and are held there while moving at +-V along
// their line of centres (towards each other, or apart); the liquid starts at
// rest and the run goes on until the force is steady. No lubrication acts.
// lambda = F / (6 pi rho nu a V) is compared with Brenner's exact value for an
// isolated pair. The periodic images add a far-field part that hardly changes
// over s << L; it is read off at the largest gap measured (s = 0.5a, where the
// lattice resolves the gap by 2 dx or more and the pair is well described) as
// lambda_measured - lambda_exact and removed at every gap:
//   lambda_IB(s) = lambda_measured(s) - box_offset.
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "engine/coupling/scheme.hpp"

namespace flocsim::calibration {

struct PairResistanceSettings {
  double viscosity = 1.0 / 6.0;
  coupling::Scheme scheme;
  double box_over_a = 16;   // box 16a x 8a x 8a (rounded to whole cells)
  double reynolds = 0.01;   // 2 a V / nu: creeping flow
  double tolerance = 2e-6;  // steady: relative change of lambda per 200 steps
  long max_steps = 1000000;
  // The input radius a_g; 0: the shipped hydrodynamic-radius calibration's
  // for the scheme at a and nu (a scheme calibrated but not shipped at this a
  // is measured with its own calibration's a_g, given here).
  double input_radius = 0;
};

// One held pair at gap s (in units of a), from a liquid at rest; returns
// lambda_measured and the steps taken. Double precision, the shipped
// hydrodynamic-radius calibration of the scheme.
struct PairResistancePoint {
  double gap_over_a = 0;
  double lambda_measured = 0;  // box images included
  double lambda_exact = 0;     // Brenner (1961)
  long steps = 0;
};
PairResistancePoint measure_pair_resistance(double hydrodynamic_radius, double gap_over_a,
                                            bool separating, const PairResistanceSettings& s);

// The gaps a calibration measures by default (units of a); the last is where
// the box offset is read.
std::vector<double> default_pair_gaps();

struct PairResistanceEntry {
  double hydrodynamic_radius = 0;
  double viscosity = 0;
  coupling::Scheme scheme;
  int box = 0;  // length along the line of centres (dx); the cross-section is half
  bool separating = false;
  double input_radius = 0;                  // a_g the pair was measured with (0: not recorded)
  double box_offset = 0;                    // lambda_measured - lambda_exact at the largest gap
  std::vector<PairResistancePoint> points;  // increasing gap_over_a
  // lambda_IB(s/a) = lambda_measured - box_offset, linear between points, held
  // at the end values outside them.
  double lattice_share(double gap_over_a) const;
};

// All gaps in one box: each gap starts from the steady flow of the one before
// (the spheres moved, the liquid kept), which reaches the same steady state in
// a fraction of the steps from rest.
PairResistanceEntry calibrate_pair_resistance(
    double hydrodynamic_radius, const std::vector<double>& gaps, bool separating,
    const PairResistanceSettings& s, void (*progress)(const PairResistancePoint&) = nullptr);

// The held pair's tangential relative motions, which a bonded pair in an
// aggregate makes when it is sheared or rolled (docs/validation/bonded-pair.md);
// only measured, not calibrated: the lubrication correction acts along the line
// of centres only.
//   slide: sphere 0 moves at +V along y, sphere 1 at -V, neither rotates: the
//          facing surfaces slip past each other at 2V, the motion whose
//          resistance grows as ln(a/s) at contact;
//   roll:  neither translates, sphere 0 rotates at +V/a about z, sphere 1 at
//          -V/a: the facing surfaces both move at +V along y, no slip across
//          the gap (relative rolling, finite at contact).
enum class TangentialMotion { slide, roll };

// Force and torque on sphere 0 (at -x of the pair's centre), signed, in units
// of 6 pi rho nu a V and 8 pi rho nu a^2 V: an isolated sphere would read
// force_y = -1 when sliding and torque_z = -1 when rolling. The box's images
// are included (no offset removed).
struct PairTangentialPoint {
  double gap_over_a = 0;
  double force_y = 0;
  double torque_z = 0;
  long steps = 0;
};

// All gaps in one box, each from the steady flow of the one before.
std::vector<PairTangentialPoint> measure_pair_tangential(
    double hydrodynamic_radius, const std::vector<double>& gaps, TangentialMotion motion,
    const PairResistanceSettings& s,
    const std::function<void(const PairTangentialPoint&)>& progress = {});

// The `flocsim calibrate --close-pairs` command that makes the entry a case at
// radius a, viscosity nu and IB scheme lacks (a >= 6 in a 12a box, as the
// shipped a = 6 entries: a 16a box costs 2.4x more for the same lambda_IB
// once the box's offset is removed).
std::string close_pair_calibrate_command(double a, double nu, const coupling::Scheme& scheme);

class PairResistanceTable {
 public:
  static PairResistanceTable load(const std::string& filename);
  static PairResistanceTable parse(const std::string& json_text, const std::string& origin);
  // engine/calibration/pair_resistance.json at build time, compiled in.
  static const PairResistanceTable& shipped();
  void save(const std::string& filename) const;
  // Replaces an entry of the same a, nu, scheme and direction.
  void add(const PairResistanceEntry& entry);
  const std::vector<PairResistanceEntry>& entries() const { return entries_; }
  // Whether an approaching entry exists for this a and scheme.
  bool has(double hydrodynamic_radius, const coupling::Scheme& scheme = {}) const;
  // lambda_IB at the gaps of the calibration, (s/a, lambda_IB) in increasing
  // s/a, for a at nu: between the two approaching entries whose viscosities
  // bracket nu, linear in log(nu) at every gap; outside the calibrated
  // viscosities the nearest entry (no extrapolation). Throws std::out_of_range
  // naming what exists when no entry has this a and scheme.
  std::vector<std::pair<double, double>> lattice_share(double hydrodynamic_radius, double viscosity,
                                                       const coupling::Scheme& scheme = {}) const;
  // How far viscosity lies outside the calibrated ones for this a and scheme,
  // as a factor >= 1 (1 when two entries bracket it); infinity without entry.
  double viscosity_gap(double hydrodynamic_radius, double viscosity,
                       const coupling::Scheme& scheme = {}) const;
  std::string note;

 private:
  std::vector<PairResistanceEntry> entries_;
};

}  // namespace flocsim::calibration
