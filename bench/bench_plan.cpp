// `flocsim sweep plan` against the clock: the plan's wall-time estimate for the
// demo sweep (sweeps/demo.json at --jobs 2), then the demo sweep itself run by
// `flocsim sweep launch` into a fresh database, and the sweep's measured wall
// time (first worker start to last worker end, from the database's attempts).
// Prints the estimate, the measurement and their ratio; the estimate must lie
// within a factor 1.5 of the measurement (exit 1 otherwise). Also checks that
// the plan's lattice-update range holds the runs' own cost figures (steps x
// cells from each result.json).
// Usage: bench_plan [--jobs N] [--keep DIR]
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "db/results_db.hpp"
#include "orchestrator/plan.hpp"
#include "orchestrator/sweep.hpp"

namespace fs = std::filesystem;
using namespace flocsim;
using json = nlohmann::json;

int main(int argc, char** argv) {
  int jobs = 2;
  std::string keep;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--jobs" && i + 1 < argc)
      jobs = std::atoi(argv[++i]);
    else if (a == "--keep" && i + 1 < argc)
      keep = argv[++i];
    else {
      std::fprintf(stderr, "usage: bench_plan [--jobs N] [--keep DIR]\n");
      return 2;
    }
  }
  const std::string sweep_file = std::string(FLOCSIM_SOURCE_DIR) + "/sweeps/demo.json";
  const fs::path dir =
      keep.empty() ? fs::temp_directory_path() / ("flocsim_bench_plan_" + std::to_string(getpid()))
                   : fs::path(keep);
  fs::remove_all(dir);
  fs::create_directories(dir);

  orchestrator::PlanOptions options;
  options.jobs = jobs;
  const orchestrator::SweepPlan plan =
      orchestrator::plan_sweep(orchestrator::read_sweep_file(sweep_file), options);
  if (!plan.wall_min_s) {
    std::fprintf(stderr, "bench_plan: the plan has no wall-time estimate\n");
    return 1;
  }

  const std::string db_path = (dir / "demo.sqlite").string();
  const std::string command = std::string(FLOCSIM_EXE) + " sweep launch " + sweep_file + " --db " +
                              db_path + " --jobs " + std::to_string(jobs) + " > " +
                              (dir / "launch.log").string() + " 2>&1";
  if (std::system(command.c_str()) != 0) {
    std::fprintf(stderr, "bench_plan: the demo sweep failed; see %s\n",
                 (dir / "launch.log").string().c_str());
    return 1;
  }
  db::ResultsDb db(db_path, db::ResultsDb::Mode::kReadOnly);
  double first_start = 1e300, last_end = 0, updates = 0;
  for (const db::ResultsDb::ResultRow& r : db.result_rows()) {
    for (const db::AttemptRecord& a : db.attempts(r.run.id)) {
      first_start = std::min(first_start, a.started_at);
      last_end = std::max(last_end, a.ended_at.value_or(0));
    }
    const json result = json::parse(r.result_json);
    const json box = result.at("derived").at("box_cells");
    updates += result.at("cost").at("steps").get<double>() * box[0].get<double>() *
               box[1].get<double>() * box[2].get<double>();
  }
  const double measured = last_end - first_start;
  const double estimate = 0.5 * (*plan.wall_min_s + *plan.wall_max_s);
  const double ratio = estimate / measured;
  const bool updates_inside =
      updates >= plan.lattice_updates_min && updates <= plan.lattice_updates_max;
  const bool within = ratio >= 1 / 1.5 && ratio <= 1.5;
  std::printf("demo sweep at --jobs %d on %d cores (%s)\n", jobs, plan.cores,
              plan.costs.front().basis().c_str());
  std::printf("  plan: wall time %.1f-%.1f s (middle %.1f s); lattice updates %.4g-%.4g\n",
              *plan.wall_min_s, *plan.wall_max_s, estimate, plan.lattice_updates_min,
              plan.lattice_updates_max);
  std::printf(
      "  run:  wall time %.1f s (first worker start to last worker end); lattice "
      "updates %.4g (steps x cells of each result.json)\n",
      measured, updates);
  std::printf("  estimate / measured = %.2f (limit: within a factor 1.5): %s\n", ratio,
              within ? "ok" : "OUTSIDE");
  std::printf("  runs' lattice updates inside the plan's range: %s\n",
              updates_inside ? "yes" : "NO");
  if (keep.empty()) fs::remove_all(dir);
  return within && updates_inside ? 0 : 1;
}
