// Reads a sphere scene's case file into a SuspensionCase, once, in this order
// (parse_suspension_case, near the end): the fields checked against their
// table (case_fields.hpp); identity and the fidelity preset (preset(), with
// why each preset's values); physics; the velocity scale and the coupling
// scheme, moved onto the numerical limits where the case leaves them to it
// (numerics_limits.hpp); the calibrated marker radius and close pairs; the
// protocol; then the derived box, sphere count and forces, and the checks that
// refuse what cannot run. The canonical form (to_json) and older versions'
// models close the file.
#include "engine/case/suspension_case.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/calibration/pair_resistance.hpp"
#include "engine/calibration/table_scheme.hpp"
#include "engine/case/case_fields.hpp"
#include "engine/case/case_support.hpp"
#include "engine/case/fluid_case.hpp"
#include "engine/case/numerics_limits.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/output/hdf5_file.hpp"

namespace flocsim::cases {

using input::InputError;
using input::InputReader;
using input::Range;

namespace {

// A calibration entry counts as near the case's viscosity within this factor
// (rounding allowed: nu = 0.005 against an entry at 0.01 is near).
constexpr double kNearViscosityFactor = 2.0 * (1 + 1e-9);

// Resolution, domain and durations of each fidelity preset. The paper preset
// is the paper's default case (a = 6 dx, L = 48a, L/W = 2); standard keeps
// the resolution and shrinks the domain (the paper saw <= 4 % domain-size
// effect on F); draft is for quick looks and CI.
// Immersed boundary: draft and standard take the cheaper one-sweep option
// (its drag on frozen random arrays at phi = 0.2 is the paper method's to
// 0.01 %, within the paper's 1.5 % resolution tolerance; docs/accuracy-cost.md)
// where it is validated, phi <= 0.2; paper keeps the paper's method.
// Settling velocity U_inf (used when neither numerics.U_inf nor
// numerics.viscosity is given; steps per a/U_inf = a / U_inf): the largest
// U_inf whose results stay within 1.5 % (F) and the seeds' scatter (the rest)
// of U_inf = 0.015 is 0.07 (docs/accuracy-cost.md, "The lattice Mach
// number"), but a preset takes it only where its calibrations cover the
// viscosities nu = 2 a U_inf / Re_inf of the paper's grid (Re_inf 6-72;
// tests/run/paper_grid_test.cpp holds every point to it):
// - draft (a = 4) takes 0.07, the configuration that was measured: its
//   viscosities, 0.0117-0.093, lie within a factor 2 of close-pair
//   calibrations (at Re_inf 6 through the paper's method, whose table reaches
//   0.08; the one-sweep table stops at 0.04).
// - standard (a = 6) takes 0.04: nu = 12 U_inf / Re_inf puts Re_inf 6 on
//   0.08. The a = 6 close-pair tables now reach 0.08, so 0.07 (Re_inf 6 on
//   0.14, 1.75 away) would be covered too, but its accuracy at a = 6 has not
//   been compared with 0.04 in a suspension yet.
// - paper keeps 0.02, inside the paper's own range (0.01-0.03), raised where
//   nu would fall below the paper's method's floor (Re_inf above 18 at a = 6;
//   check_multi_sweep_floor).
// A scene without liquid has no Mach number to trade (below).
struct Preset {
  double radius_cells, length_over_a, stage1_min, stage1_max, stage2_settle, statistics;
  coupling::Scheme coupling;
  double settling_velocity;
};
// U_inf of a scene without liquid (granular) at every preset: there it sets
// only the time unit and the start, Maxwellian with U_inf per component, whose
// tail must stay below the runs' sphere speed check (0.3 per step: 4.3 U_inf
// at 0.07, where a granular gas of 61 spheres with a strong well reached 0.36
// within 10 a/U_inf; 15 U_inf at 0.02; kMaxSettlingVelocityWithoutLiquid).
constexpr double kSettlingVelocityWithoutLiquid = 0.02;

Preset preset(const std::string& fidelity) {
  using coupling::kOneSweepScheme;
  using coupling::kPaperScheme;
  if (fidelity == "draft") return {4, 16, 5, 20, 10, 20, kOneSweepScheme, 0.07};
  if (fidelity == "standard") return {6, 32, 20, 100, 50, 100, kOneSweepScheme, 0.04};
  return {6, 48, 30, 150, 100, 300, kPaperScheme, 0.02};  // paper
}

// numerics.coupling ("immersed-boundary", the default, or
// "partially-saturated") and, for the immersed boundary,
// numerics.immersed_boundary: {"marker_spacing", "sweeps", "kernel",
// "forcing", "gains"}, each defaulting to the preset's value (control forcing:
// to markers 1 dx apart and the measured default gains).
coupling::Scheme read_coupling(InputReader& numerics, const coupling::Scheme& preset_scheme) {
  const std::string method = numerics.choice("coupling", coupling::method_names(),
                                             coupling::method_name(preset_scheme.method));
  if (method == coupling::method_name(coupling::Method::partially_saturated)) {
    if (numerics.has("immersed_boundary"))
      throw InputError(
          "numerics.immersed_boundary: only with numerics.coupling = \"immersed-boundary\" "
          "(numerics.coupling = \"partially-saturated\" has no markers)");
    return coupling::kPartiallySaturatedScheme;
  }
  coupling::Scheme scheme = preset_scheme;
  scheme.method = coupling::Method::immersed_boundary;
  if (!numerics.has("immersed_boundary")) return scheme;
  InputReader ib = numerics.object("immersed_boundary");
  scheme.forcing = *coupling::forcing_from_name(ib.choice(
      "forcing", coupling::forcing_names(), coupling::forcing_name(coupling::Forcing::direct)));
  const coupling::Scheme& defaults = scheme.control() ? coupling::kControlScheme : preset_scheme;
  scheme.marker_spacing =
      ib.number("marker_spacing", {.above = 0.2, .at_most = 1.5}, defaults.marker_spacing);
  scheme.kernel = *coupling::kernel_from_name(
      ib.choice("kernel", coupling::kernel_names(), coupling::kernel_name(defaults.kernel)));
  if (scheme.control()) {
    if (scheme.marker_spacing < coupling::kSmallestControlMarkerSpacing)
      throw InputError(
          "numerics.immersed_boundary.marker_spacing = " + format_value(scheme.marker_spacing) +
          " with control forcing: " + coupling::dense_control_markers_why());
    // said as the reason, not as a range: "must be >= 1 and <= 1" hid why
    if (ib.has("sweeps")) {
      const long n = ib.integer("sweeps", {.at_least = 1, .at_most = 20});
      if (n != 1)
        throw InputError("numerics.immersed_boundary.sweeps = " + std::to_string(n) +
                         ": control forcing makes one correction a step, so sweeps must be 1 "
                         "(or left out)");
    }
    scheme.sweeps = 1;
    scheme.gains = coupling::kControlScheme.gains;
    if (ib.has("gains")) {
      InputReader g = ib.object("gains");
      scheme.gains.integral =
          g.number("integral", {.above = 0, .at_most = 100}, scheme.gains.integral);
      scheme.gains.proportional =
          g.number("proportional", {.at_least = 0, .at_most = 100}, scheme.gains.proportional);
      if (!coupling::stable_gains(scheme.gains))
        // the values as given (shortest round trip): rounded, (1, 1.0000001)
        // read "{integral 1, proportional 1}", which the region holds
        throw InputError("numerics.immersed_boundary.gains = {integral " +
                         exact_value(scheme.gains.integral) + ", proportional " +
                         exact_value(scheme.gains.proportional) +
                         "}: " + coupling::stable_gains_region());
      g.finish();
    }
  } else {
    if (ib.has("gains"))
      throw InputError("numerics.immersed_boundary.gains: only with \"forcing\": \"control\"");
    scheme.sweeps =
        static_cast<int>(ib.integer("sweeps", {.at_least = 1, .at_most = 20}, defaults.sweeps));
  }
  ib.finish();
  return scheme;
}

// "{marker_spacing 1, sweeps 1, kernel roma3}"; with the case's
// numerics.immersed_boundary as written (`given`), a field it leaves out is
// marked "(default)": the user sees which values they did not choose.
std::string scheme_fields(const coupling::Scheme& s,
                          const nlohmann::json& given = nlohmann::json()) {
  auto field = [&](const char* name, const std::string& value) {
    const bool defaulted = given.is_object() && !given.contains(name);
    return std::string(name) + " " + value + (defaulted ? " (default)" : "");
  };
  if (!s.immersed_boundary()) return "{coupling partially-saturated}";
  if (s.control())
    return "{forcing control, " + field("marker_spacing", format_value(s.marker_spacing)) + ", " +
           field("kernel", coupling::kernel_name(s.kernel)) + "}";
  return "{" + field("marker_spacing", format_value(s.marker_spacing)) + ", " +
         field("sweeps", std::to_string(s.sweeps)) + ", " +
         field("kernel", coupling::kernel_name(s.kernel)) + "}";
}

// The case field that names a scheme.
std::string coupling_field(const coupling::Scheme& s) {
  return s.immersed_boundary() ? "numerics.immersed_boundary" : "numerics.coupling";
}

// The refusal of a scheme used beyond the solids fraction it is validated for.
InputError beyond_validated_phi(const coupling::Scheme& scheme, const nlohmann::json& given,
                                double phi) {
  const std::string limit = format_value(coupling::largest_validated_phi(scheme));
  if (scheme.immersed_boundary() && !scheme.control())
    return InputError("numerics.immersed_boundary = " + scheme_fields(scheme, given) +
                      " with phi = " + format_value(phi) + ": " + std::to_string(scheme.sweeps) +
                      " forcing sweep" + (scheme.sweeps == 1 ? " is" : "s are") +
                      " validated only up to phi = " + limit +
                      " (one forcing sweep leaves the overlap of neighbouring spheres' kernels "
                      "uncorrected: 3-4 % too little drag at phi = 0.27); use sweeps = 2 "
                      "(docs/accuracy-cost.md)");
  return InputError(coupling_field(scheme) + " = " + scheme_fields(scheme, given) +
                    " with phi = " + format_value(phi) + ": " + scheme.describe() +
                    " is checked only up to phi = " + limit +
                    " (docs/coupling.md); use the paper's direct forcing (the default of "
                    "fidelity \"paper\") above it");
}

std::string box_text(const std::vector<double>& b) {
  return format_value(b[0]) + " x " + format_value(b[1]) + " x " + format_value(b[2]);
}

// Sphere centres of a snapshot written by a run (spheres/step_N.h5), checked
// against this case: the same box (the snapshot's record of it, or for older
// snapshots that lack one, `given_box`, the case's positions_from_box), same
// radius, inside the box, no overlap.
std::vector<double> snapshot_positions(const std::string& file, double a,
                                       const lattice::Extent& box,
                                       const std::vector<double>& given_box) {
  const std::string field = "positions_from = \"" + file + "\"";
  std::vector<double> x, recorded_box;
  double radius = 0;
  try {
    output::Hdf5File f(file, output::Hdf5File::Mode::read);
    x = f.read<double>("/position");
    radius = f.attribute_double("/", "radius");
    if (f.exists("/box")) recorded_box = f.read<double>("/box");
  } catch (const std::exception& e) {
    throw InputError(field +
                     ": must be a sphere snapshot (spheres/step_N.h5 of a run): " + e.what());
  }
  if (x.empty() || x.size() % 3 != 0)
    throw InputError(field + ": /position must hold N x 3 centres, holds " +
                     std::to_string(x.size()) + " numbers");
  if (std::abs(radius - a) > 1e-9)
    throw InputError(field + ": its spheres have radius " + format_value(radius) +
                     ", the case has numerics.a_over_dx = " + format_value(a));
  const std::vector<double> case_box = {static_cast<double>(box.nx), static_cast<double>(box.ny),
                                        static_cast<double>(box.nz)};
  const std::string this_box = "this case's box is " + box_text(case_box) +
                               " cells (L_over_a, L_over_W and numerics.a_over_dx)";
  if (!recorded_box.empty()) {
    if (recorded_box.size() != 3)
      throw InputError(field + ": /box must hold 3 numbers, holds " +
                       std::to_string(recorded_box.size()));
    if (!given_box.empty() && given_box != recorded_box)
      throw InputError("positions_from_box = [" + box_text(given_box) + "]: " + file +
                       " records its box as " + box_text(recorded_box) +
                       " cells; leave positions_from_box out");
    if (recorded_box != case_box)
      throw InputError(field + ": its spheres fill a " + box_text(recorded_box) + " box, " +
                       this_box + "; give the snapshot's L_over_a and L_over_W");
  } else if (given_box.empty()) {
    throw InputError(field +
                     ": records no box (written by a flocsim before snapshots did), so its "
                     "spheres cannot be checked against this case's box; give the box of the run "
                     "that wrote it, in cells, as \"positions_from_box\": [nx, ny, nz] (its "
                     "result.json's derived.box_cells); " +
                     this_box);
  } else if (given_box != case_box) {
    throw InputError("positions_from_box = [" + box_text(given_box) + "]: the snapshot's box is " +
                     "not this case's; " + this_box +
                     "; give the snapshot's L_over_a and "
                     "L_over_W");
  }
  const double L[3] = {static_cast<double>(box.nx), static_cast<double>(box.ny),
                       static_cast<double>(box.nz)};
  const std::size_t n = x.size() / 3;
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d)
      if (!(x[3 * i + d] >= 0 && x[3 * i + d] < L[d]))
        throw InputError(field + ": sphere " + std::to_string(i) + " lies outside the " +
                         std::to_string(box.nx) + " x " + std::to_string(box.ny) + " x " +
                         std::to_string(box.nz) + " box of this case (L_over_a, L_over_W)");
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      double r2 = 0;
      for (int d = 0; d < 3; ++d) {
        double dx = x[3 * i + d] - x[3 * j + d];
        dx -= L[d] * std::round(dx / L[d]);
        r2 += dx * dx;
      }
      if (r2 < 4 * a * a * (1 - 1e-9))
        throw InputError(field + ": spheres " + std::to_string(i) + " and " + std::to_string(j) +
                         " overlap (centre distance " + format_value(std::sqrt(r2)) + " < 2a)");
    }
  return x;
}

}  // namespace

