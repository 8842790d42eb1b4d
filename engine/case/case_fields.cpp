// The case-file field table (case_fields.hpp says what reads it): one row per
// field, each group of fields one function, in the order the readers read
// them (sphere scenes: identity, physics, lubrication and box, numerics,
// coupling, input radius, protocol; the fluid scene: its lattice, initial flow
// and run), assembled by make_table(); then the lookups, the typed readers and
// the generated Markdown tables and JSON Schema.
#include "engine/case/case_fields.hpp"

#include <stdexcept>

#include "engine/case/fluid_case.hpp"
#include "engine/case/suspension_case.hpp"

// GCC 12 warns that the Range of a row that names no range "may be used
// uninitialized" (a known false positive of designated initializers of
// aggregates holding strings); every member has a default initializer.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

namespace flocsim::cases {

using input::FieldSpec;
using input::FieldTable;
using input::FieldType;
using input::Range;

namespace {

constexpr unsigned bit(Scene s) {
  return 1u << static_cast<unsigned>(s);
}
constexpr unsigned kSuspension = bit(Scene::suspension);
constexpr unsigned kFixedArray = bit(Scene::fixed_array);
constexpr unsigned kSingle = bit(Scene::single_sphere);
constexpr unsigned kGranular = bit(Scene::granular);
constexpr unsigned kFluid = bit(Scene::fluid);
constexpr unsigned kSpheres = kSuspension | kFixedArray | kSingle | kGranular;
constexpr unsigned kLiquidSpheres = kSuspension | kFixedArray | kSingle;
constexpr unsigned kContacts = kSuspension | kGranular;
constexpr unsigned kManySpheres = kSuspension | kFixedArray | kGranular;
constexpr unsigned kEvery = kSpheres | kFluid;

const std::string kPreset = "the preset's (draft, standard, paper: ";
const std::string kNoLiquid = "has no liquid, so no coupling runs; not recorded";
const std::string kNoContacts =
    "has no contacts (collisions, square well), so it does nothing there; still recorded (it "
    "changes the run's id): leave it out";

// The sphere scenes' fields (docs/user-guide.md, "Case file: scenes with spheres").
void add_sphere_fields(std::vector<FieldSpec>& t) {
  t.push_back({.path = "fidelity",
               .type = FieldType::choice,
               .choices = {"draft", "standard", "paper"},
               .fallback = "standard",
               .contexts = kSpheres,
               .doc = "preset of resolution, box and durations (table \"fidelity\" below)"});
  t.push_back({.path = "seed",
               .type = FieldType::integer,
               .range = {.at_least = 0, .at_most = 4294967295.0},
               .fallback = 1,
               .contexts = kSpheres,
               .doc = "random placement and start"});
  t.push_back({.path = "positions_from",
               .type = FieldType::string,
               .contexts = kFixedArray,
               .unused = "places its spheres itself",
               .doc = "hold the spheres of this snapshot (spheres/step_N.h5 of a run) still, "
                      "instead of phi",
               .rules = "not with phi; the snapshot's radius and box must be this case's"});
  t.push_back({.path = "positions_from_box",
               .type = FieldType::numbers,
               .range = {.at_least = 1, .at_most = 1e5},
               .length = 3,
               .unit = "cells",
               .contexts = kFixedArray,
               .unused = "places its spheres itself",
               .doc = "the box of a snapshot that does not record it",
               .rules = "whole numbers; only with positions_from"});
}

// phi and the dimensionless groups, the contacts.
void add_physics_fields(std::vector<FieldSpec>& t) {
  t.push_back({.path = "phi",
               .type = FieldType::number,
               .range = {.above = 0, .at_most = 0.35, .why = "(random placement jams near 0.38)"},
               .default_rule = "required (fixed-array: or positions_from)",
               .contexts = kManySpheres,
               .unused = "places no spheres by a solids fraction",
               .doc = "solids fraction",
               .rules = "each coupling scheme's validated phi (one sweep, control forcing, "
                        "partially saturated cells: 0.2)"});
  t.push_back({.path = "Re_inf",
               .type = FieldType::number,
               .range = {.above = 0, .at_most = 200},
               .fallback = 12.0,
               .contexts = kSpheres,
               .doc = "settling Reynolds number 2 a U_inf / nu",
               .rules = "U_inf = Re_inf nu / (2a); the Mach cap; the stability floor; the "
                        "viscosity ceiling"});
  t.push_back({.path = "density_ratio",
               .type = FieldType::number,
               .range = {.above = 1, .at_most = 100, .why = "(spheres must settle)"},
               .fallback = 4.0,
               .contexts = kSpheres,
               .doc = "rho_p / rho"});
  t.push_back({.path = "du_over_Uinf",
               .type = FieldType::number,
               .range = {.at_least = 0, .at_most = 0.5},
               .fallback = 0.0,
               .contexts = kContacts,
               .warn_when_unused = true,
               .unused = kNoContacts,
               .doc = "square-well strength du / U_inf (0: no attraction, no stage 2)"});
  t.push_back({.path = "delta_over_a",
               .type = FieldType::number,
               .range = {.above = 0, .at_most = 0.5},
               .fallback = 0.025,
               .contexts = kContacts,
               .warn_when_unused = true,
               .unused = kNoContacts,
               .doc = "square-well width / a"});
  t.push_back({.path = "restitution",
               .type = FieldType::number,
               .range = {.at_least = 0, .at_most = 1},
               .fallback = 1.0,
               .contexts = kContacts,
               .warn_when_unused = true,
               .unused = kNoContacts,
               .doc = "coefficient of restitution e of collisions"});
  t.push_back({.path = "friction",
               .type = FieldType::number,
               .range = {.at_least = 0, .at_most = 10},
               .fallback = 0.0,
               .contexts = kContacts,
               .warn_when_unused = true,
               .unused = kNoContacts,
               .doc = "friction coefficient mu_f of collisions"});
}

// Lubrication (the suspension's) and the box's shape.
void add_lubrication_and_box_fields(std::vector<FieldSpec>& t) {
  t.push_back({.path = "lubrication_model",
               .type = FieldType::choice,
               .choices = {"calibrated", "nguyen-ladd"},
               .fallback = "calibrated",
               .contexts = kSuspension,
               .warn_when_unused = true,
               .unused = "has no lubrication, so no model runs; not recorded",
               .doc = "close-pair force: Brenner minus the lattice's calibrated share, or "
                      "Nguyen-Ladd's",
               .rules = "calibrated: a close-pair calibration at this a_over_dx"});
  t.push_back({.path = "lubrication_integration",
               .type = FieldType::choice,
               .choices = {"implicit", "explicit-paper"},
               .fallback = "implicit",
               .contexts = kSuspension,
               .warn_when_unused = true,
               .unused = "has no lubrication, so no model runs; not recorded",
               .doc = "backward Euler per pair, or the paper's forward Euler (comparisons)"});
  t.push_back({.path = "lubrication_onset_over_a",
               .type = FieldType::number,
               .range = {.above = 0, .at_most = 1},
               .fallback = 0.2,
               .contexts = kSuspension,
               .warn_when_unused = true,
               .unused = "has no lubrication, so it does nothing there; still recorded (it "
                         "changes the run's id): leave it out",
               .doc = "gap s0 / a below which lubrication acts"});
  t.push_back({.path = "lubrication_saturation_over_a",
               .type = FieldType::number,
               .range = {.above = 0, .below = 1},
               .fallback = 2e-4,
               .contexts = kSuspension,
               .warn_when_unused = true,
               .unused = "has no lubrication, so it does nothing there; still recorded (it "
                         "changes the run's id): leave it out",
               .doc = "gap s1 / a below which the lubrication force stops growing",
               .rules = "below lubrication_onset_over_a"});
  t.push_back({.path = "L_over_a",
               .type = FieldType::number,
               .range = {.at_least = 8, .at_most = 256},
               .default_rule = kPreset + "16, 32, 48)",
               .contexts = kSpheres,
               .doc = "box length L / a (along gravity)",
               .rules = "the lattice must fit in 80 % of memory"});
  t.push_back({.path = "L_over_W",
               .type = FieldType::number,
               .range = {.at_least = 0.25, .at_most = 8},
               .fallback = 2.0,
               .contexts = kSpheres,
               .doc = "box length over width",
               .rules = "box width W > 6a"});
}

void add_numerics_fields(std::vector<FieldSpec>& t) {
  t.push_back({.path = "numerics",
               .type = FieldType::object,
               .contexts = kSpheres,
               .doc = "resolution, lattice and coupling"});
  t.push_back({.path = "numerics.a_over_dx",
               .type = FieldType::number,
               .range = {.at_least = 3, .at_most = 24},
               .default_rule = kPreset + "4, 6, 6)",
               .unit = "cells",
               .contexts = kSpheres,
               .doc = "hydrodynamic radius a / dx",
               .rules = "a shipped calibration at this a (or numerics.input_radius)"});
  t.push_back({.path = "numerics.viscosity",
               .type = FieldType::number,
               .range = {.above = 0,
                         .at_most = kLargestViscosity,
                         .why = "(the viscosity ceiling, measured; docs/numerics.md)"},
               .default_rule = "2 a U_inf / Re_inf",
               .unit = "lattice units",
               .contexts = kSpheres,
               .doc = "lattice kinematic viscosity nu (tau = 3 nu + 1/2); not with U_inf",
               .rules = "the stability floor (0.01 below a_over_dx 6, 0.005 from 6); the "
                        "multi-sweep floor; the viscosity ceiling"});
  t.push_back({.path = "numerics.U_inf",
               .type = FieldType::number,
               .range = {.above = 0,
                         .at_most = kMaxSettlingVelocity,
                         .why = "(Mach limit for settling flows)"},
               .default_rule = kPreset +
                               "0.07, 0.04, 0.02; granular 0.02), moved to the stability floor, "
                               "the multi-sweep floor or the viscosity ceiling where nu would "
                               "leave them",
               .unit = "lattice units",
               .contexts = kSpheres,
               .doc = "single-sphere settling velocity; not with viscosity",
               .rules = "the Mach cap (granular: 0.05); the stability floor; the multi-sweep "
                        "floor; the viscosity ceiling"});
  t.push_back({.path = "numerics.trt_magic",
               .type = FieldType::number,
               .range = {.above = 0, .at_most = 10},
               .fallback = 0.25,
               .contexts = kLiquidSpheres,
               .warn_when_unused = true,
               .unused = "has no liquid, so it does nothing there; still recorded (it changes "
                         "the run's id): leave it out",
               .doc = "TRT magic parameter Lambda"});
  t.push_back({.path = "numerics.inside_liquid",
               .type = FieldType::choice,
               .choices = {"measured", "rigid-body"},
               .fallback = "measured",
               .contexts = kSuspension | kSingle,
               .unused = "has no spheres moving in a liquid",
               .doc = "the liquid inside a sphere: its measured momentum change, or rigid-body "
                      "(comparisons)"});
}

// numerics.coupling and numerics.immersed_boundary (docs/immersed-boundary.md, docs/coupling.md).
void add_coupling_fields(std::vector<FieldSpec>& t) {
  t.push_back({.path = "numerics.coupling",
               .type = FieldType::choice,
               .choices = coupling::method_names(),
               .fallback = "immersed-boundary",
               .contexts = kLiquidSpheres,
               .warn_when_unused = true,
               .unused = kNoLiquid,
               .doc = "how spheres and liquid are coupled",
               .rules = "partially-saturated: not with numerics.immersed_boundary"});
  t.push_back({.path = "numerics.immersed_boundary",
               .type = FieldType::object,
               .contexts = kLiquidSpheres,
               .warn_when_unused = true,
               .unused = kNoLiquid,
               .doc = "markers, sweeps, kernel, forcing (docs/immersed-boundary.md)",
               .rules = "a scheme the shipped calibration holds at this a"});
  t.push_back({.path = "numerics.immersed_boundary.marker_spacing",
               .type = FieldType::number,
               .range = {.above = 0.2, .at_most = 1.5},
               .default_rule = kPreset + "1, 1, 0.7; at phi > 0.2 0.7; control forcing 1)",
               .unit = "dx",
               .contexts = kLiquidSpheres,
               .doc = "mean distance between the markers on a sphere",
               .rules = "control forcing: >= 1"});
  t.push_back({.path = "numerics.immersed_boundary.sweeps",
               .type = FieldType::integer,
               .range = {.at_least = 1, .at_most = 20},
               .default_rule = kPreset + "1, 1, 2; at phi > 0.2 2)",
               .contexts = kLiquidSpheres,
               .doc = "direct-forcing sweeps per time step",
               .rules = "control forcing: 1"});
  t.push_back({.path = "numerics.immersed_boundary.kernel",
               .type = FieldType::choice,
               .choices = coupling::kernel_names(),
               .fallback = "roma3",
               .contexts = kLiquidSpheres,
               .doc = "interpolation kernel"});
  t.push_back({.path = "numerics.immersed_boundary.forcing",
               .type = FieldType::choice,
               .choices = coupling::forcing_names(),
               .fallback = "direct",
               .contexts = kLiquidSpheres,
               .doc = "direct forcing, or the paper's control forcing (docs/coupling.md)"});
  t.push_back({.path = "numerics.immersed_boundary.gains",
               .type = FieldType::object,
               .contexts = kLiquidSpheres,
               .doc = "control forcing's gains",
               .rules = "only with forcing control; integral >= 1, integral + 2 proportional "
                        "<= 3"});
  t.push_back({.path = "numerics.immersed_boundary.gains.integral",
               .type = FieldType::number,
               .range = {.above = 0, .at_most = 100},
               .fallback = coupling::kControlScheme.gains.integral,
               .contexts = kLiquidSpheres,
               .doc = "integral gain G"});
  t.push_back({.path = "numerics.immersed_boundary.gains.proportional",
               .type = FieldType::number,
               .range = {.at_least = 0, .at_most = 100},
               .fallback = coupling::kControlScheme.gains.proportional,
               .contexts = kLiquidSpheres,
               .doc = "proportional gain P"});
}

void add_input_radius_field(std::vector<FieldSpec>& t) {
  t.push_back({.path = "numerics.input_radius",
               .type = FieldType::number,
               .range = {.above = 0, .at_most = 24.5},
               .default_rule = "the shipped calibration, interpolated in log nu",
               .unit = "cells",
               .contexts = kLiquidSpheres,
               .warn_when_unused = true,
               .unused = "has no liquid, so it does nothing there; still recorded (it changes "
                         "the run's id): leave it out",
               .doc = "marker radius a_g by hand",
               .rules = "per scheme: [a - 1, a] direct forcing, [a - 1.5, a] control, "
                        "[a - 0.5, a + 0.5] partially saturated"});
}

void add_protocol_fields(std::vector<FieldSpec>& t) {
  const Range duration{.at_least = 0, .at_most = 1e5};
  t.push_back({.path = "protocol",
               .type = FieldType::object,
               .contexts = kSpheres,
               .doc = "stages, statistics and output cadence"});
  t.push_back({.path = "protocol.stage1_min",
               .type = FieldType::number,
               .range = duration,
               .default_rule = kPreset + "5, 20, 30)",
               .unit = "a/U_inf",
               .contexts = kSpheres,
               .doc = "stage 1 (du = 0) at least this long"});
  t.push_back({.path = "protocol.stage1_max",
               .type = FieldType::number,
               .range = duration,
               .default_rule = kPreset + "20, 100, 150)",
               .unit = "a/U_inf",
               .contexts = kSpheres,
               .doc = "stage 1 at most this long",
               .rules = ">= protocol.stage1_min"});
  t.push_back({.path = "protocol.stage2_settle",
               .type = FieldType::number,
               .range = duration,
               .default_rule = kPreset + "10, 50, 100)",
               .unit = "a/U_inf",
               .contexts = kSpheres,
               .doc = "with du > 0: settling time before the statistics"});
  t.push_back({.path = "protocol.statistics",
               .type = FieldType::number,
               .range = {.above = 0, .at_most = 1e5},
               .default_rule = kPreset + "20, 100, 300)",
               .unit = "a/U_inf",
               .contexts = kSpheres,
               .doc = "averaging window",
               .rules = ">= 20 protocol.sample_every"});
  t.push_back({.path = "protocol.sample_every",
               .type = FieldType::number,
               .range = {.above = 0, .at_most = 100},
               .fallback = 0.5,
               .unit = "a/U_inf",
               .contexts = kSpheres,
               .doc = "time-series cadence"});
  t.push_back({.path = "protocol.stationarity_window",
               .type = FieldType::number,
               .range = {.above = 0, .at_most = 1e4},
               .fallback = 20.0,
               .unit = "a/U_inf",
               .contexts = kSpheres,
               .doc = "window of stage 1's stationarity test"});
  t.push_back({.path = "protocol.snapshot_every",
               .type = FieldType::number,
               .range = duration,
               .fallback = 10.0,
               .unit = "a/U_inf",
               .contexts = kSpheres,
               .doc = "sphere snapshots, and one at the end (0: none at all)"});
  t.push_back({.path = "protocol.checkpoint_every_s",
               .type = FieldType::number,
               .range = {.above = 0},
               .fallback = 600.0,
               .unit = "s (wall clock)",
               .contexts = kSpheres,
               .doc = "checkpoint cadence"});
  t.push_back({.path = "protocol.progress_every_s",
               .type = FieldType::number,
               .range = {.above = 0, .at_most = 3600},
               .fallback = 2.0,
               .unit = "s (wall clock)",
               .contexts = kSpheres,
               .doc = "progress.json cadence"});
  t.push_back({.path = "protocol.threads",
               .type = FieldType::integer,
               .range = {.at_least = 0, .at_most = 1024},
               .fallback = 0,
               .contexts = kSpheres,
               .doc = "OpenMP threads (0: all)"});
}

// The fluid scene's fields (docs/user-guide.md, "Case file: the fluid scene").
void add_fluid_fields(std::vector<FieldSpec>& t) {
  t.push_back({.path = "fluid",
               .type = FieldType::object,
               .default_rule = "required",
               .contexts = kFluid,
               .doc = "the periodic box of liquid"});
  t.push_back({.path = "fluid.size",
               .type = FieldType::numbers,
               .range = {.at_least = 1, .at_most = 4096},
               .length = 3,
               .default_rule = "required",
               .unit = "cells",
               .contexts = kFluid,
               .doc = "box nx, ny, nz",
               .rules = "whole numbers; populations fit in 80 % of memory"});
  t.push_back({.path = "fluid.viscosity",
               .type = FieldType::number,
               .range = {.above = 0, .at_most = 1, .why = "(tau = 3 nu + 1/2 must exceed 1/2)"},
               .default_rule = "required",
               .unit = "lattice units",
               .contexts = kFluid,
               .doc = "kinematic viscosity nu; below 0.005 accepted with a warning"});
  t.push_back({.path = "fluid.trt_magic",
               .type = FieldType::number,
               .range = {.above = 0, .at_most = 10},
               .fallback = 0.25,
               .contexts = kFluid,
               .doc = "TRT magic parameter Lambda"});
  t.push_back({.path = "fluid.body_force",
               .type = FieldType::numbers,
               .range = {.at_least = -0.01, .at_most = 0.01},
               .length = 3,
               .fallback = nlohmann::json::array({0, 0, 0}),
               .unit = "lattice units",
               .contexts = kFluid,
               .doc = "uniform force density",
               .rules = "the mean flow it builds over run.steps stays under the Mach limit"});
}

// fluid.initial: the initial velocity field.
void add_fluid_initial_fields(std::vector<FieldSpec>& t) {
  const Range speed{.at_least = -kMaxLatticeSpeed,
                    .at_most = kMaxLatticeSpeed,
                    .why = "(Mach limit |u| <= 0.2 c_s)"};
  const Range amplitude{
      .at_least = 0, .at_most = kMaxLatticeSpeed, .why = "(Mach limit |u| <= 0.2 c_s)"};
  const std::string waves = "only for type shear_wave and taylor_green";
  t.push_back({.path = "fluid.initial",
               .type = FieldType::object,
               .contexts = kFluid,
               .doc = "the initial velocity field"});
  t.push_back({.path = "fluid.initial.type",
               .type = FieldType::choice,
               .choices = {"rest", "uniform", "shear_wave", "taylor_green"},
               .fallback = "rest",
               .contexts = kFluid,
               .doc = "kind of initial field"});
  t.push_back({.path = "fluid.initial.velocity",
               .type = FieldType::numbers,
               .range = speed,
               .length = 3,
               .fallback = nlohmann::json::array({0, 0, 0}),
               .unit = "lattice units",
               .contexts = kFluid,
               .doc = "uniform flow added to any type"});
  t.push_back({.path = "fluid.initial.amplitude",
               .type = FieldType::number,
               .range = amplitude,
               .default_rule = "required for waves",
               .unit = "lattice units",
               .contexts = kFluid,
               .doc = "wave amplitude",
               .rules = waves});
  t.push_back({.path = "fluid.initial.wavelengths",
               .type = FieldType::integer,
               .range = {.at_least = 1, .at_most = 1024},
               .fallback = 1,
               .contexts = kFluid,
               .doc = "whole wavelengths across the box",
               .rules = waves + "; at least 4 cells per wavelength"});
  t.push_back({.path = "fluid.initial.axis",
               .type = FieldType::choice,
               .choices = {"x", "y", "z"},
               .fallback = "x",
               .contexts = kFluid,
               .doc = "shear wave: direction of the wave vector",
               .rules = "type shear_wave only"});
  t.push_back({.path = "fluid.initial.component",
               .type = FieldType::choice,
               .choices = {"x", "y", "z"},
               .fallback = "y",
               .contexts = kFluid,
               .doc = "shear wave: velocity component",
               .rules = "type shear_wave only; differs from axis"});
  t.push_back({.path = "fluid.initial.plane",
               .type = FieldType::choice,
               .choices = {"xy", "yz", "zx"},
               .fallback = "xy",
               .contexts = kFluid,
               .doc = "Taylor-Green plane",
               .rules = "type taylor_green only"});
  t.push_back({.path = "fluid.initial.noise",
               .type = FieldType::number,
               .range = amplitude,
               .fallback = 0.0,
               .unit = "lattice units",
               .contexts = kFluid,
               .doc = "random velocity perturbation per component",
               .rules = "peak initial speed under the Mach limit"});
  t.push_back({.path = "fluid.initial.seed",
               .type = FieldType::integer,
               .range = {.at_least = 0, .at_most = 4294967295.0},
               .fallback = 1,
               .contexts = kFluid,
               .doc = "noise seed (reproducible per cell)"});
}

// run: the fluid scene's steps and output.
void add_fluid_run_fields(std::vector<FieldSpec>& t) {
  t.push_back(
      {.path = "run", .type = FieldType::object, .contexts = kFluid, .doc = "steps and output"});
  t.push_back({.path = "run.steps",
               .type = FieldType::integer,
               .range = {.at_least = 0, .at_most = 1e12},
               .fallback = 1000,
               .contexts = kFluid,
               .doc = "time steps"});
  t.push_back({.path = "run.progress_every_s",
               .type = FieldType::number,
               .range = {.above = 0, .at_most = 3600},
               .fallback = 2.0,
               .unit = "s (wall clock)",
               .contexts = kFluid,
               .doc = "progress.json cadence"});
  t.push_back({.path = "run.checkpoint_every_s",
               .type = FieldType::number,
               .range = {.above = 0},
               .fallback = 600.0,
               .unit = "s (wall clock)",
               .contexts = kFluid,
               .doc = "checkpoint cadence"});
  t.push_back({.path = "run.write_fields",
               .type = FieldType::boolean,
               .fallback = false,
               .contexts = kFluid,
               .doc = "write field snapshots"});
  t.push_back({.path = "run.fields_every",
               .type = FieldType::integer,
               .range = {.at_least = 0},
               .fallback = 0,
               .unit = "steps",
               .contexts = kFluid,
               .doc = "field snapshot cadence (0: the final one only)"});
  t.push_back({.path = "run.threads",
               .type = FieldType::integer,
               .range = {.at_least = 0, .at_most = 1024},
               .fallback = 0,
               .contexts = kFluid,
               .doc = "OpenMP threads (0: all)"});
}

FieldTable make_table() {
  FieldTable table{.what = "case", .context_field = "scene"};
  for (const auto& entry : kScenes) table.context_names.emplace_back(entry.name);
  auto& t = table.fields;
  t.push_back({.path = "scene",
               .type = FieldType::choice,
               .choices = scene_names(),
               .default_rule = "required",
               .contexts = kEvery,
               .doc = "what runs (table \"scene\" below)"});
  t.push_back({.path = "precision",
               .type = FieldType::choice,
               .choices = {"double", "float"},
               .fallback = "double",
               .contexts = kEvery,
               .doc = "floating point of the lattice"});
  t.push_back({.path = "device",
               .type = FieldType::choice,
               .choices = {"cpu", "cuda"},
               .fallback = "cpu",
               .contexts = kEvery,
               .doc = "where the lattice steps (docs/gpu.md); `flocsim run --device` overrides it",
               .rules = "cuda: the fluid scene, and sphere scenes with a liquid (immersed "
                        "boundary or partially saturated cells; not granular); needs a CUDA "
                        "build and a usable GPU"});
  add_sphere_fields(t);
  add_physics_fields(t);
  add_lubrication_and_box_fields(t);
  add_numerics_fields(t);
  add_coupling_fields(t);
  add_input_radius_field(t);
  add_protocol_fields(t);
  add_fluid_fields(t);
  add_fluid_initial_fields(t);
  add_fluid_run_fields(t);
  return table;
}

// Sets `value` at the dotted `path` of `schema`'s nested properties.
void put_property(nlohmann::ordered_json& properties, const std::string& path,
                  const nlohmann::ordered_json& value) {
  const auto dot = path.find('.');
  if (dot == std::string::npos) {
    properties[path] = value;
    return;
  }
  put_property(properties[path.substr(0, dot)]["properties"], path.substr(dot + 1), value);
}

// The rules of one scene: its refused fields (false), its required ones.
nlohmann::ordered_json scene_rule(const FieldTable& table, int scene) {
  nlohmann::ordered_json then = {{"properties", nlohmann::ordered_json::object()}};
  for (const FieldSpec& f : table.fields) {
    if ((f.contexts >> scene) & 1u || f.warn_when_unused) continue;
    const auto dot = f.path.rfind('.');
    const FieldSpec* parent =
        dot == std::string::npos ? nullptr : table.find(f.path.substr(0, dot));
    if (parent && !((parent->contexts >> scene) & 1u)) continue;  // refused with its parent
    put_property(then["properties"], f.path, false);
  }
  const Scene s = static_cast<Scene>(scene);
  if (s == Scene::suspension || s == Scene::granular) then["required"] = {"phi"};
  if (s == Scene::fixed_array) {
    then["oneOf"] = {{{"required", {"phi"}}}, {{"required", {"positions_from"}}}};
  }
  if (s == Scene::fluid) {
    then["required"] = {"fluid"};
    then["properties"]["fluid"] = {{"required", {"size", "viscosity"}}};
  }
  return {{"if",
           {{"properties", {{"scene", {{"const", std::string(scene_name(s))}}}}},
            {"required", {"scene"}}}},
          {"then", then}};
}

}  // namespace

const FieldTable& case_field_table() {
  static const FieldTable table = make_table();
  return table;
}

const FieldSpec& case_field(std::string_view path) {
  const FieldSpec* f = case_field_table().find(path);
  if (!f) throw std::logic_error("case field " + std::string(path) + " is not declared");
  return *f;
}

double case_number(input::InputReader& reader, const std::string& key,
                   const std::optional<Range>& range, std::optional<double> fallback) {
  const FieldSpec& f = case_field(reader.field(key));
  if (!fallback && f.fallback.is_number()) fallback = f.fallback.get<double>();
  return reader.number(key, range ? *range : f.range, fallback);
}

long case_integer(input::InputReader& reader, const std::string& key) {
  const FieldSpec& f = case_field(reader.field(key));
  std::optional<long> fallback;
  if (f.fallback.is_number()) fallback = f.fallback.get<long>();
  return reader.integer(key, f.range, fallback);
}

bool case_boolean(input::InputReader& reader, const std::string& key) {
  const FieldSpec& f = case_field(reader.field(key));
  std::optional<bool> fallback;
  if (f.fallback.is_boolean()) fallback = f.fallback.get<bool>();
  return reader.boolean(key, fallback);
}

std::string case_choice(input::InputReader& reader, const std::string& key,
                        std::optional<std::string> fallback) {
  const FieldSpec& f = case_field(reader.field(key));
  if (!fallback && f.fallback.is_string()) fallback = f.fallback.get<std::string>();
  return reader.choice(key, f.choices, fallback);
}

std::string case_fields_markdown(bool with_spheres) {
  const FieldTable& table = case_field_table();
  FieldTable part{.what = table.what,
                  .context_field = table.context_field,
                  .context_names = table.context_names};
  const unsigned mask = with_spheres ? kSpheres : kFluid;
  for (const FieldSpec& f : table.fields)
    if (f.contexts & mask) part.fields.push_back(f);
  if (!with_spheres) part.context_names.clear();  // one scene: no column for it
  return input::markdown_table(part, {});
}

nlohmann::ordered_json partial_case_schema() {
  return {{"type", "object"},
          {"properties", input::schema_properties(case_field_table(), "")},
          {"additionalProperties", false}};
}

nlohmann::ordered_json case_schema() {
  const FieldTable& table = case_field_table();
  nlohmann::ordered_json schema = {
      {"$schema", "https://json-schema.org/draft/2020-12/schema"},
      {"title", "flocsim case file"},
      {"description",
       "A flocsim case (docs/user-guide.md). Generated by `flocsim case schema` from the "
       "case field table (engine/case/case_fields.cpp); rules that tie fields together are "
       "checked by flocsim itself."},
      {"type", "object"},
      {"properties", input::schema_properties(table, "")},
      {"additionalProperties", false},
      {"required", {"scene"}}};
  nlohmann::ordered_json rules = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < table.context_names.size(); ++i)
    rules.push_back(scene_rule(table, static_cast<int>(i)));
  schema["allOf"] = rules;
  return schema;
}

}  // namespace flocsim::cases
