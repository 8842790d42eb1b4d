// `flocsim sweep plan`: every point of a grid read by the run's own parser (a
// refused point carries the run's message), sized from the run's own protocol
// (steps worked by hand from the fidelity preset), and timed and weighed by
// building the case's real coupled step.
#include "orchestrator/plan.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "engine/case/case_file.hpp"
#include "engine/immersed_boundary/sphere_markers.hpp"
#include "engine/input/input_reader.hpp"
#include "orchestrator/sweep.hpp"

namespace orc = flocsim::orchestrator;
using ::testing::HasSubstr;

namespace {

orc::SweepSpec paper_grid(const std::string& fidelity) {
  orc::SweepSpec spec =
      orc::read_sweep_file(std::string(FLOCSIM_SOURCE_DIR) + "/sweeps/paper.json");
  spec.base["fidelity"] = fidelity;
  return spec;
}

TEST(SweepPlan, ThePapersGridIsSizedFromItsProtocol) {
  orc::PlanOptions o;
  o.measure_steps = 0;  // sizes only
  const orc::SweepPlan plan = orc::plan_sweep(paper_grid("paper"), o);
  ASSERT_EQ(plan.runs.size(), 120u);
  // the 24 runs at Re_inf 72: the paper's method below its floor (nu 0.0133
  // would need U_inf 0.08 at a = 6; tests/run/paper_grid_test.cpp)
  EXPECT_EQ(plan.refused, 24);
  EXPECT_EQ(plan.to_run, 96);
  // By hand, the paper preset (docs/user-guide.md): a = 6 dx, L = 48a, L/W = 2:
  // 288 x 144 x 144 = 5 971 968 cells. At phi 0.2, Re_inf 12, U_inf = 0.02 (the
  // preset's; nu = 2 a U_inf / Re_inf = 0.02 is above the floor): a/U_inf = 300
  // steps, samples every 150. Stage 1 of 30-150 a/U_inf = 9 000-45 000 steps,
  // with the well 100 a/U_inf to settle (30 000) and 300 of statistics (90 000):
  // 129 000-165 000 steps; without the well no stage 2: 99 000-135 000.
  int checked = 0;
  for (const orc::PlannedRun& r : plan.runs) {
    const auto& c = r.point.case_json;
    if (c["phi"] != 0.2 || c["Re_inf"] != 12) continue;
    EXPECT_EQ(r.size.cells, 5971968);
    EXPECT_EQ(r.size.box.nx, 288);
    const bool well = c["du_over_Uinf"].get<double>() > 0;
    EXPECT_EQ(r.size.steps_min, well ? 129000 : 99000) << c.dump();
    EXPECT_EQ(r.size.steps_max, well ? 165000 : 135000) << c.dump();
    ++checked;
  }
  EXPECT_EQ(checked, 6);
  // the totals are the sum over the runs
  double low = 0, high = 0;
  for (const orc::PlannedRun& r : plan.runs) {
    low += static_cast<double>(r.size.cells) * r.size.steps_min;
    high += static_cast<double>(r.size.cells) * r.size.steps_max;
  }
  EXPECT_DOUBLE_EQ(plan.lattice_updates_min, low);
  EXPECT_DOUBLE_EQ(plan.lattice_updates_max, high);
  // without a rate there is no time estimate, and the plan says why
  EXPECT_FALSE(plan.wall_min_s);
  std::ostringstream text;
  orc::write_plan(plan, text, true);
  EXPECT_THAT(text.str(), HasSubstr("plan of sweep paper: 120 points, 96 to run, 24 refused"));
  EXPECT_THAT(text.str(), HasSubstr("--measure-steps"));
}

TEST(SweepPlan, RefusesExactlyWhatTheRunRefusesWithItsMessage) {
  // The draft preset refuses the 24 points at Re_inf 72 (a = 4 caps Re_inf at
  // 56) and the 12 at Re_inf 48 with phi > 0.2 (the paper's two-sweep method
  // needs nu >= 0.0133 at a = 4, beyond the Mach limit there:
  // tests/run/paper_grid_test.cpp); the plan must say so for each, with the
  // message `flocsim run` gives, which names what would work.
  orc::PlanOptions o;
  o.measure_steps = 0;
  const orc::SweepPlan plan = orc::plan_sweep(paper_grid("draft"), o);
  ASSERT_EQ(plan.runs.size(), 120u);
  EXPECT_EQ(plan.refused, 36);
  for (const orc::PlannedRun& r : plan.runs) {
    std::string run_says;
    try {
      flocsim::cases::parse_case(r.point.case_json);
    } catch (const flocsim::input::InputError& e) {
      run_says = e.what();
    }
    EXPECT_EQ(r.refused, run_says) << r.point.point.dump();
    const double re = r.point.case_json["Re_inf"], phi = r.point.case_json["phi"];
    EXPECT_EQ(!r.refused.empty(), re == 72 || (re == 48 && phi > 0.2)) << r.point.point.dump();
    if (!r.refused.empty()) {
      // at Re_inf 72 the paper's method (phi > 0.2) needs a = 8 for its floor
      EXPECT_THAT(r.refused, HasSubstr(re != 72    ? "raise numerics.a_over_dx to 6"
                                       : phi > 0.2 ? "raise numerics.a_over_dx to at least 8"
                                                   : "raise numerics.a_over_dx to at least 6"));
    }
  }
  std::ostringstream screen;
  orc::write_plan(plan, screen, false);
  EXPECT_THAT(screen.str(), HasSubstr("refused (36), as `flocsim run` refuses them"));
  EXPECT_THAT(screen.str(), HasSubstr("raise numerics.a_over_dx to at least 6"));
}

TEST(SweepPlan, TimesTheRealStepAndWeighsTheLatticesStorage) {
  // The demo sweep: one configuration (64 x 32 x 32 float lattice, 49 spheres,
  // one-sweep IB) shared by its four points.
  orc::PlanOptions o;
  o.measure_steps = 5;
  o.measure_seconds = 0.2;
  const orc::SweepPlan plan = orc::plan_sweep(
      orc::read_sweep_file(std::string(FLOCSIM_SOURCE_DIR) + "/sweeps/demo.json"), o);
  ASSERT_EQ(plan.costs.size(), 1u);
  const orc::StepCost& c = plan.costs.front();
  EXPECT_EQ(c.runs, 4);
  ASSERT_TRUE(c.measured);
  EXPECT_GE(c.measured->steps, 5);
  EXPECT_GT(c.measured->step_s, 0);
  EXPECT_EQ(c.measured->threads, 1);  // the demo's protocol.threads
  // The lattice's storage by hand: 19 populations, the 3-component force field
  // and the immersed boundary's (rho, u*) rows: 26 floats per cell; the
  // spheres and markers add little. The state allocated must hold at least that
  // and not twice it.
  const double storage = 26.0 * 4 * 64 * 32 * 32;
  EXPECT_GE(c.measured->memory_bytes, storage);
  EXPECT_LE(c.measured->memory_bytes, 2 * storage);
  // Steps by hand: a/U_inf = 4 / 0.03 = 133.3 steps, samples every 67; stage 1
  // of 8-15 a/U_inf ends on the sample at or after 1067-2000 steps: 1072-2010;
  // with the well 8 a/U_inf to settle (1072) and 16 of statistics (2144).
  for (const orc::PlannedRun& r : plan.runs) {
    const bool well = r.point.case_json["du_over_Uinf"].get<double>() > 0;
    EXPECT_EQ(r.size.steps_min, well ? 1072 + 1072 + 2144 : 1072 + 2144);
    EXPECT_EQ(r.size.steps_max, well ? 2010 + 1072 + 2144 : 2010 + 2144);
  }
  // a run: its setup and its steps at the measured rate
  for (const orc::PlannedRun& r : plan.runs) {
    ASSERT_TRUE(r.wall_min_s);
    EXPECT_NEAR(*r.wall_min_s, c.measured->setup_s + r.size.steps_min * c.measured->step_s,
                1e-9 * *r.wall_min_s);
  }
  // one job: the sweep is the runs one after another
  double sum = 0;
  for (const orc::PlannedRun& r : plan.runs) sum += *r.wall_max_s;
  ASSERT_TRUE(plan.wall_max_s);
  EXPECT_NEAR(*plan.wall_max_s, sum, 1e-9 * sum);
}

// The plan of `spec` with the GPU figures `bench` (as bench_coupling_gpu
// --json writes them) read from a file in `dir`; nothing timed here.
orc::SweepPlan plan_on_gpu(const orc::SweepSpec& spec, const nlohmann::json& bench,
                           const std::string& dir, orc::GpuRates& rates) {
  std::filesystem::create_directories(dir);
  const std::string file = dir + "/bench-coupling-gpu.json";
  std::ofstream(file) << bench.dump(2);
  rates = orc::read_gpu_rates({file});
  orc::PlanOptions o;
  o.measure_steps = 0;
  o.gpu = &rates;
  return orc::plan_sweep(spec, o);
}

// --gpu-rate: a GPU benchmark's figures (as bench_coupling_gpu and
// bench_fluid_gpu write them) give each configuration's seconds per step by
// the model of orchestrator/gpu_rates.hpp, worked here by hand: the paper's
// case at the paper preset (288 x 144 x 144, N = 1320) on a GPU whose fluid
// runs at 8000 MLUPS beside the coupling and whose immersed boundary adds
// 1.5 ms to the step for 1320 x 900 markers.
TEST(SweepPlan, AGpuBenchmarkGivesTheRateOfWhatTheGpuRuns) {
  const std::string dir = ::testing::TempDir() + "/plan-gpu-rate";
  const orc::SweepSpec spec = paper_grid("paper");
  const auto first = flocsim::cases::parse_case(orc::expand(spec).front().case_json);
  const flocsim::coupling::Scheme& scheme = first.spheres.numerics.coupling;
  const bool single = first.spheres.numerics.single_precision;
  nlohmann::json bench = {{"gpu", "NVIDIA H100 (test figures)"},
                          {"results",
                           {{{"option", scheme.describe()},
                             {"precision", single ? "float" : "double"},
                             {"fluid_MLUPS", 8000.0},
                             {"coupling_ms", 1.5},
                             {"spheres", 1320},
                             {"markers_per_sphere", 900}}}}};
  orc::GpuRates rates;
  const orc::SweepPlan plan = plan_on_gpu(spec, bench, dir, rates);
  double gpu_hours = 0;
  int checked = 0;
  for (const orc::PlannedRun& r : plan.runs) {
    if (!r.refused.empty()) continue;
    const auto parsed = flocsim::cases::parse_case(r.point.case_json);
    const double markers =
        r.size.spheres * flocsim::immersed_boundary::marker_count(
                             parsed.spheres.numerics.input_radius, scheme.marker_spacing);
    const double step = r.size.cells / 8000e6 + 1.5e-3 * markers / (1320.0 * 900.0);
    ASSERT_TRUE(r.wall_min_s) << r.point.case_json.dump();
    EXPECT_NEAR(*r.wall_min_s, step * r.size.steps_min, 1e-9 * *r.wall_min_s);
    EXPECT_NEAR(*r.wall_max_s, step * r.size.steps_max, 1e-9 * *r.wall_max_s);
    gpu_hours += step * r.size.steps_max / 3600;
    ++checked;
  }
  EXPECT_EQ(checked, 96);  // the 24 at Re_inf 72 are refused at the paper preset
  EXPECT_NEAR(plan.gpu_hours_max, gpu_hours, 1e-9 * gpu_hours);
  std::ostringstream text;
  orc::write_plan(plan, text, false);
  EXPECT_THAT(text.str(), HasSubstr("on the GPU NVIDIA H100 (test figures)"));
  EXPECT_THAT(text.str(), HasSubstr("GPU-hours"));

  // A figure of another precision is no figure for this grid: the plan says
  // why and falls back to what it has here (no measurement: no rate).
  bench["results"][0]["precision"] = single ? "double" : "float";
  orc::GpuRates other;
  const orc::SweepPlan without = plan_on_gpu(spec, bench, dir, other);
  EXPECT_FALSE(without.wall_min_s);
  std::ostringstream why;
  orc::write_plan(without, why, false);
  EXPECT_THAT(why.str(),
              HasSubstr("not on the GPU: no coupled-step benchmark of " + scheme.describe()));
}

// Partially saturated cells have no markers: their cost grows with the cells
// each sphere covers. By hand: the demo-sized case below, a = 4 dx (a_g = a
// for this coupling), covers a cube of edge ceil(2 (4 + sqrt(3)/2)) + 3 = 13
// cells per sphere, 2197; a benchmark that added 2 ms for 1320 spheres of
// a = 6 (edge ceil(2 (6 + 0.866)) + 3 = 17, 4913 cells) gives this case
// cells / (fluid MLUPS) + 2 ms x (N x 2197) / (1320 x 4913). (The calibrated
// a_g at a = 4 is 4.017; any a_g in (3.634, 4.134] gives edge 13.)
TEST(SweepPlan, AGpuBenchmarkOfPartiallySaturatedCellsScalesWithTheCoveredCells) {
  const std::string dir = ::testing::TempDir() + "/plan-gpu-rate-psm";
  orc::SweepSpec spec = paper_grid("draft");
  spec.base["numerics"] = {{"coupling", "partially-saturated"}};
  spec.axes = {orc::Axis{"phi", {nlohmann::json(0.12)}}, orc::Axis{"Re_inf", {nlohmann::json(12)}},
               orc::Axis{"du_over_Uinf", {nlohmann::json(0)}}};
  const auto first = flocsim::cases::parse_case(orc::expand(spec).front().case_json);
  const flocsim::coupling::Scheme& scheme = first.spheres.numerics.coupling;
  ASSERT_FALSE(scheme.immersed_boundary());
  ASSERT_GT(first.spheres.numerics.input_radius, 3.634);
  ASSERT_LE(first.spheres.numerics.input_radius, 4.134);
  const bool single = first.spheres.numerics.single_precision;
  const nlohmann::json bench = {{"gpu", "NVIDIA H200 (test figures)"},
                                {"results",
                                 {{{"option", scheme.describe()},
                                   {"precision", single ? "float" : "double"},
                                   {"fluid_MLUPS", 9000.0},
                                   {"coupling_ms", 2.0},
                                   {"spheres", 1320},
                                   {"cube_cells_per_sphere", 4913}}}}};
  orc::GpuRates rates;
  const orc::SweepPlan plan = plan_on_gpu(spec, bench, dir, rates);
  ASSERT_EQ(plan.runs.size(), 1u);
  const orc::PlannedRun& r = plan.runs.front();
  ASSERT_TRUE(r.refused.empty()) << r.refused;
  const double step = r.size.cells / 9000e6 + 2e-3 * r.size.spheres * 2197.0 / (1320.0 * 4913.0);
  ASSERT_TRUE(r.wall_min_s);
  EXPECT_NEAR(*r.wall_min_s, step * r.size.steps_min, 1e-9 * *r.wall_min_s);
}

TEST(SweepPlan, RefusesAGpuRateFileThatIsNotABenchmarksOutput) {
  const std::string dir = ::testing::TempDir() + "/plan-gpu-rate-bad";
  std::filesystem::create_directories(dir);
  auto refusal = [&](const std::string& text) {
    const std::string file = dir + "/rate.json";
    std::ofstream(file) << text;
    try {
      orc::read_gpu_rates({file});
    } catch (const flocsim::input::InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_THAT(refusal(R"({"results": []})"), HasSubstr("not a GPU benchmark's output"));
  EXPECT_THAT(refusal(R"({"gpu": "G", "results": [{"precision": "float", "MLUPS": -3}]})"),
              HasSubstr("results[0].MLUPS = -3: must be a positive finite number"));
  EXPECT_THAT(refusal(R"({"gpu": "G", "results": [{"precision": "half", "MLUPS": 3}]})"),
              HasSubstr("results[0].precision: must be \"float\" or \"double\""));
  EXPECT_THAT(refusal(R"({"gpu": "G", "results": [{"precision": "float", "option": "x",
                         "fluid_MLUPS": 1, "coupling_ms": 1, "spheres": 0,
                         "markers_per_sphere": 9}]})"),
              HasSubstr("results[0].spheres = 0: must be a positive finite number"));
  EXPECT_THAT(refusal(R"({"gpu": "G", "results": [{"precision": "float"}]})"),
              HasSubstr("neither a fluid result"));
}

TEST(SweepPlan, ReadsSlurmTimeLimitsInEveryForm) {
  EXPECT_EQ(orc::slurm_time_limit_s("90"), 5400);            // minutes
  EXPECT_EQ(orc::slurm_time_limit_s("10:30"), 630);          // minutes:seconds
  EXPECT_EQ(orc::slurm_time_limit_s("01:00:00"), 3600);      // hours:minutes:seconds
  EXPECT_EQ(orc::slurm_time_limit_s("2-00:00:00"), 172800);  // days-hours:minutes:seconds
  EXPECT_EQ(orc::slurm_time_limit_s("1-12"), 129600);        // days-hours
  EXPECT_EQ(orc::slurm_time_limit_s("1-01:30"), 91800);      // days-hours:minutes
  EXPECT_FALSE(orc::slurm_time_limit_s("soon"));
  EXPECT_FALSE(orc::slurm_time_limit_s("1:2:3:4"));
}

}  // namespace