double schiller_naumann_drag_coefficient(double reynolds) {
  return 24.0 / reynolds * (1.0 + 0.15 * std::pow(reynolds, 0.687));
}

namespace {

// One reading of a case: what has been read so far, the fidelity preset's
// values, how the velocity scale was given and the immersed-boundary options
// as written (messages that show a scheme mark the fields it leaves out).
struct Reading {
  SuspensionCase c;
  Preset p{};
  bool has_nu = false, has_u = false;
  nlohmann::json ib_given = nlohmann::json::object();
};

// scene (read by the caller), fidelity, precision, device, seed
void read_identity(InputReader& root, SuspensionCase& c) {
  c.fidelity = case_choice(root, "fidelity");
  c.numerics.single_precision = case_choice(root, "precision") == "float";
  // On a GPU the lattice and the immersed boundary run there (docs/gpu.md);
  // which couplings can is checked once the coupling is known (read_coupling_choice).
  parse_device_name(case_choice(root, "device"), c.device);
  if (c.device == Device::cuda && !modules_of(c.scene).liquid)
    throw InputError(root.field("device") + " = \"cuda\": scene \"" +
                     std::string(scene_name(c.scene)) +
                     "\" has no liquid, and the GPU runs the lattice; give \"cpu\" or leave the "
                     "field out");
  c.seed = static_cast<std::uint64_t>(case_integer(root, "seed"));
}

// positions_from and positions_from_box (fixed-array only: check_fields
// refuses them elsewhere).
void read_positions_source(InputReader& root, SuspensionCase& c) {
  if (root.has("positions_from")) {
    if (root.has("phi"))
      throw InputError(
          "phi and positions_from: give one; with positions_from the snapshot sets N and phi");
    c.positions_from = root.text("positions_from");
    if (c.positions_from.empty())
      throw InputError(
          "positions_from = \"\": must name a sphere snapshot file (spheres/step_N.h5 of a run)");
    if (root.has("positions_from_box")) {
      c.positions_from_box =
          root.numbers("positions_from_box", 3, case_field("positions_from_box").range);
      for (double n : c.positions_from_box)
        if (n != std::round(n))
          throw InputError("positions_from_box = [" + box_text(c.positions_from_box) +
                           "]: must be whole numbers of cells");
    }
  } else if (root.has("positions_from_box")) {
    throw InputError("positions_from_box: only with positions_from (the box of its snapshot)");
  }
}

// The top-level physics: phi, the dimensionless groups, contacts, lubrication, box shape.
void read_physics(InputReader& root, SuspensionCase& c, const Preset& p) {
  if (c.scene != Scene::single_sphere && c.positions_from.empty())
    c.physics.phi = case_number(root, "phi");
  c.physics.reynolds_inf = case_number(root, "Re_inf");
  c.physics.density_ratio = case_number(root, "density_ratio");
  c.physics.du_over_uinf = case_number(root, "du_over_Uinf");
  c.physics.delta_over_a = case_number(root, "delta_over_a");
  c.physics.restitution = case_number(root, "restitution");
  c.physics.friction = case_number(root, "friction");
  // a scene without lubrication runs no model and records none (check_fields
  // warns where one is given: a suspension's case reused for its fixed array)
  c.physics.lubrication_model = case_choice(root, "lubrication_model");
  c.physics.lubrication_integration = case_choice(root, "lubrication_integration");
  c.physics.lubrication_onset_over_a = case_number(root, "lubrication_onset_over_a");
  c.physics.lubrication_saturation_over_a =
      case_number(root, "lubrication_saturation_over_a",
                  Range{.above = 0,
                        .below = c.physics.lubrication_onset_over_a,
                        .why = "(below lubrication_onset_over_a)"});
  c.physics.length_over_a = case_number(root, "L_over_a", std::nullopt, p.length_over_a);
  c.physics.length_over_width = case_number(root, "L_over_W");
}

// numerics.a_over_dx and the velocity scale: numerics.viscosity or
// numerics.U_inf (never both), or the preset's U_inf, moved onto the stability
// floor where it would imply a viscosity below it.
void read_velocity_scale(InputReader& num, Reading& r) {
  SuspensionCase& c = r.c;
  c.numerics.radius_cells = case_number(num, "a_over_dx", std::nullopt, r.p.radius_cells);
  r.has_nu = num.has("viscosity");
  r.has_u = num.has("U_inf");
  if (r.has_nu && r.has_u)
    throw InputError(
        "numerics: give either numerics.viscosity or numerics.U_inf, not both (each fixes the "
        "other through Re_inf)");
  const double a = c.numerics.radius_cells;
  const double nu_min = smallest_stable_viscosity(a);
  if (r.has_nu) {
    c.numerics.viscosity =
        case_number(num, "viscosity",
                    Range{.at_least = nu_min, .at_most = kLargestViscosity, .why = stable_why(a)});
    c.derived.settling_velocity = c.physics.reynolds_inf * c.numerics.viscosity / (2 * a);
    return;
  }
  const Range u_range{
      .above = 0, .at_most = largest_settling_velocity(c), .why = largest_settling_velocity_why(c)};
  c.derived.settling_velocity =
      case_number(num, "U_inf", u_range,
                  has_liquid(c) ? r.p.settling_velocity : kSettlingVelocityWithoutLiquid);
  c.numerics.viscosity = c.derived.settling_velocity * 2 * a / c.physics.reynolds_inf;
  // by default stay inside the stable viscosity range: lower U_inf onto the
  // viscosity ceiling (a low Re_inf with the preset's U_inf), or raise it onto
  // the stability floor; a U_inf given is never moved, but refused
  if (!r.has_u && has_liquid(c) && c.numerics.viscosity > kLargestViscosity * (1 + 1e-12)) {
    c.numerics.viscosity = kLargestViscosity;
    c.derived.settling_velocity = c.physics.reynolds_inf * c.numerics.viscosity / (2 * a);
  }
  check_viscosity_ceiling(r.c);
  if (!r.has_u && c.numerics.viscosity < nu_min) {
    c.numerics.viscosity = nu_min;
    c.derived.settling_velocity = c.physics.reynolds_inf * c.numerics.viscosity / (2 * a);
  }
}

// The coupling: the preset's option where it is validated for this phi (a
// snapshot's phi is only known later: the paper's method then) and calibrated
// for this a within a factor 2 of this viscosity, else the paper's method. So
// does a scene with the calibrated close-pair model where the option's
// close-pair resistance has not been measured at this a within a factor 2 of
// nu but the paper method's is nearer (where neither is, the faster one runs,
// with the same warning). Then the case's own numerics options on top.
coupling::Scheme choose_scheme(InputReader& num, const Reading& r) {
  const SuspensionCase& c = r.c;
  const double a = c.numerics.radius_cells;
  const auto& radii = calibration::CalibrationTable::shipped();
  auto calibrated_near = [&](const coupling::Scheme& scheme) {
    return radii.has(a, scheme) &&
           std::abs(std::log(radii.lookup(a, c.numerics.viscosity, scheme).viscosity /
                             c.numerics.viscosity)) <= std::log(kNearViscosityFactor);
  };
  auto pair_gap = [&](const coupling::Scheme& scheme) {
    return calibration::PairResistanceTable::shipped().viscosity_gap(a, c.numerics.viscosity,
                                                                     scheme);
  };
  coupling::Scheme preset_scheme = r.p.coupling;
  if (!c.positions_from.empty() || c.physics.phi > coupling::largest_validated_phi(preset_scheme) ||
      !calibrated_near(preset_scheme) ||
      (modules_of(c.scene).lubrication && c.physics.lubrication_model == "calibrated" &&
       pair_gap(preset_scheme) > kNearViscosityFactor &&
       pair_gap(coupling::kPaperScheme) < pair_gap(preset_scheme)))
    preset_scheme = coupling::kPaperScheme;
  return read_coupling(num, preset_scheme);
}

// trt_magic, inside_liquid and the coupling scheme. A scene without liquid
// couples nothing: its options are read (and checked) but no scheme runs and
// none is recorded (check_fields warns).
void read_scheme(InputReader& num, Reading& r) {
  SuspensionCase& c = r.c;
  c.numerics.trt_magic = case_number(num, "trt_magic");
  c.numerics.inside_liquid = case_choice(num, "inside_liquid");
  if (!has_liquid(c)) {
    // no coupling runs: its options (checked and warned about by
    // check_fields) are not read, and no rule between them applies
    case_choice(num, "coupling");
    num.object("immersed_boundary");
    c.numerics.coupling = r.p.coupling;
    return;
  }
  c.numerics.coupling = choose_scheme(num, r);
  // By default also stay clear of the multi-sweep coupling's oscillation
  // (check_multi_sweep_floor): raise U_inf until nu reaches its floor, where
  // the Mach limit allows, and choose again at that viscosity.
  if (!r.has_nu && !r.has_u && multi_sweep_oscillates(c)) {
    const double u = settling_velocity_at_multi_sweep_floor(c);
    if (u <= kMaxSettlingVelocity) {
      c.numerics.viscosity = kSmallestMultiSweepViscosity;
      c.derived.settling_velocity = u;
      c.numerics.coupling = choose_scheme(num, r);
    }
  }
}

// numerics.input_radius: where each scheme puts its boundary relative to its
// input radius (the shipped-table test checks the calibrated offsets against
// the same).
void read_input_radius(InputReader& num, SuspensionCase& c) {
  c.numerics.input_radius_given = num.has("input_radius");
  if (!c.numerics.input_radius_given) return;
  if (!has_liquid(c)) {  // no markers: the field's own range only (check_fields warns)
    c.numerics.input_radius = case_number(num, "input_radius");
    return;
  }
  const double a = c.numerics.radius_cells;
  const coupling::Scheme& s = c.numerics.coupling;
  const Range range =
      !s.immersed_boundary()
          ? Range{.at_least = a - 0.5,
                  .at_most = a + 0.5,
                  .why =
                      "(partially saturated cells' boundary lies within half a cell of the "
                      "covered sphere's)"}
      : s.control()
          ? Range{.at_least = a - 1.5,
                  .at_most = a,
                  .why =
                      "(control forcing's wall lies up to the kernel's half-width, 1.5 dx, "
                      "outside its markers)"}
          : Range{.at_least = a - 1,
                  .at_most = a,
                  .why =
                      "(markers sit inside the hydrodynamic radius a_over_dx, by less than "
                      "1 dx)"};
  c.numerics.input_radius = case_number(num, "input_radius", range);
}

// A scheme asked for beyond the phi it is validated for is refused for that
// before its calibration is looked for: one sweep at phi 0.3 is not to be
// calibrated but replaced.
void refuse_beyond_validated_phi(const Reading& r) {
  const SuspensionCase& c = r.c;
  if (c.positions_from.empty() &&
      c.physics.phi > coupling::largest_validated_phi(c.numerics.coupling))
    throw beyond_validated_phi(c.numerics.coupling, r.ib_given, c.physics.phi);
}

// A hand-given a_g replaces the calibration, not the validation: the scheme
// must still be one the project offers (calibrated at some a).
void check_offered_scheme(const Reading& r) {
  const SuspensionCase& c = r.c;
  const auto& table = calibration::CalibrationTable::shipped();
  bool offered = false;
  std::string names;
  for (const auto& e : table.entries()) {
    offered = offered || e.scheme.same_calibration(c.numerics.coupling);
    const std::string n = scheme_fields(e.scheme);
    if (names.find(n) == std::string::npos) names += (names.empty() ? "" : ", ") + n;
  }
  if (offered) return;
  refuse_beyond_validated_phi(r);
  throw InputError(coupling_field(c.numerics.coupling) + " = " +
                   scheme_fields(c.numerics.coupling, r.ib_given) +
                   ": not an offered option (no calibration of it is shipped at any a); "
                   "offered: " +
                   names + " (docs/accuracy-cost.md)");
}

// a_g for this a from the shipped calibration, interpolated in log(nu)
// between the calibrated viscosities around this one.
void apply_radius_calibration(Reading& r) {
  SuspensionCase& c = r.c;
  if (!has_liquid(c)) return;
  if (c.numerics.input_radius_given) return check_offered_scheme(r);
  const double a = c.numerics.radius_cells;
  const auto& table = calibration::CalibrationTable::shipped();
  if (table.has(a, coupling::kPaperScheme) && !table.has(a, c.numerics.coupling)) {
    refuse_beyond_validated_phi(r);
    throw InputError(
        coupling_field(c.numerics.coupling) + " = " +
        scheme_fields(c.numerics.coupling, r.ib_given) +
        ": not calibrated at numerics.a_over_dx = " + format_value(a) + " (" +
        c.numerics.coupling.describe() + "); calibrate it with `flocsim calibrate --radius " +
        format_value(a) + " --viscosity NU" + calibration::calibrate_options(c.numerics.coupling) +
        " --table engine/calibration/hydrodynamic_radius.json` and rebuild, or choose a "
        "calibrated scheme (docs/immersed-boundary.md, \"Options\")");
  }
  try {
    c.numerics.input_radius = table.input_radius(a, c.numerics.viscosity, c.numerics.coupling);
    c.numerics.calibration_viscosity =
        table.lookup(a, c.numerics.viscosity, c.numerics.coupling).viscosity;
  } catch (const std::out_of_range& e) {
    throw InputError("numerics.a_over_dx = " + format_value(a) + ": " + e.what() +
                     " Or give numerics.input_radius (the marker radius a_g) yourself.");
  }
  if (std::abs(std::log(c.numerics.calibration_viscosity / c.numerics.viscosity)) > std::log(2.0))
    c.warnings.push_back("the hydrodynamic-radius calibration nearest to viscosity = " +
                         format_value(c.numerics.viscosity) + " was made at " +
                         format_value(c.numerics.calibration_viscosity) +
                         "; `flocsim calibrate --viscosity` makes one for this viscosity");
}

// lubrication_model calibrated: the lattice's share from the shipped close-pair table.
void apply_lubrication_calibration(SuspensionCase& c) {
  if (!modules_of(c.scene).lubrication || c.physics.lubrication_model != "calibrated") return;
  const double a = c.numerics.radius_cells;
  const auto& pairs = calibration::PairResistanceTable::shipped();
  try {
    c.numerics.lubrication_lattice_share =
        pairs.lattice_share(a, c.numerics.viscosity, c.numerics.coupling);
  } catch (const std::out_of_range& e) {
    throw InputError("lubrication_model = \"calibrated\" with numerics.a_over_dx = " +
                     format_value(a) + ": " + e.what());
  }
  const double gap = pairs.viscosity_gap(a, c.numerics.viscosity, c.numerics.coupling);
  if (gap > kNearViscosityFactor)
    c.warnings.push_back(
        "the close-pair calibration nearest to viscosity = " + format_value(c.numerics.viscosity) +
        " at a_over_dx = " + format_value(a) + " lies a factor " + format_value(gap) + " away; `" +
        calibration::close_pair_calibrate_command(a, c.numerics.viscosity, c.numerics.coupling) +
        "` and a rebuild make one");
  if (c.numerics.input_radius_given)
    c.warnings.push_back(
        "the close-pair calibration was made with the shipped marker radius for a_over_dx = " +
        format_value(a) + "; with numerics.input_radius given it holds only approximately");
}

void read_protocol(InputReader& root, SuspensionCase& c, const Preset& p) {
  InputReader pr = root.object("protocol");
  Protocol& t = c.protocol;
  t.stage1_min = case_number(pr, "stage1_min", std::nullopt, p.stage1_min);
  t.stage1_max = case_number(
      pr, "stage1_max",
      Range{.at_least = t.stage1_min, .at_most = 1e5, .why = "(at least protocol.stage1_min)"},
      p.stage1_max);
  t.stage2_settle = case_number(pr, "stage2_settle", std::nullopt, p.stage2_settle);
  t.statistics = case_number(pr, "statistics", std::nullopt, p.statistics);
  t.sample_every = case_number(pr, "sample_every");
  t.stationarity_window = case_number(pr, "stationarity_window");
  t.snapshot_every = case_number(pr, "snapshot_every");
  t.checkpoint_every_s = case_number(pr, "checkpoint_every_s");
  t.progress_every_s = case_number(pr, "progress_every_s");
  t.threads = static_cast<int>(case_integer(pr, "threads"));
  pr.finish();
  if (t.statistics < 20 * t.sample_every)
    throw InputError(
        "protocol.statistics = " + exact_value(t.statistics) +
        ": must be >= 20 x protocol.sample_every = " + format_value(20 * t.sample_every) +
        " (10 batch means of at least 2 samples each)");
}

// The box in cells and the sphere count (from phi, or from the snapshot),
// with the phi limit of the coupling scheme at the realised N.
void derive_box_and_spheres(Reading& r) {
  SuspensionCase& c = r.c;
  const double a = c.numerics.radius_cells;
  const int L = static_cast<int>(std::lround(c.physics.length_over_a * a));
  const int W = static_cast<int>(std::lround(L / c.physics.length_over_width));
  c.derived.box = {L, W, W};
  // Pair observables look up to 3a around each sphere (h(theta), and the
  // well and event ranges, 2(a + delta) plus a skin, are shorter): that must
  // stay below half the box so that a pair has one periodic image only.
  if (W <= 6 * a)
    throw InputError("L_over_W = " + exact_value(c.physics.length_over_width) +
                     " with L_over_a = " + exact_value(c.physics.length_over_a) +
                     ": makes the box width W = " + std::to_string(W) +
                     " cells; must exceed 6a = " + format_value(6 * a) +
                     " so that pairs within 3a have a single periodic image");
  const double volume = static_cast<double>(L) * W * W;
  const double sphere_volume = 4.0 / 3.0 * M_PI * a * a * a;
  const bool single = c.scene == Scene::single_sphere;
  c.derived.sphere_count =
      single ? 1 : static_cast<int>(std::lround(c.physics.phi * volume / sphere_volume));
  if (!c.positions_from.empty()) {
    c.initial_positions =
        snapshot_positions(c.positions_from, a, c.derived.box, c.positions_from_box);
    c.derived.sphere_count = static_cast<int>(c.initial_positions.size() / 3);
    c.physics.phi = c.derived.sphere_count * sphere_volume / volume;
  }
  if (c.derived.sphere_count < 1)
    throw InputError("phi = " + exact_value(c.physics.phi) +
                     ": gives N = 0 spheres in this box; raise phi or L_over_a");
  c.derived.phi_realised = c.derived.sphere_count * sphere_volume / volume;
  // The smallest phi that rounds to this N (a small box at phi = 0.2 holds
  // 0.2015: rounding, not a denser suspension), for a snapshot's N too.
  const double phi_asked = (c.derived.sphere_count - 0.5) * sphere_volume / volume;
  if (has_liquid(c) && phi_asked > coupling::largest_validated_phi(c.numerics.coupling))
    throw beyond_validated_phi(c.numerics.coupling, r.ib_given,
                               c.positions_from.empty() ? c.physics.phi : c.derived.phi_realised);
  if (single) c.physics.phi = c.derived.phi_realised;
}

// The lattice-unit forces (docs/model.md section 2).
void derive_forces(SuspensionCase& c) {
  const double a = c.numerics.radius_cells;
  const double sphere_volume = 4.0 / 3.0 * M_PI * a * a * a;
  c.derived.drag_coefficient = schiller_naumann_drag_coefficient(c.physics.reynolds_inf);
  const double U = c.derived.settling_velocity;
  c.derived.gravity =
      0.375 * c.derived.drag_coefficient * U * U / ((c.physics.density_ratio - 1.0) * a);
  c.derived.convective_time = a / U;
  c.derived.escape_velocity = c.physics.du_over_uinf * U;
  c.derived.well_width = c.physics.delta_over_a * a;
  // rho_bar - rho = phi (rho_p - rho); rho_p - rho_bar = (1 - phi)(rho_p - rho)
  c.derived.liquid_body_force =
      c.derived.phi_realised * (c.physics.density_ratio - 1.0) * c.derived.gravity;
  c.derived.sphere_net_gravity = (1.0 - c.derived.phi_realised) * (c.physics.density_ratio - 1.0) *
                                 sphere_volume * c.derived.gravity;
}

// The lattice must fit in 80 % of this machine's memory.
void check_memory(const SuspensionCase& c) {
  const double bytes = static_cast<double>(c.derived.box.cells()) * 19.0 *
                       (c.numerics.single_precision ? 4.0 : 8.0) * 1.25;
  const double available = physical_memory_bytes();
  if (has_liquid(c) && available > 0 && bytes > 0.8 * available)
    throw InputError("L_over_a = " + exact_value(c.physics.length_over_a) +
                     ", a_over_dx = " + exact_value(c.numerics.radius_cells) + ": the " +
                     std::to_string(c.derived.box.nx) + " x " + std::to_string(c.derived.box.ny) +
                     " x " + std::to_string(c.derived.box.nz) + " lattice needs " +
                     format_value(bytes / 1e9) + " GB; must fit in 80 % of this machine's " +
                     format_value(available / 1e9) + " GB");
}

}  // namespace

