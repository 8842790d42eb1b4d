#include "engine/case/fluid_case.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>

#include "engine/case/case_fields.hpp"
#include "engine/case/case_support.hpp"
#include "engine/case/scene.hpp"
#include "engine/input/input_reader.hpp"

namespace flocsim::cases {

using input::InputError;
using input::InputReader;
using input::Range;

namespace {

const char* kAxisNames[3] = {"x", "y", "z"};

int axis_index(const std::string& s) {
  return s == "x" ? 0 : s == "y" ? 1 : 2;
}

int extent_along(const lattice::Extent& e, int axis) {
  return axis == 0 ? e.nx : axis == 1 ? e.ny : e.nz;
}

// A uniform random number in [-1, 1) that depends only on (seed, cell), so the
// initial field does not depend on the order in which cells are visited.
double cell_noise(unsigned seed, long cell, int component) {
  std::uint64_t z = (static_cast<std::uint64_t>(seed) << 40) ^
                    (static_cast<std::uint64_t>(cell) * 3 + static_cast<std::uint64_t>(component));
  z += 0x9e3779b97f4a7c15ULL;  // splitmix64
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-52 - 1.0;
}

// fluid.initial: the type, the uniform flow added to it and its wave. The
// wave's fields apply to the wave types only: given with another type they
// are refused naming the type.
void read_initial_field(InputReader& fluid, FluidCase& c) {
  InputReader init = fluid.object("initial");
  InitialField& in = c.initial;
  in.type = case_choice(init, "type");
  const auto u = init.numbers("velocity", 3, case_field("fluid.initial.velocity").range,
                              std::vector<double>{0, 0, 0});
  in.mean_velocity = {u[0], u[1], u[2]};
  const bool wave = in.type == "shear_wave" || in.type == "taylor_green";
  auto only_for = [&](const char* key, bool applies, const char* types) {
    if (!applies && init.has(key))
      throw InputError(init.field(key) + ": only with " + init.field("type") + " " + types +
                       " (type = \"" + in.type + "\")");
  };
  only_for("amplitude", wave, "\"shear_wave\" or \"taylor_green\"");
  only_for("wavelengths", wave, "\"shear_wave\" or \"taylor_green\"");
  only_for("axis", in.type == "shear_wave", "\"shear_wave\"");
  only_for("component", in.type == "shear_wave", "\"shear_wave\"");
  only_for("plane", in.type == "taylor_green", "\"taylor_green\"");
  if (wave) {
    in.amplitude = case_number(init, "amplitude");
    in.wavelengths = static_cast<int>(case_integer(init, "wavelengths"));
  }
  if (in.type == "shear_wave") {
    in.axis = axis_index(case_choice(init, "axis"));
    in.component = axis_index(case_choice(init, "component"));
    if (in.component == in.axis)
      throw InputError(init.field("component") + " = \"" + kAxisNames[in.component] +
                       "\": must differ from " + init.field("axis") +
                       " (a shear wave is transverse)");
  }
  if (in.type == "taylor_green") {
    const std::string plane = case_choice(init, "plane");
    in.plane_first = axis_index(plane.substr(0, 1));
    in.plane_second = axis_index(plane.substr(1, 1));
  }
  in.noise = case_number(init, "noise");
  in.seed = static_cast<unsigned>(case_integer(init, "seed"));
  init.finish();
}

// The initial wave's resolution: at least 4 cells per wavelength.
void check_wave_resolution(const FluidCase& c) {
  const InitialField& in = c.initial;
  auto check = [&](int axis) {
    const int n = extent_along(c.size, axis);
    if (n < 4 * in.wavelengths)
      throw InputError("fluid.size[" + std::to_string(axis) + "] = " + std::to_string(n) +
                       ": must be >= 4 x fluid.initial.wavelengths = " +
                       std::to_string(4 * in.wavelengths) + " to resolve the initial wave");
  };
  if (in.type == "shear_wave") check(in.axis);
  if (in.type == "taylor_green") {
    check(in.plane_first);
    check(in.plane_second);
  }
}

// fluid: size, viscosity, trt_magic, body_force and the initial field.
void read_fluid(InputReader& root, FluidCase& c) {
  InputReader fluid = root.object("fluid", true);
  const auto size = fluid.numbers("size", 3, case_field("fluid.size").range);
  for (int d = 0; d < 3; ++d)
    if (size[d] != std::floor(size[d]))
      throw InputError(fluid.field("size") + "[" + std::to_string(d) +
                       "] = " + exact_value(size[d]) + ": must be a whole number of cells");
  c.size = {static_cast<int>(size[0]), static_cast<int>(size[1]), static_cast<int>(size[2])};
  c.relaxation.viscosity = case_number(fluid, "viscosity");
  c.relaxation.magic_lambda = case_number(fluid, "trt_magic");
  if (c.relaxation.viscosity < kSmallestTestedViscosity)
    c.warnings.push_back(fluid.field("viscosity") + " = " + exact_value(c.relaxation.viscosity) +
                         " is below the smallest viscosity the solver is tested at (" +
                         format_value(kSmallestTestedViscosity) + ", tau = 0.515)");
  const auto f = fluid.numbers("body_force", 3, case_field("fluid.body_force").range,
                               std::vector<double>{0, 0, 0});
  c.body_force = {f[0], f[1], f[2]};
  read_initial_field(fluid, c);
  fluid.finish();
  check_wave_resolution(c);
}

void read_run_control(InputReader& root, FluidCase& c) {
  InputReader run = root.object("run");
  c.run.steps = case_integer(run, "steps");
  c.run.progress_every_s = case_number(run, "progress_every_s");
  c.run.checkpoint_every_s = case_number(run, "checkpoint_every_s");
  c.run.write_fields = case_boolean(run, "write_fields");
  c.run.fields_every = case_integer(run, "fields_every");
  c.run.threads = static_cast<int>(case_integer(run, "threads"));
  run.finish();
}

// The Mach limit for the initial field and for the mean flow the body force
// builds up, and the memory the populations need.
void check_fluid_limits(const FluidCase& c) {
  const InitialField& in = c.initial;
  // The largest speed the initial field reaches (mean + wave + noise along a
  // component, bounded by the Euclidean sum) must respect the Mach limit.
  const double mean = std::hypot(in.mean_velocity.x, in.mean_velocity.y, in.mean_velocity.z);
  double wave_peak = in.amplitude;
  if (in.type == "taylor_green")  // the second velocity component carries U k1 / k2
    wave_peak *= std::max(1.0, static_cast<double>(extent_along(c.size, in.plane_second)) /
                                   extent_along(c.size, in.plane_first));
  const double peak = mean + wave_peak + std::sqrt(3.0) * in.noise;
  if (peak > kMaxLatticeSpeed)
    throw InputError("fluid.initial: peak initial speed |velocity| + wave peak + sqrt(3) noise = " +
                     format_value(peak) + ": must be <= " + format_value(kMaxLatticeSpeed) +
                     " (Mach limit |u| <= 0.2 c_s)");
  // A uniform body force in a fully periodic box accelerates the mean flow
  // without bound (nothing balances it): u_mean(t) = u_mean(0) + f t / rho.
  const double fmag = std::hypot(c.body_force.x, c.body_force.y, c.body_force.z);
  const double final_mean = mean + fmag * static_cast<double>(c.run.steps);
  if (fmag > 0 && final_mean > kMaxLatticeSpeed)
    throw InputError("fluid.body_force = [" + exact_value(c.body_force.x) + ", " +
                     exact_value(c.body_force.y) + ", " + exact_value(c.body_force.z) +
                     "]: accelerates the mean flow to |u| = " + format_value(final_mean) +
                     " after run.steps = " + std::to_string(c.run.steps) +
                     "; must stay <= " + format_value(kMaxLatticeSpeed) +
                     " (Mach limit |u| <= 0.2 c_s; a periodic box has nothing to balance it)");
  // Memory: 19 populations per cell in the chosen precision.
  const double bytes = static_cast<double>(c.size.cells()) * 19.0 *
                       (c.precision == Precision::double_precision ? 8.0 : 4.0);
  const double available = physical_memory_bytes();
  if (available > 0 && bytes > 0.8 * available)
    throw InputError("fluid.size = [" + std::to_string(c.size.nx) + ", " +
                     std::to_string(c.size.ny) + ", " + std::to_string(c.size.nz) + "]: needs " +
                     format_value(bytes / 1e9) +
                     " GB for the populations; must fit in 80 % of this machine's " +
                     format_value(available / 1e9) + " GB");
}

}  // namespace

FluidCase parse_fluid_case(const nlohmann::json& document) {
  FluidCase c;
  InputReader root(document, "");
  root.choice("scene", {std::string(scene_name(Scene::fluid))});
  // every field against its declaration: unknown, unused in this scene, type, range
  c.warnings = input::check_fields(case_field_table(), document, scene_context(Scene::fluid));
  c.precision = case_choice(root, "precision") == "float" ? Precision::single_precision
                                                          : Precision::double_precision;
  parse_device_name(case_choice(root, "device"), c.device);
  read_fluid(root, c);
  read_run_control(root, c);
  root.finish();
  check_fluid_limits(c);
  return c;
}

nlohmann::json FluidCase::to_json() const {
  nlohmann::json j;
  j["scene"] = std::string(scene_name(Scene::fluid));
  j["precision"] = precision == Precision::single_precision ? "float" : "double";
  // written only off the default, so cases and checkpoints from before the
  // field existed read the same
  if (device != Device::cpu) j["device"] = device_name(device);
  auto& f = j["fluid"];
  f["size"] = {size.nx, size.ny, size.nz};
  f["viscosity"] = relaxation.viscosity;
  f["trt_magic"] = relaxation.magic_lambda;
  f["body_force"] = {body_force.x, body_force.y, body_force.z};
  auto& i = f["initial"];
  i["type"] = initial.type;
  i["velocity"] = {initial.mean_velocity.x, initial.mean_velocity.y, initial.mean_velocity.z};
  if (initial.type == "shear_wave" || initial.type == "taylor_green") {
    i["amplitude"] = initial.amplitude;
    i["wavelengths"] = initial.wavelengths;
  }
  if (initial.type == "shear_wave") {
    i["axis"] = kAxisNames[initial.axis];
    i["component"] = kAxisNames[initial.component];
  }
  if (initial.type == "taylor_green")
    i["plane"] = std::string(kAxisNames[initial.plane_first]) + kAxisNames[initial.plane_second];
  i["noise"] = initial.noise;
  i["seed"] = initial.seed;
  auto& r = j["run"];
  r["steps"] = run.steps;
  r["progress_every_s"] = run.progress_every_s;
  r["checkpoint_every_s"] = run.checkpoint_every_s;
  r["write_fields"] = run.write_fields;
  r["fields_every"] = run.fields_every;
  r["threads"] = run.threads;
  return j;
}

double initial_wave_number(const FluidCase& c) {
  const auto& in = c.initial;
  if (in.type == "shear_wave") return 2 * M_PI * in.wavelengths / extent_along(c.size, in.axis);
  if (in.type == "taylor_green")
    return 2 * M_PI * in.wavelengths / extent_along(c.size, in.plane_first);
  return 0.0;
}

double analytic_decay_rate(const FluidCase& c) {
  const double k = initial_wave_number(c), nu = c.relaxation.viscosity;
  if (c.initial.type == "shear_wave") return nu * k * k;
  if (c.initial.type == "taylor_green") {
    // both wave numbers of the vortex: nu (k1^2 + k2^2)
    const double k2 =
        2 * M_PI * c.initial.wavelengths / extent_along(c.size, c.initial.plane_second);
    return nu * (k * k + k2 * k2);
  }
  return 0.0;
}

lattice::Macroscopic initial_state(const FluidCase& c, int x, int y, int z) {
  const auto& in = c.initial;
  double u[3] = {in.mean_velocity.x, in.mean_velocity.y, in.mean_velocity.z};
  double rho = 1.0;
  const int r[3] = {x, y, z};
  if (in.type == "shear_wave") {
    const double k = initial_wave_number(c);
    u[in.component] += in.amplitude * std::sin(k * r[in.axis]);
  } else if (in.type == "taylor_green") {
    // u_a = -U cos(k1 a) sin(k2 b), u_b = U (k1/k2) sin(k1 a) cos(k2 b): divergence free;
    // pressure p = -U^2/4 (cos 2 k1 a + (k1/k2)^2 cos 2 k2 b) carried by rho = 1 + 3 p.
    const int a = in.plane_first, b = in.plane_second;
    const double k1 = 2 * M_PI * in.wavelengths / extent_along(c.size, a);
    const double k2 = 2 * M_PI * in.wavelengths / extent_along(c.size, b);
    const double U = in.amplitude, ratio = k1 / k2;
    u[a] += -U * std::cos(k1 * r[a]) * std::sin(k2 * r[b]);
    u[b] += U * ratio * std::sin(k1 * r[a]) * std::cos(k2 * r[b]);
    const double p =
        -0.25 * U * U * (std::cos(2 * k1 * r[a]) + ratio * ratio * std::cos(2 * k2 * r[b]));
    rho = 1.0 + 3.0 * p;
  }
  if (in.noise > 0) {
    const long cell = x + static_cast<long>(c.size.nx) * (y + static_cast<long>(c.size.ny) * z);
    for (int d = 0; d < 3; ++d) u[d] += in.noise * cell_noise(in.seed, cell, d);
  }
  return {rho, {u[0], u[1], u[2]}};
}

}  // namespace flocsim::cases
