#pragma once
// Cases with spheres (docs/model.md sections 2-3): the dimensionless inputs of the
// paper's Table 1, numerics and run protocol, converted to lattice units.
//
//   {"scene": "suspension", "fidelity": "standard",
//    "phi": 0.20, "Re_inf": 12, "du_over_Uinf": 0.02,
//    "numerics": {"a_over_dx": 6}, "protocol": {"statistics": 100}}
//
// Scenes: suspension (the full model), fixed-array (spheres held still),
// single-sphere, granular (spheres with direct interactions and no liquid).
// Fidelity presets set resolution, domain size and durations; any field given
// explicitly overrides its preset value. Format: docs/user-guide.md.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/case/device.hpp"
#include "engine/case/scene.hpp"
#include "engine/coupling/scheme.hpp"
#include "engine/lattice/fluid_lattice.hpp"

namespace flocsim::cases {

// Largest single-sphere settling velocity U_inf accepted, in lattice units:
// the largest measured free of a Mach-number error (docs/accuracy-cost.md,
// "The lattice Mach number"). Settling suspensions (a = 4, phi 0.2, Re_inf 12,
// four seeds) kept F within 1 % of its value at U_inf = 0.015 up to 0.07, with
// and without the square well; at 0.1 F rose 1.7-1.8 % (two seeds), past the
// paper's 1.5 % resolution tolerance. The runs' last field snapshots at 0.07
// hold liquid speeds up to 1.2-2.1 U_inf (Ma = |u| sqrt(3) up to 0.25).
inline constexpr double kMaxSettlingVelocity = 0.07;
// The same for a scene without liquid (granular), which has no Mach number:
// it starts Maxwellian with U_inf per component, and the runs' sphere speed
// check (0.3 per step) must stay far out in that distribution's tail: 6 U_inf
// at 0.05 (at 0.07, 4.3 U_inf, a granular gas of 61 spheres reached it).
inline constexpr double kMaxSettlingVelocityWithoutLiquid = 0.05;
// With more than one immersed-boundary sweep, the smallest viscosity at which
// moving spheres were measured free of the coupling's period-2 oscillation
// (docs/numerics.md): 0.0133 = U_inf 0.02 at a = 4 and Re_inf 12 (clean for
// 80 a/U_inf, where nu = 0.01 oscillated from t = 26). At a = 6 the onset
// sits at the same viscosity (16a x 8a x 8a boxes, phi 0.32 and 0.2, Re_inf
// 36-72): nu 0.0067 stopped by the coupling monitor at both phi, 0.01 at or
// over its limit at Re_inf 72; at 0.0133 a run of the paper's length (600
// a/U_inf, phi 0.32, Re_inf 60) completed with its worst window at 0.72 of
// the limit. So one floor at every resolution (at a = 8 one probe on it, phi
// 0.32, Re_inf 72, 200 a/U_inf: 0.31 of the limit; above a = 8 assumed); the
// monitor stops a run that crosses it all the same.
inline constexpr double kSmallestMultiSweepViscosity = 0.04 / 3;
// Largest lattice viscosity accepted in a scene with liquid, whether given
// (numerics.viscosity) or implied by Re_inf and U_inf (nu = 2 a U_inf /
// Re_inf): one rule, the viscosity ceiling (docs/numerics.md, "Viscosity
// ceiling"). Measured at a = 4 against runs at nu = 1/6 (tau = 1, the largest
// calibrated viscosity) with the same Re_inf: a single sphere settled 0.7 %
// fast at nu 0.2, 1.8 % at 0.25, 2.8 % at 0.3, 3.1 % at 0.5 and blew up at
// 0.75 and 1; suspensions (phi 0.1) ran at 0.2 (three seeds) and blew up
// within 10 a/U_inf at 0.25, 0.3, 0.5, 0.75 and 1.
inline constexpr double kLargestViscosity = 0.2;

// Smallest viscosity at which the coupled solver (lattice, immersed boundary,
// spheres) is measured stable at a resolution of a_over_dx cells per radius:
// 0.005 (tau = 0.515) from a = 6 dx up, 0.01 below (docs/numerics.md,
// "Stability floor": at a = 4, 21 of 25 suspensions at nu = 0.005-0.008
// blew up within 20 a/U_inf, none of 6 at nu = 0.01; at a = 6 and 8, none of
// 7 at nu = 0.005).
double smallest_stable_viscosity(double radius_cells);

// The physical problem as the user states it: the dimensionless groups of the
// paper's Table 1, the domain's shape in radii, and the lubrication model (the
// case file's top-level numbers and model choices).
struct Physics {
  double phi = 0.20;                            // requested solids fraction
  double reynolds_inf = 12;                     // Re_inf = U_inf 2a / nu
  double density_ratio = 4.0;                   // rho_p / rho
  double du_over_uinf = 0.0;                    // square-well strength
  double delta_over_a = 0.025;                  // square-well width
  double restitution = 1.0;                     // e
  double friction = 0.0;                        // mu_f
  double lubrication_onset_over_a = 0.2;        // s0 / a
  double lubrication_saturation_over_a = 2e-4;  // s1 / a
  // "calibrated": the exact two-sphere resistance minus the lattice's own
  // measured share (shipped close-pair calibration, docs/contacts.md);
  // "nguyen-ladd": (3/2) pi rho nu a^2 (1/s - 1/s0), which assumes the lattice
  // resolves nothing more below s0 and so counts part of the resistance twice.
  // A case file defaults to "calibrated" (parse_suspension_case fills the
  // lattice's share); a struct built in code has no share, so its default is
  // the model that needs none.
  std::string lubrication_model = "nguyen-ladd";
  // "implicit": backward Euler per pair, never reverses an approach;
  // "explicit-paper": forward Euler as in the paper, which can (for comparison).
  std::string lubrication_integration = "implicit";
  double length_over_a = 48;     // L / a
  double length_over_width = 2;  // L / W
};

// How the problem is discretised: the case file's "numerics" (and "precision"),
// with what the shipped calibrations give for this resolution and viscosity.
struct Numerics {
  bool single_precision = false;
  double radius_cells = 6;  // hydrodynamic radius a / dx
  double viscosity = 0;     // lattice nu (derived when not given)
  double trt_magic = 0.25;
  // numerics.inside_liquid: how a sphere's equation of motion accounts for the
  // liquid that stays on the lattice inside it. "measured" (default): the
  // change of its momentum as the lattice carries it (Kempe & Froehlich 2012;
  // Breugem 2012). "rigid-body": assumed to move with the sphere, so the
  // sphere's translation sees the mass m_p - m_liquid (ten Cate et al. 2002,
  // the method the paper cites), for comparisons; rotation stays measured.
  std::string inside_liquid = "measured";
  // numerics.immersed_boundary: marker spacing, forcing sweeps, kernel; the
  // preset's default, and only schemes the shipped calibration holds at this a
  coupling::Scheme coupling;
  // Marker radius a_g of the immersed boundary, which gives hydrodynamic
  // radius a: numerics.input_radius, or looked up in the shipped calibration
  // table (engine/calibration), interpolated in log(nu) between the calibrated
  // viscosities around this one (the nearest entry's a_g outside them).
  double input_radius = 0;
  bool input_radius_given = false;
  double calibration_viscosity = 0;  // viscosity of the nearest table entry
  // lubrication_model calibrated: the lattice's share lambda_IB(s/a) at this a
  // and nu, (s/a, lambda_IB) from the shipped close-pair table, interpolated in
  // log(nu) between the calibrated viscosities around this one
  std::vector<std::pair<double, double>> lubrication_lattice_share;
};

// The run protocol, the case file's "protocol" (durations in a / U_inf).
struct Protocol {
  double stage1_min = 20;     // du = 0 stage: at least this long ...
  double stage1_max = 100;    // ... until stationary, at most this long
  double stage2_settle = 50;  // du at target: before statistics start
  double statistics = 100;    // averaging window
  double sample_every = 0.5;  // time-series cadence
  double stationarity_window = 20;
  double checkpoint_every_s = 600;
  double snapshot_every = 10;  // sphere snapshots, a / U_inf (0: none)
  double progress_every_s = 2;
  int threads = 0;
};

// What the solver steps with: Physics and Numerics in lattice units
// (dx = dt = 1, rho = 1). Never read from the case file.
struct Derived {
  lattice::Extent box;            // cells: L x W x W
  int sphere_count = 0;           // N
  double phi_realised = 0;        // N (4/3) pi a^3 / V
  double settling_velocity = 0;   // U_inf (numerics.U_inf when given)
  double drag_coefficient = 0;    // C_D (Schiller-Naumann at Re_inf)
  double gravity = 0;             // g
  double convective_time = 0;     // a / U_inf in time steps
  double escape_velocity = 0;     // du
  double well_width = 0;          // delta
  double liquid_body_force = 0;   // f = (rho_bar - rho) g, along +x
  double sphere_net_gravity = 0;  // (rho_p - rho_bar) V_p g, acting along -x
};

struct SuspensionCase {
  Scene scene = Scene::suspension;
  Device device = Device::cpu;  // "device": where the lattice and its coupling step (device.hpp)
  std::string fidelity = "standard";
  std::uint64_t seed = 1;