SuspensionCase parse_suspension_case(const nlohmann::json& document) {
  Reading r;
  SuspensionCase& c = r.c;
  InputReader root(document, "");
  c.scene = scene_from_name(root.choice("scene", scene_names(/*with_spheres=*/true)));
  // every field against its declaration: unknown, unused in this scene, type, range
  c.warnings = input::check_fields(case_field_table(), document, scene_context(c.scene));
  read_identity(root, c);
  r.p = preset(c.fidelity);
  read_positions_source(root, c);
  read_physics(root, c, r.p);
  InputReader num = root.object("numerics");
  read_velocity_scale(num, r);
  read_scheme(num, r);
  if (document.contains("numerics") && document["numerics"].contains("immersed_boundary"))
    r.ib_given = document["numerics"]["immersed_boundary"];
  read_input_radius(num, c);
  num.finish();
  check_mach_cap(c);
  check_stability_floor(c);
  apply_radius_calibration(r);
  check_multi_sweep_floor(r.c, r.has_nu, r.has_u);
  apply_lubrication_calibration(c);
  read_protocol(root, c, r.p);
  root.finish();
  derive_box_and_spheres(r);
  derive_forces(c);
  check_memory(c);
  return c;
}

nlohmann::json SuspensionCase::to_json() const {
  nlohmann::json j;
  j["scene"] = std::string(scene_name(scene));
  j["fidelity"] = fidelity;
  j["precision"] = numerics.single_precision ? "float" : "double";
  if (device != Device::cpu) j["device"] = device_name(device);
  j["seed"] = seed;
  if (!positions_from.empty())
    j["positions_from"] = positions_from;
  else if (scene != Scene::single_sphere)
    j["phi"] = physics.phi;
  j["Re_inf"] = physics.reynolds_inf;
  j["density_ratio"] = physics.density_ratio;
  j["du_over_Uinf"] = physics.du_over_uinf;
  j["delta_over_a"] = physics.delta_over_a;
  j["restitution"] = physics.restitution;
  j["friction"] = physics.friction;
  if (modules_of(scene).lubrication) {  // no model runs elsewhere, so none is recorded
    j["lubrication_model"] = physics.lubrication_model;
    j["lubrication_integration"] = physics.lubrication_integration;
  }
  j["lubrication_onset_over_a"] = physics.lubrication_onset_over_a;
  j["lubrication_saturation_over_a"] = physics.lubrication_saturation_over_a;
  j["L_over_a"] = physics.length_over_a;
  j["L_over_W"] = physics.length_over_width;
  j["numerics"] = {{"a_over_dx", numerics.radius_cells},
                   {"viscosity", numerics.viscosity},
                   {"trt_magic", numerics.trt_magic}};
  if (modules_of(scene).liquid) {
    // written only when not the default, so that every case that predates the
    // choice keeps its identity
    if (numerics.coupling.immersed_boundary())
      j["numerics"]["immersed_boundary"] = immersed_boundary_json(numerics.coupling);
    else
      j["numerics"]["coupling"] = coupling::method_name(numerics.coupling.method);
  }
  if (numerics.input_radius_given) j["numerics"]["input_radius"] = numerics.input_radius;
  // written only when not the default, so that every case that predates the
  // option keeps its identity
  if (numerics.inside_liquid != "measured") j["numerics"]["inside_liquid"] = numerics.inside_liquid;
  j["protocol"] = {{"stage1_min", protocol.stage1_min},
                   {"stage1_max", protocol.stage1_max},
                   {"stage2_settle", protocol.stage2_settle},
                   {"statistics", protocol.statistics},
                   {"sample_every", protocol.sample_every},
                   {"stationarity_window", protocol.stationarity_window},
                   {"snapshot_every", protocol.snapshot_every},
                   {"checkpoint_every_s", protocol.checkpoint_every_s},
                   {"progress_every_s", protocol.progress_every_s},
                   {"threads", protocol.threads}};
  return j;
}

