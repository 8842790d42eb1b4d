// GPU coupled-step benchmark: a coupling on the GPU (engine/coupling_gpu:
// the immersed boundary, or partially saturated cells) plus the lattice step,
// against the lattice step alone with its force field (the reference
// bench_coupling takes on the CPU), measured in the same run and alternated
// repetition by repetition. Default scene: the paper's case, phi = 0.20, a = 6 dx, box
// 288 x 144 x 144, N = 1320 spheres placed randomly without overlap, moving
// and turning (so the surface velocity is not zero), a_g = 5.612 (the paper
// method's input radius at a = 6). The spheres do not move between steps:
// their dynamics (events, lubrication, sphere equations) stay on the CPU and
// cost about 1 ms a step (issue 39's table), timed by bench_coupling there.
//
// Printed per option and precision: the median over repetitions of the fluid
// alone (MLUPS), of the full coupled step, their ratio (target: >= 50 %), and
// the coupling's milliseconds per step: the full step's less the fluid's.
// Its full_step_ms per option is what `flocsim sweep plan --gpu-rate` reads.
//
// Usage: bench_coupling_gpu [--scale S] [--reps R] [--steps K]
//                           [--options OPTION,...] [--precision float|double|all]
//                           [--json FILE]
//   --scale S   shrinks the box to (288 x 144 x 144) / S at the same phi
//   --options   as bench_coupling's (direct:KERNEL:SPACING:SWEEPS,
//               control:KERNEL:SPACING[:G:P], psm); default: the presets'
//               schemes direct:roma3:1.0:1 and direct:roma3:0.7:2, and the
//               couplings a case may choose, control:roma3:1.0 (cases refuse
//               control forcing with markers closer than 1 dx) and psm
// Exit: 0 measured; 77 no usable GPU (the reason printed); 2 bad arguments.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "bench/coupling_options.hpp"
#include "engine/coupling_gpu/gpu_immersed_boundary.hpp"
#include "engine/coupling_gpu/gpu_partially_saturated.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/lattice_gpu/gpu_fluid_lattice.hpp"
#include "engine/lattice_gpu/gpu_runtime.hpp"
#include "engine/partially_saturated/covered_cell_body.hpp"
#include "engine/placement/random_placement.hpp"

using namespace flocsim;
using spheres::Vec3;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

spheres::SphereSet suspension(lattice::Extent e, double a, double phi) {
  spheres::SphereSet s;
  s.radius = a;
  const spheres::PeriodicBox box{Vec3(e.nx, e.ny, e.nz)};
  const int n = static_cast<int>(std::lround(phi * e.cells() / s.volume()));
  s.resize(static_cast<std::size_t>(n));
  s.position = placement::place_randomly({.count = n, .radius = a, .seed = 7}, box);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> u(0.0, 0.01);
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.velocity[i] = Vec3(0.02 + u(rng), u(rng), u(rng));
    s.angular_velocity[i] = Vec3(u(rng), u(rng), u(rng)) / a;
  }
  return s;
}

// The spheres' radius, and the input radius each coupling takes at it: the
// paper method's a_g at a = 6 for the immersed boundary, a itself for
// partially saturated cells (as bench_coupling takes them on the CPU).
constexpr double kRadius = 6.0;
constexpr double kImmersedBoundaryInputRadius = 5.612;
constexpr double kPartiallySaturatedInputRadius = kRadius;

