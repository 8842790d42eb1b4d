// flocsim post on the paper's grid: 120 completed runs (phi 0.12-0.32, Re_inf
// 6-72, du/U_inf 0-0.03) written through db/'s API, each with a series.h5 of
// 600 samples and 48 slabs (300 a/U_inf sampled every 0.5). Times, as medians
// of --reps repetitions:
//  - reading the runs (load_runs): the floor every table and figure pays;
//  - `post tables` (three formats, both tables);
//  - `post figures` (every figure, PNG + PDF, gnuplot processes included).
// Limits: tables within 5 s and figures within 60 s on 2 cores, the "seconds"
// a user waits after a sweep; each figure is also given as a multiple of the
// floor measured in the same run (tables), or per figure (figures: one gnuplot
// process each, about 0.1-0.2 s, dominates).
// Usage: bench_post [--reps R] [--keep DIR]
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "db/results_db.hpp"
#include "engine/output/hdf5_file.hpp"
#include "orchestrator/sweep.hpp"
#include "postprocess/figures.hpp"
#include "postprocess/tables.hpp"

namespace fs = std::filesystem;
using namespace flocsim;
using json = nlohmann::json;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void write_series(const fs::path& dir, double du, double phi, unsigned seed) {
  fs::create_directories(dir);
  output::Hdf5File f(dir / "series.h5", output::Hdf5File::Mode::create);
  const int n = 600, slabs = 48;
  std::vector<double> t, stage, u, c, phi_x;
  for (int k = 0; k < n; ++k) {
    t.push_back(0.5 * k);
    stage.push_back(k < 200 ? 1 : 2);
    u.push_back(0.3 + du * std::tanh(k / 100.0) + 0.01 * std::sin(0.1 * k + seed));
    c.push_back(0.5 + 30 * du * std::tanh(k / 100.0));
    for (int s = 0; s < slabs; ++s) phi_x.push_back(phi + 0.02 * std::sin(0.05 * k + 0.4 * s));
  }
  f.write("/time", {t.size()}, t.data());
  f.write("/stage", {t.size()}, stage.data());
  f.write("/U_over_Uinf", {t.size()}, u.data());
  f.write("/C_sph", {t.size()}, c.data());
  f.write("/phi_x", {static_cast<hsize_t>(n), static_cast<hsize_t>(slabs)}, phi_x.data());
  f.create_group("/distributions");
  std::vector<double> p(200), r, g, th, h;
  for (std::size_t k = 1; k < p.size(); ++k)
    p[k] = std::exp(-static_cast<double>(k) / (5 + 300 * du));
  for (int k = 0; k < 80; ++k) {
    r.push_back(2 + 0.05 * k);
    g.push_back(1 + std::exp(-k / 10.0));
  }
  for (int k = 0; k < 60; ++k) {
    th.push_back(M_PI * (k + 0.5) / 60);
    h.push_back(1 + 0.1 * std::cos(2 * th.back()));
  }
  f.write("/distributions/size_distribution", {p.size()}, p.data());
  f.write("/distributions/r_over_a", {r.size()}, r.data());
  f.write("/distributions/g", {g.size()}, g.data());
  f.write("/distributions/theta", {th.size()}, th.data());
  f.write("/distributions/h", {h.size()}, h.data());
  f.close();
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 3;
  fs::path keep;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::string(argv[i]) == "--reps")
      reps = std::max(1, std::atoi(argv[++i]));
    else if (std::string(argv[i]) == "--keep")
      keep = argv[++i];
  }
  const fs::path dir =
      keep.empty() ? fs::temp_directory_path() / ("flocsim_bench_post_" + std::to_string(getpid()))
                   : keep;
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string path = (dir / "paper.db").string();
  {
    db::ResultsDb db(path, db::ResultsDb::Mode::kCreate);
    const auto sweep = db.upsert_sweep("paper", "{}", "[]", 3);
    std::vector<db::ResultsDb::NewRun> news;
    std::vector<json> cases;
    for (double phi : {0.12, 0.20, 0.25, 0.32})
      for (double re : {6, 12, 24, 48, 72})
        for (double du : {0.0, 0.005, 0.01, 0.02, 0.025, 0.03}) {
          json c = orchestrator::canonical(json{{"scene", "suspension"},
                                                {"fidelity", "paper"},
                                                {"phi", phi},
                                                {"Re_inf", re},
                                                {"du_over_Uinf", du}});
          const std::string id = orchestrator::case_id(c);
          news.push_back({id, c.dump(), (dir / id.substr(0, 16)).string(), "{}"});
          cases.push_back(c);
        }
    db.add_runs(sweep, news);
    db::AttemptStart start;
    start.host = "bench";
    start.owner_pid = getpid();
    for (std::size_t k = 0; k < news.size(); ++k) {
      db::ClaimRequest req;
      req.sweep_id = sweep;
      req.states = {db::RunState::kPending};
      req.run_id = news[k].id;
      const auto claim = db.claim_run(req, start);
      const double phi = cases[k]["phi"], du = cases[k]["du_over_Uinf"];
      const double re = cases[k]["Re_inf"];
      db::ResultRecord rec;
      rec.run_id = news[k].id;
      rec.flocsim_version = "bench";
      rec.completed_at = "now";
      rec.wall_s = 3600;
      const double F = 4 + 10 * phi + 0.05 * re - 20 * du, n_a = 2 + 300 * du;
      rec.result_json = json{{"observables", {{"window", {{"start", 150}, {"end", 450}}}}},
                             {"not_stationary", json::array()},
                             {"derived", {{"sphere_count", 1320}}}}
                            .dump();
      rec.observables = {{"F", F, 0.02 * F},          {"n_a_mean", n_a, 0.05 * n_a},
                         {"Re", 0.3 * re, 0.01 * re}, {"Re_T", 0.05 * re, 0.002 * re},
                         {"U_over_Uinf", 0.3, 0.01},  {"C_sph", 0.5 + 30 * du, 0.05}};
      db.record_result(claim->attempt_id, rec);
      write_series(news[k].run_dir, du, phi, static_cast<unsigned>(k));
    }
  }
  std::vector<double> load_s, tables_s, figures_s;
  std::size_t figures = 0;
  for (int r = 0; r < reps; ++r) {
    db::ResultsDb db(path, db::ResultsDb::Mode::kReadOnly);
    auto t0 = std::chrono::steady_clock::now();
    const auto runs = postprocess::load_runs(db, std::nullopt, {});
    load_s.push_back(seconds_since(t0));
    t0 = std::chrono::steady_clock::now();
    for (const std::string format : {"csv", "md", "tex"}) {
      std::ostringstream a, n;
      postprocess::write_aggregation(postprocess::aggregation_table(runs), format, a);
      postprocess::write_non_aggregating(postprocess::non_aggregating_table(runs), format, n);
    }
    tables_s.push_back(load_s.back() + seconds_since(t0));
    t0 = std::chrono::steady_clock::now();
    figures = postprocess::write_figures(runs, dir / "figures").figures.size();
    figures_s.push_back(load_s.back() + seconds_since(t0));
  }
  const double load = median(load_s), tables = median(tables_s), figs = median(figures_s);
  std::printf("bench_post: 120 runs with series.h5 (600 samples, 48 slabs), %d repetitions\n",
              reps);
  std::printf("  reading the runs (floor)   %8.3f s\n", load);
  std::printf("  post tables (3 formats)    %8.3f s  = %5.1f x floor, limit 5 s: %s\n", tables,
              tables / load, tables <= 5 ? "within" : "OVER");
  std::printf("  post figures (%zu, PNG+PDF) %8.3f s  = %.3f s per figure, limit 60 s: %s\n",
              figures, figs, figs / static_cast<double>(std::max<std::size_t>(figures, 1)),
              figs <= 60 ? "within" : "OVER");
  if (keep.empty()) fs::remove_all(dir);
  return tables <= 5 && figs <= 60 ? 0 : 1;
}