  // fixed-array only: hold the spheres of this run's snapshot
  // (spheres/step_N.h5) still instead of placing them at random (paper Fig. 1b)
  std::string positions_from;
  // positions_from_box: the snapshot's box in cells, for snapshots written
  // before they recorded it (empty when not given); must be this case's box
  std::vector<double> positions_from_box;
  std::vector<double> initial_positions;  // its centres, x y z per sphere

  Physics physics;
  Numerics numerics;
  Protocol protocol;
  Derived derived;

  std::vector<std::string> warnings;

  nlohmann::json to_json() const;       // the canonical case, defaults filled in
  nlohmann::json derived_json() const;  // the lattice-unit quantities, for logs and result.json
};

// Validates everything before any work starts; throws input::InputError that
// names the field, the value and the allowed range.
SuspensionCase parse_suspension_case(const nlohmann::json& document);

// numerics.immersed_boundary as a case file writes it: {marker_spacing, sweeps, kernel}.
nlohmann::json immersed_boundary_json(const coupling::Scheme& scheme);

// A resolved case (result.json's or a checkpoint's "case") as the current
// version writes it: fields that older versions did not write had one value
// each then. numerics.immersed_boundary was the paper's method; a lubricated
// scene's lubrication_model was Nguyen-Ladd's, integrated implicitly. Scenes
// without lubrication carry those fields (with whatever default their version
// had) but do not use them, so they are removed. Used wherever two runs' models are compared
// (resume, F/F0 baselines).
nlohmann::json with_older_versions_models(nlohmann::json resolved_case);

// Schiller-Naumann: C_D = 24/Re (1 + 0.15 Re^0.687).
double schiller_naumann_drag_coefficient(double reynolds);

}  // namespace flocsim::cases