// One coupled step on the GPU, in the time loop's order: the coupling's
// forcing (the immersed boundary's sweeps, or the spheres' coverage), the
// lattice step, and for partially saturated cells the exchange that gives
// each sphere its load.
template <class Real>
class CoupledGpuStep {
 public:
  CoupledGpuStep(const coupling::Scheme& scheme, gpu::GpuFluidLattice<Real>& lattice)
      : lattice_(lattice) {
    if (scheme.immersed_boundary())
      ib_ = std::make_unique<gpu::GpuImmersedBoundary<Real>>(
          immersed_boundary::ImmersedBoundarySettings{.input_radius = kImmersedBoundaryInputRadius,
                                                      .scheme = scheme});
    else
      psm_ = std::make_unique<gpu::GpuPartiallySaturatedCells<Real>>(kPartiallySaturatedInputRadius,
                                                                     lattice);
  }
  void step(lattice::FluidLattice<Real>& mirror, const spheres::SphereSet& s) {
    if (ib_) ib_->apply(lattice_, s);  // waits for its loads: the step's real order
    if (psm_) psm_->apply(mirror, s);
    lattice_.step();
    if (psm_) psm_->after_liquid_step(mirror, s);  // waits for the exchange
  }
  // What the coupling's cost scales with, per sphere (orchestrator/gpu_rates.hpp):
  // its markers, or the cells of the cube it covers.
  nlohmann::json work_per_sphere() const {
    if (ib_) return {{"markers_per_sphere", ib_->markers_per_sphere()}};
    const int edge = partially_saturated::covering_box_edge(kPartiallySaturatedInputRadius);
    return {{"cube_cells_per_sphere", edge * edge * edge}};
  }

 private:
  gpu::GpuFluidLattice<Real>& lattice_;
  std::unique_ptr<gpu::GpuImmersedBoundary<Real>> ib_;
  std::unique_ptr<gpu::GpuPartiallySaturatedCells<Real>> psm_;
};

