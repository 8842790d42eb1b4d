#include "engine/run/case_cost.hpp"

#include <malloc.h>
#include <omp.h>

#include <thread>
#include <vector>

#include "engine/case/scene.hpp"
#include "engine/run/coupled_step.hpp"
#include "engine/run/protocol.hpp"
#include "engine/run/sphere_run.hpp"
#include "engine/run/timed_stages.hpp"

namespace flocsim::run {

namespace {

// Sets the OpenMP threads for the lifetime of the object, as a run would.
class ThreadsAsTheRun {
 public:
  explicit ThreadsAsTheRun(int threads) : before_(omp_get_max_threads()) {
    if (threads > 0) omp_set_num_threads(threads);
  }
  ~ThreadsAsTheRun() { omp_set_num_threads(before_); }
  ThreadsAsTheRun(const ThreadsAsTheRun&) = delete;
  ThreadsAsTheRun& operator=(const ThreadsAsTheRun&) = delete;

 private:
  int before_;
};

// After the setup: one untimed step (it touches every page and sizes each
// stage's scratch), then at least `steps` steps and `seconds` seconds timed.
// `advance` takes one step and says whether the state is still sound.
template <class Advance>
void time_steps(StepMeasurement& m, Advance&& advance, int steps, double seconds,
                double memory_before) {
  m.threads = omp_get_max_threads();
  if (!advance()) return;
  const auto t1 = TimedStages::Clock::now();
  while ((m.steps < steps || TimedStages::since(t1) < seconds) && m.steps < kMostMeasuredSteps) {
    if (!advance()) break;
    ++m.steps;
  }
  if (m.steps > 0) m.step_s = TimedStages::since(t1) / m.steps;
  m.memory_bytes = std::max(0.0, allocated_bytes() - memory_before);
}

template <class Real>
StepMeasurement measure_sphere_steps(const cases::SuspensionCase& c, int steps, double seconds) {
  StepMeasurement m;
  const double memory_before = allocated_bytes();
  const auto t0 = TimedStages::Clock::now();
  TimedStages stages;
  const cases::SceneModules& modules = cases::modules_of(c.scene);
  const Protocol protocol(c, modules);
  CoupledStep<Real> step(c, protocol.escape_velocity(), stages);
  spheres::SphereSet s;
  s.radius = c.numerics.radius_cells;
  s.density_ratio = c.physics.density_ratio;
  place_spheres(c, modules, step.box(), s);
  m.setup_s = TimedStages::since(t0);
  time_steps(
      m, [&] { return step.advance(s).empty(); }, steps, seconds, memory_before);
  return m;
}

template <class Real>
StepMeasurement measure_fluid_steps(const cases::FluidCase& c, int steps, double seconds) {
  StepMeasurement m;
  const double memory_before = allocated_bytes();
  const auto t0 = TimedStages::Clock::now();
  lattice::FluidLattice<Real> fluid(c.size, c.relaxation);
  fluid.set_body_force(c.body_force);
  fluid.initialise_equilibrium(
      [&](int x, int y, int z) { return cases::initial_state(c, x, y, z); });
  m.setup_s = TimedStages::since(t0);
  time_steps(
      m,
      [&] {
        fluid.step();
        return true;
      },
      steps, seconds, memory_before);
  return m;
}

}  // namespace

CaseSize case_size(const cases::ParsedCase& parsed) {
  CaseSize z;
  if (parsed.fluid_scene) {
    const cases::FluidCase& c = parsed.fluid;
    z.scene = std::string(cases::scene_name(cases::Scene::fluid));
    z.box = c.size;
    z.cells = c.size.cells();
    z.single_precision = c.precision == cases::Precision::single_precision;
    z.steps_min = z.steps_max = c.run.steps;
    z.threads = c.run.threads;
    nlohmann::json key = c.to_json();
    key["fluid"].erase("viscosity");
    key["fluid"].erase("initial");
    key["fluid"].erase("body_force");
    key.erase("run");
    key["threads"] = c.run.threads;
    z.cost_key = key;
    return z;
  }
  const cases::SuspensionCase& c = parsed.spheres;
  const cases::SceneModules& modules = cases::modules_of(c.scene);
  z.scene = std::string(cases::scene_name(c.scene));
  if (modules.liquid) {
    z.box = c.derived.box;
    z.cells = c.derived.box.cells();
  }
  z.spheres = c.derived.sphere_count;
  z.single_precision = c.numerics.single_precision;
  const auto [shortest, longest] = Protocol(c, modules).length_bounds();
  z.steps_min = shortest;
  z.steps_max = longest;
  z.steps_per_convective_time = c.derived.convective_time;
  z.threads = c.protocol.threads;
  nlohmann::json key = c.to_json();
  for (const char* physics_only : {"seed", "Re_inf", "du_over_Uinf", "protocol"})
    key.erase(physics_only);
  key["numerics"].erase("viscosity");
  key["numerics"].erase("input_radius");
  key["threads"] = c.protocol.threads;
  // the box and N, which the case's fields set, decide the cost; say them outright
  key["box_cells"] = {z.box.nx, z.box.ny, z.box.nz};
  key["sphere_count"] = z.spheres;
  z.cost_key = key;
  return z;
}

StepMeasurement measure_steps(const cases::ParsedCase& c, int steps, double seconds, int copies) {
  auto one = [&c, steps, seconds] {
    if (c.fluid_scene) {
      const ThreadsAsTheRun threads(c.fluid.run.threads);
      return c.fluid.precision == cases::Precision::single_precision
                 ? measure_fluid_steps<float>(c.fluid, steps, seconds)
                 : measure_fluid_steps<double>(c.fluid, steps, seconds);
    }
    const ThreadsAsTheRun threads(c.spheres.protocol.threads);
    return c.spheres.numerics.single_precision
               ? measure_sphere_steps<float>(c.spheres, steps, seconds)
               : measure_sphere_steps<double>(c.spheres, steps, seconds);
  };
  if (copies <= 1) return one();
  // Each std::thread is an initial thread to OpenMP, with its own team of the
  // case's threads, as each worker process of a sweep has.
  std::vector<StepMeasurement> each(static_cast<std::size_t>(copies));
  std::vector<std::thread> workers;
  for (int i = 0; i < copies; ++i) workers.emplace_back([&each, &one, i] { each[i] = one(); });
  for (std::thread& w : workers) w.join();
  StepMeasurement m = each.front();
  m.setup_s = m.step_s = 0;
  m.steps = 0;
  for (const StepMeasurement& e : each) {
    m.setup_s += e.setup_s / copies;
    m.step_s += e.step_s / copies;
    m.steps = std::max(m.steps, e.steps);
  }
  // copies that overlap in time see each other's memory: not one run's
  m.memory_bytes = 0;
  return m;
}

double allocated_bytes() {
  // every arena's bytes in use plus the large blocks mapped on their own:
  // unlike the resident set, not lowered when freed memory is reused
  const struct mallinfo2 m = mallinfo2();
  return static_cast<double>(m.uordblks) + static_cast<double>(m.hblkhd);
}

}  // namespace flocsim::run