nlohmann::json SuspensionCase::derived_json() const {
  const std::string input_radius_from =
      numerics.input_radius_given ? std::string("numerics.input_radius")
      : !modules_of(scene).liquid
          ? std::string("unused (no liquid)")
          : "shipped calibration, interpolated in log nu (nearest entry nu = " +
                format_value(numerics.calibration_viscosity) + ")";
  return {{"box_cells", {derived.box.nx, derived.box.ny, derived.box.nz}},
          {"sphere_count", derived.sphere_count},
          {"phi_realised", derived.phi_realised},
          {"U_inf", derived.settling_velocity},
          {"viscosity", numerics.viscosity},
          {"tau", 3 * numerics.viscosity + 0.5},
          {"C_D", derived.drag_coefficient},
          {"gravity", derived.gravity},
          {"convective_time_steps", derived.convective_time},
          {"escape_velocity", derived.escape_velocity},
          {"well_width", derived.well_width},
          {"liquid_body_force", derived.liquid_body_force},
          {"sphere_net_gravity", derived.sphere_net_gravity},
          {"Mach_U_inf", derived.settling_velocity * std::sqrt(3.0)},
          {"input_radius", numerics.input_radius},
          {"input_radius_from", input_radius_from}};
}

nlohmann::json immersed_boundary_json(const coupling::Scheme& scheme) {
  if (scheme.control())
    return {{"forcing", coupling::forcing_name(scheme.forcing)},
            {"marker_spacing", scheme.marker_spacing},
            {"kernel", coupling::kernel_name(scheme.kernel)},
            {"gains",
             {{"integral", scheme.gains.integral}, {"proportional", scheme.gains.proportional}}}};
  return {{"marker_spacing", scheme.marker_spacing},
          {"sweeps", scheme.sweeps},
          {"kernel", coupling::kernel_name(scheme.kernel)}};
}

nlohmann::json with_older_versions_models(nlohmann::json c) {
  if (!c.is_object()) return c;
  const std::string scene =
      c.contains("scene") && c["scene"].is_string() ? c["scene"].get<std::string>() : "";
  bool immersed = false, lubricated = false;
  for (const auto& entry : kScenes)
    if (scene == entry.name) {
      immersed = entry.modules.liquid && entry.modules.spheres;
      lubricated = entry.modules.lubrication;
    }
  if (immersed && c.contains("numerics") && c["numerics"].is_object() &&
      !c["numerics"].contains("immersed_boundary"))
    c["numerics"]["immersed_boundary"] = immersed_boundary_json(coupling::kPaperScheme);
  if (!lubricated) {
    c.erase("lubrication_model");
    c.erase("lubrication_integration");
  } else {
    if (!c.contains("lubrication_model")) c["lubrication_model"] = "nguyen-ladd";
    if (!c.contains("lubrication_integration")) c["lubrication_integration"] = "implicit";
  }
  return c;
}

}  // namespace flocsim::cases