template <class Real>
nlohmann::json time_option(lattice::Extent e, const spheres::SphereSet& s,
                           const coupling::Scheme& scheme, int steps, int reps) {
  lattice::FluidLattice<Real> host(e, {0.01, 0.25});
  host.set_body_force({1e-6, 0, 0});
  host.enable_force_field();
  gpu::GpuFluidLattice<Real> coupled(e, {0.01, 0.25}), alone(e, {0.01, 0.25});
  alone.upload(host);
  if (!scheme.immersed_boundary()) {
    // partially saturated cells force no field: their lattice steps without one
    lattice::FluidLattice<Real> plain(e, {0.01, 0.25});
    plain.set_body_force({1e-6, 0, 0});
    coupled.upload(plain);
  } else {
    coupled.upload(host);
  }
  CoupledGpuStep<Real> coupling(scheme, coupled);
  for (int k = 0; k < 2; ++k) {  // warm-up: every buffer allocated, both parities
    coupling.step(host, s);
    alone.step();
  }
  coupled.synchronize();
  alone.synchronize();
  std::vector<double> fluid_ms, step_ms, extra_ms, ratios;
  for (int r = 0; r < reps; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < steps; ++k) alone.step();
    alone.synchronize();
    const double fluid = seconds_since(t0) / steps;
    t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < steps; ++k) coupling.step(host, s);
    coupled.synchronize();
    const double full = seconds_since(t0) / steps;
    fluid_ms.push_back(1e3 * fluid);
    step_ms.push_back(1e3 * full);
    // the coupling's cost is what the coupled step adds to the fluid alone: its
    // kernels, its transfers and the host's waits for them
    extra_ms.push_back(1e3 * (full - fluid));
    ratios.push_back(fluid / full);
  }
  if (!std::isfinite(coupled.total_mass()))
    throw std::runtime_error("the benchmark's lattice blew up: its figures are not valid");
  const double cells = static_cast<double>(e.cells());
  nlohmann::json out = {{"option", scheme.describe()},
                        {"precision", sizeof(Real) == 8 ? "double" : "float"},
                        {"size", {e.nx, e.ny, e.nz}},
                        {"spheres", s.size()},
                        {"fluid_MLUPS", cells / median(fluid_ms) / 1e3},
                        {"full_step_MLUPS", cells / median(step_ms) / 1e3},
                        {"full_over_fluid", median(ratios)},
                        {"fluid_ms", median(fluid_ms)},
                        {"full_step_ms", median(step_ms)},
                        {"coupling_ms", median(extra_ms)},
                        {"reps", reps},
                        {"steps", steps}};
  out.update(coupling.work_per_sphere());
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  double scale = 1;
  int reps = 5, steps = 20;
  std::string options = "direct:roma3:1.0:1,direct:roma3:0.7:2,control:roma3:1.0,psm";
  std::string precision = "all", json_file;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--scale" && has_value) {
      scale = std::atof(argv[++i]);
    } else if (arg == "--reps" && has_value) {
      reps = std::atoi(argv[++i]);
    } else if (arg == "--steps" && has_value) {
      steps = std::atoi(argv[++i]);
    } else if (arg == "--options" && has_value) {
      options = argv[++i];
    } else if (arg == "--precision" && has_value) {
      precision = argv[++i];
    } else if (arg == "--json" && has_value) {
      json_file = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: bench_coupling_gpu [--scale S] [--reps R] [--steps K] "
                   "[--options OPTION,...] [--precision float|double|all] [--json FILE]\n");
      return 2;
    }
  }
  if (!(scale >= 1 && scale <= 8) || reps < 1 || steps < 1 ||
      (precision != "float" && precision != "double" && precision != "all")) {
    std::fprintf(stderr,
                 "bench_coupling_gpu: --scale must be in [1, 8], --reps and --steps at least 1, "
                 "--precision float, double or all\n");
    return 2;
  }
  std::vector<coupling::Scheme> schemes;
  for (const std::string& text : bench::split(options, ',')) {
    const auto scheme = bench::parse_option(text);
    if (!scheme) {
      std::fprintf(stderr, "bench_coupling_gpu: --options entry '%s': expected %s\n", text.c_str(),
                   bench::kOptionsSyntax);
      return 2;
    }
    schemes.push_back(*scheme);
  }
  const gpu::GpuQuery q = gpu::query_gpus();
  if (q.devices.empty()) {
    std::printf("no GPU: %s; nothing measured\n", q.why_none.c_str());
    return 77;
  }
  const lattice::Extent e{static_cast<int>(std::lround(288 / scale)),
                          static_cast<int>(std::lround(144 / scale)),
                          static_cast<int>(std::lround(144 / scale))};
  const spheres::SphereSet s = suspension(e, kRadius, 0.2);
  std::printf("GPU: %s; box %d x %d x %d, %zu spheres (phi 0.2, a = 6), %d reps of %d steps\n",
              q.devices[0].name.c_str(), e.nx, e.ny, e.nz, s.size(), reps, steps);
  std::printf("%-64s %-6s %12s %12s %8s %8s\n", "option", "prec", "fluid MLUPS", "full MLUPS",
              "ratio", "+coupling ms");
  nlohmann::json all = nlohmann::json::array();
  // rewritten after each option: a run stopped at its time limit (the device
  // check's) keeps every figure measured so far ("complete": false)
  const auto save = [&](bool complete) {
    if (json_file.empty()) return;
    const std::string tmp = json_file + ".tmp";
    std::ofstream(tmp) << nlohmann::json{{"gpu", q.devices[0].name},
                                         {"complete", complete},
                                         {"results", all}}
                              .dump(2)
                       << "\n";
    std::rename(tmp.c_str(), json_file.c_str());
  };
  for (const auto& scheme : schemes)
    for (const std::string p : {"float", "double"}) {
      if (precision != "all" && precision != p) continue;
      const nlohmann::json r = p == "float" ? time_option<float>(e, s, scheme, steps, reps)
                                            : time_option<double>(e, s, scheme, steps, reps);
      std::printf("%-64s %-6s %12.0f %12.0f %7.0f%% %8.3f\n", scheme.describe().c_str(), p.c_str(),
                  r["fluid_MLUPS"].get<double>(), r["full_step_MLUPS"].get<double>(),
                  100 * r["full_over_fluid"].get<double>(), r["coupling_ms"].get<double>());
      all.push_back(r);
      save(false);
    }
  std::printf("target: full step >= 50 %% of the fluid alone (issue 39)\n");
  save(true);
  return 0;
}
