// flocsim post: the aggregation table against a hand calculation on a database
// written through db/'s API, the pairing rule (never across numerics, missing
// baselines listed with their reason), rounding to the error, the reference
// correlations against hand-computed values, and figures that gnuplot really
// drew.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "db/results_db.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/observables/reference_correlations.hpp"
#include "engine/output/hdf5_file.hpp"
#include "orchestrator/report.hpp"
#include "orchestrator/sweep.hpp"
#include "postprocess/figures.hpp"
#include "postprocess/paper_values.hpp"
#include "postprocess/report.hpp"
#include "postprocess/tables.hpp"

namespace flocsim::postprocess {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::Not;

struct HandRun {
  std::string id;
  json case_json;
  std::string state;  // completed | failed | running | pending
  double F = 0, F_err = 0, n_a = 0, n_a_err = 0;
  std::string lubrication_model;  // as the run resolved it (result.json's case); "" for none
  json immersed_boundary;         // as the run resolved it; null: not written (older versions)
};

json suspension(double du, double re_inf = 12, double a = 4) {
  return orchestrator::canonical(json{{"scene", "suspension"},
                                      {"fidelity", "draft"},
                                      {"phi", 0.2},
                                      {"Re_inf", re_inf},
                                      {"du_over_Uinf", du},
                                      {"numerics", {{"a_over_dx", a}}}});
}

class Post : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("flocsim_post_" + std::to_string(getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }

  // Writes the runs through db/'s API as the orchestrator would.
  std::string write_db(const std::vector<HandRun>& runs, bool with_series = false,
                       const std::string& sweep_name = "hand") {
    const std::string path = (dir_ / "results.db").string();
    db::ResultsDb db(path, db::ResultsDb::Mode::kCreate);
    const auto sweep = db.upsert_sweep(sweep_name, "{}", "[\"du_over_Uinf\"]", 2);
    std::vector<db::ResultsDb::NewRun> news;
    for (const HandRun& r : runs)
      news.push_back({r.id, orchestrator::canonical_text(r.case_json), (dir_ / r.id).string(),
                      json{{"du_over_Uinf", r.case_json.value("du_over_Uinf", 0.0)}}.dump()});
    db.add_runs(sweep, news);
    db::AttemptStart start;
    start.host = "test";
    start.owner_pid = getpid();
    for (const HandRun& r : runs) {
      const db::RunState state = db::run_state_from_string(r.state);
      if (state == db::RunState::kPending) continue;
      db::ClaimRequest req;
      req.sweep_id = sweep;
      req.states = {db::RunState::kPending};
      req.run_id = r.id;
      const auto claim = db.claim_run(req, start);
      if (state == db::RunState::kFailed)
        db.end_attempt(claim->attempt_id, db::RunState::kFailed, 1, std::nullopt, "blew up");
      if (state != db::RunState::kCompleted) continue;
      db::ResultRecord rec;
      rec.run_id = r.id;
      rec.flocsim_version = "test";
      rec.completed_at = "now";
      rec.wall_s = 10;
      json obs = {{"F", {{"mean", r.F}, {"error", r.F_err}, {"error_reliable", true}}},
                  {"n_a_mean", {{"mean", r.n_a}, {"error", r.n_a_err}, {"error_reliable", true}}},
                  {"window", {{"start", 100}, {"end", 400}}}};
      json result = {{"observables", obs},
                     {"not_stationary", json::array()},
                     {"derived", {{"sphere_count", 49}}}};
      if (!r.lubrication_model.empty()) {
        result["case"] = r.case_json;
        result["case"]["lubrication_model"] = r.lubrication_model;
        if (!r.immersed_boundary.is_null())
          result["case"]["numerics"]["immersed_boundary"] = r.immersed_boundary;
      }
      rec.result_json = result.dump();
      rec.observables = {{"F", r.F, r.F_err}, {"n_a_mean", r.n_a, r.n_a_err}, {"Re", 4.0, 0.1},
                         {"Re_T", 1.0, 0.05}, {"U_over_Uinf", 0.3, 0.01},     {"C_sph", 1.0, 0.1}};
      db.record_result(claim->attempt_id, rec);
      if (with_series) write_series(dir_ / r.id, r.case_json.value("du_over_Uinf", 0.0));
    }
    return path;
  }

  // A small series.h5 of the layout the solver writes.
  static void write_series(const fs::path& dir, double du) {
    fs::create_directories(dir);
    output::Hdf5File f(dir / "series.h5", output::Hdf5File::Mode::create);
    std::vector<double> t, stage, u, c, phi_x;
    for (int k = 0; k < 50; ++k) {
      t.push_back(k);
      stage.push_back(k < 20 ? 1 : 2);
      u.push_back(0.3 + du * k / 50);
      c.push_back(0.5 + 10 * du * k / 50);
      for (int s = 0; s < 8; ++s) phi_x.push_back(0.2 + 0.01 * std::sin(0.3 * k + s));
    }
    f.write("/time", {t.size()}, t.data());
    f.write("/stage", {t.size()}, stage.data());
    f.write("/U_over_Uinf", {t.size()}, u.data());
    f.write("/C_sph", {t.size()}, c.data());
    f.write("/phi_x", {50, 8}, phi_x.data());
    f.create_group("/distributions");
    std::vector<double> p = {0, 0.5, 0.3, 0.1, 0.1}, r = {2, 2.5, 3}, g = {3, 1.2, 1},
                        th = {0.5, 1.5}, h = {1.1, 0.9};
    f.write("/distributions/size_distribution", {p.size()}, p.data());
    f.write("/distributions/r_over_a", {r.size()}, r.data());
    f.write("/distributions/g", {g.size()}, g.data());
    f.write("/distributions/theta", {th.size()}, th.data());
    f.write("/distributions/h", {h.size()}, h.data());
    f.close();
  }

  fs::path dir_;
};

TEST_F(Post, AggregationTableEqualsAHandCalculation) {
  // Baseline F0 = 4.0 +- 0.12, <n_a>0 = 2.0 +- 0.1; du = 0.02: F = 3.0 +- 0.09,
  // <n_a> = 8.0 +- 0.4. By hand: F/F0 = 0.75 with 0.75 sqrt(0.03^2 + 0.03^2)
  // = 0.0318198; <n_a>/<n_a>0 = 4 with 4 sqrt(0.05^2 + 0.05^2) = 0.2828427.
  const std::string db_path =
      write_db({{"base", suspension(0), "completed", 4.0, 0.12, 2.0, 0.1},
                {"agg", suspension(0.02), "completed", 3.0, 0.09, 8.0, 0.4}});
  db::ResultsDb db(db_path, db::ResultsDb::Mode::kReadOnly);
  const auto runs = load_runs(db, std::nullopt, {});
  const auto rows = aggregation_table(runs);
  ASSERT_EQ(rows.size(), 1u);
  ASSERT_NE(rows[0].baseline, nullptr) << rows[0].reason;
  EXPECT_EQ(rows[0].baseline->id, "base");
  EXPECT_NEAR(rows[0].F_over_F0->mean, 0.75, 1e-14);
  EXPECT_NEAR(*rows[0].F_over_F0->error, 0.0318198052, 1e-9);
  EXPECT_NEAR(rows[0].n_over_n0->mean, 4.0, 1e-14);
  EXPECT_NEAR(*rows[0].n_over_n0->error, 0.2828427125, 1e-9);
  // phi 0.2, Re_inf 12, du 0.02 is the paper's Fig. 9 case (<n_a> = 11.9, no
  // error given): 8.0 / 11.9 = 0.6722689 with flocsim's 0.4 / 11.9 = 0.0336134.
  ASSERT_TRUE(rows[0].n_a_paper.has_value());
  EXPECT_EQ(*rows[0].n_a_paper, 11.9);
  EXPECT_NEAR(rows[0].n_over_paper->mean, 0.6722689076, 1e-9);
  EXPECT_NEAR(*rows[0].n_over_paper->error, 0.0336134454, 1e-9);
  // The paper's text puts its <n_a>/<n_a>0 at du 0.02 between 11.9 / 4.88 =
  // 2.44 and 7.6 (paper_values.hpp; worked in PaperValues below).
  ASSERT_TRUE(rows[0].n_over_n0_paper.has_value());
  EXPECT_NEAR(rows[0].n_over_n0_paper->low, 11.9 / 4.88, 1e-12);
  EXPECT_NEAR(rows[0].n_over_n0_paper->high, 7.6, 1e-12);
  std::ostringstream md, csv, tex;
  write_aggregation(rows, "md", md);
  write_aggregation(rows, "csv", csv);
  write_aggregation(rows, "tex", tex);
  EXPECT_THAT(md.str(), HasSubstr("| 0.75 ± 0.03 |"));  // rounded to the error
  EXPECT_THAT(md.str(), HasSubstr("| 4.0 ± 0.3 |"));
  EXPECT_THAT(csv.str(), HasSubstr(",0.75,0.03181980515,"));  // full precision in CSV
  EXPECT_THAT(tex.str(), HasSubstr("$0.75 \\pm 0.03$"));
  EXPECT_THAT(tex.str(), HasSubstr("\\toprule"));
  EXPECT_THAT(md.str(), HasSubstr("| 2.44-7.6 |"));
  EXPECT_THAT(csv.str(), HasSubstr(",2.44-7.6,"));
}

// The paper states <n_a> only for phi 0.2, Re_inf 12 at du/U_inf 0.01, 0.02,
// 0.03 (Fig. 9 caption); any other case gets an empty column, never a value
// read off a neighbour.
TEST(PaperValues, OnlyTheStatedCasesHaveAPublishedAggregateSize) {
  EXPECT_EQ(paper_mean_aggregate_size(0.2, 12, 0.01), 4.88);
  EXPECT_EQ(paper_mean_aggregate_size(0.2, 12, 0.03), 59.4);
  EXPECT_FALSE(paper_mean_aggregate_size(0.2, 12, 0.025).has_value());
  EXPECT_FALSE(paper_mean_aggregate_size(0.2, 24, 0.02).has_value());
  EXPECT_FALSE(paper_mean_aggregate_size(0.12, 12, 0.02).has_value());
  EXPECT_FALSE(paper_mean_aggregate_size(0.2, 12, 0).has_value());
}

// The paper's discussion of Fig. 12 states <n_a>/<n_a>0 of about 2.3 (phi
// 0.12) and 7.6 (phi 0.20) for named (Re_inf, du/U_inf) cases. <n_a> grows
// with du and <n_a>0 does not depend on it. By hand at phi 0.2, Re_inf 12
// (stated 7.6 at du 0.025; Fig. 9: 4.88, 11.9, 59.4 at 0.01, 0.02, 0.03):
// <n_a>0 <= 4.88, and <n_a>(0.025) in [11.9, 59.4] gives <n_a>0 in
// [11.9/7.6, 59.4/7.6] = [1.5658, 7.8158], so [1.5658, 4.88]. Ratios:
// du 0.01: [4.88/4.88, 4.88 x 7.6/11.9] = [1, 3.1166]; du 0.02: [2.4385, 7.6];
// du 0.03: [max(7.6, 12.172), 37.936]. Elsewhere only the stated point:
// phi 0.2, Re_inf 48 (7.6 at 0.03) at du 0.02: [1, 7.6]; phi 0.12, Re_inf 24
// (2.3 at 0.025) at 0.03: [2.3, inf). Another (phi, Re_inf), or du = 0: nothing;
// nor phi 0.12, Re_inf 6, whose stated du (0.05) is outside the paper's range.
TEST(PaperValues, TheTextBoundsTheNormalisedSize) {
  const auto at = [](double phi, double re, double du) {
    return paper_normalised_size(phi, re, du);
  };
  const auto n0 = paper_baseline_range(0.2, 12);
  ASSERT_TRUE(n0);
  EXPECT_NEAR(n0->low, 1.565789474, 1e-9);
  EXPECT_NEAR(n0->high, 4.88, 1e-12);
  EXPECT_TRUE(at(0.2, 12, 0.025)->about);
  EXPECT_EQ(at(0.2, 12, 0.025)->low, 7.6);
  EXPECT_NEAR(at(0.2, 12, 0.01)->low, 1.0, 1e-12);
  EXPECT_NEAR(at(0.2, 12, 0.01)->high, 3.116638655, 1e-9);
  EXPECT_NEAR(at(0.2, 12, 0.02)->low, 2.438524590, 1e-9);
  EXPECT_NEAR(at(0.2, 12, 0.02)->high, 7.6, 1e-12);
  EXPECT_NEAR(at(0.2, 12, 0.03)->low, 12.17213115, 1e-7);
  EXPECT_NEAR(at(0.2, 12, 0.03)->high, 37.93613445, 1e-7);
  EXPECT_FALSE(at(0.2, 12, 0.03)->about);
  EXPECT_EQ(at(0.2, 48, 0.02)->low, 1.0);
  EXPECT_EQ(at(0.2, 48, 0.02)->high, 7.6);
  EXPECT_EQ(at(0.12, 24, 0.03)->low, 2.3);
  EXPECT_TRUE(std::isinf(at(0.12, 24, 0.03)->high));
  EXPECT_FALSE(at(0.12, 6, 0.03));
  EXPECT_FALSE(paper_baseline_range(0.2, 48));  // no stated <n_a> there
  EXPECT_FALSE(at(0.2, 24, 0.02));
  EXPECT_FALSE(at(0.25, 12, 0.02));
  EXPECT_FALSE(at(0.2, 12, 0));
}

TEST_F(Post, ABaselineThatLeavesDuAtItsDefaultIsFound) {
  // du_over_Uinf absent from the baseline's case means 0, its default
  json base = suspension(0);
  base.erase("du_over_Uinf");
  const std::string db_path =
      write_db({{"base", base, "completed", 4.0, 0.12, 2.0, 0.1},
                {"agg", suspension(0.02), "completed", 3.0, 0.09, 8.0, 0.4}});
  db::ResultsDb db(db_path, db::ResultsDb::Mode::kReadOnly);
  const auto rows = aggregation_table(load_runs(db, std::nullopt, {}));
  ASSERT_EQ(rows.size(), 1u);
  ASSERT_NE(rows[0].baseline, nullptr) << rows[0].reason;
}

// The same input case resolved to another lubrication model under another
// version (the default changed): F/F0 would mix two models, so no pairing.
TEST_F(Post, NoBaselineAcrossResolvedModels) {
  const std::string db_path =
      write_db({{"base", suspension(0), "completed", 4.0, 0.12, 2.0, 0.1, "nguyen-ladd"},
                {"agg", suspension(0.02), "completed", 3.0, 0.09, 8.0, 0.4, "calibrated"},
                {"agg2", suspension(0.03), "completed", 2.8, 0.09, 12.0, 0.4, "nguyen-ladd"}});
  db::ResultsDb db(db_path, db::ResultsDb::Mode::kReadOnly);
  const auto runs = load_runs(db, std::nullopt, {});
  const auto rows = aggregation_table(runs);
  ASSERT_EQ(rows.size(), 2u);
  for (const auto& r : rows) {
    if (r.run->id == "agg") {
      EXPECT_EQ(r.baseline, nullptr);
      EXPECT_THAT(r.reason, AllOf(HasSubstr("lubrication_model nguyen-ladd"),
                                  HasSubstr("lubrication_model calibrated")));
    } else {
      ASSERT_NE(r.baseline, nullptr) << r.reason;  // same model: paired
      EXPECT_NEAR(r.F_over_F0->mean, 2.8 / 4.0, 1e-12);
    }
  }
}

// Results of older versions lack numerics.immersed_boundary: they ran the
// paper's method (0.7 dx, 2 sweeps, roma3), so they pair with a run that names
// it and not with one that ran another scheme. Of several du = 0 runs of one
// case the first that ran the same models serves.
TEST_F(Post, OlderResultsPairByTheModelsTheyRan) {
  const json paper = {{"marker_spacing", 0.7}, {"sweeps", 2}, {"kernel", "roma3"}};
  const json one_sweep = {{"marker_spacing", 1.0}, {"sweeps", 1}, {"kernel", "roma3"}};
  const std::string db_path = write_db({
      {"old0", suspension(0), "completed", 4.0, 0.12, 2.0, 0.1, "calibrated"},  // no IB field
      {"new1", suspension(0.01), "completed", 3.6, 0.1, 4.0, 0.2, "calibrated", paper},
      {"new2", suspension(0.02), "completed", 3.2, 0.1, 8.0, 0.4, "calibrated", one_sweep},
  });
  db::ResultsDb db(db_path, db::ResultsDb::Mode::kReadOnly);
  auto rows = aggregation_table(load_runs(db, std::nullopt, {}));
  ASSERT_EQ(rows.size(), 2u);
  for (const auto& r : rows) {
    if (r.run->id == "new1") {
      ASSERT_NE(r.baseline, nullptr) << r.reason;
      EXPECT_NEAR(r.F_over_F0->mean, 3.6 / 4.0, 1e-12);
    } else {
      EXPECT_EQ(r.baseline, nullptr);
      EXPECT_THAT(r.reason, AllOf(HasSubstr("\"sweeps\":2"), HasSubstr("\"sweeps\":1")));
    }
  }
  // two baselines: the one with the other model comes first, the matching one serves
  fs::rename(db_path, fs::path(db_path).parent_path() / "first.db");  // write_db's path is reused
  const std::string db_path2 = write_db({
      {"nl0", suspension(0), "completed", 4.2, 0.1, 2.0, 0.1, "nguyen-ladd", paper},
      {"cal0", suspension(0), "completed", 4.0, 0.1, 2.0, 0.1, "calibrated", paper},
      {"cal2", suspension(0.02), "completed", 3.0, 0.1, 8.0, 0.4, "calibrated", paper},
  });
  db::ResultsDb second(db_path2, db::ResultsDb::Mode::kReadOnly);
  rows = aggregation_table(load_runs(second, std::nullopt, {}));
  ASSERT_EQ(rows.size(), 1u);
  ASSERT_NE(rows[0].baseline, nullptr) << rows[0].reason;
  EXPECT_EQ(rows[0].baseline->id, "cal0");
  EXPECT_NEAR(rows[0].F_over_F0->mean, 3.0 / 4.0, 1e-12);
}

TEST_F(Post, NoBaselineAcrossNumericsAndEveryMissingBaselineHasItsReason) {
  const std::string db_path = write_db({
      {"b8", suspension(0, 12, 8), "completed", 4.0, 0.1, 2.0, 0.1},     // du = 0 at a = 8
      {"a6", suspension(0.03, 12, 6), "completed", 3.0, 0.1, 9.0, 0.5},  // a = 6: no baseline
      {"f24", suspension(0, 24), "failed"},                              // a failed baseline
      {"a24", suspension(0.01, 24), "completed", 3.5, 0.1, 3.0, 0.2},
      {"run", suspension(0.02, 24), "running"},  // still running
  });
  db::ResultsDb db(db_path, db::ResultsDb::Mode::kReadOnly);
  const auto runs = load_runs(db, std::nullopt, {});
  const auto rows = aggregation_table(runs);
  ASSERT_EQ(rows.size(), 3u);  // every run with du > 0 is listed
  std::map<std::string, std::string> reason;
  for (const auto& r : rows) {
    EXPECT_EQ(r.baseline, nullptr) << r.run->id;
    reason[r.run->id] = r.reason;
  }
  EXPECT_THAT(reason["a6"], HasSubstr("no du = 0 run of the same case"));
  EXPECT_THAT(reason["a24"], HasSubstr("baseline f24 is failed"));
  EXPECT_THAT(reason["run"], HasSubstr("this run is running"));
  // a run with no result has no verdict on its errors or stationarity: blank, not "yes"
  std::ostringstream csv;
  write_aggregation(rows, "csv", csv);
  std::istringstream lines(csv.str());
  std::string header, line;
  std::getline(lines, header);
  std::vector<std::string> names;
  for (std::istringstream h(header); std::getline(h, line, ',');) names.push_back(line);
  const auto column = [&](const std::string& name) {
    return std::find(names.begin(), names.end(), name) - names.begin();
  };
  bool seen_running = false;
  while (std::getline(lines, line)) {
    std::vector<std::string> cells;
    for (std::istringstream c(line); std::getline(c, header, ',');) cells.push_back(header);
    cells.resize(names.size());
    if (cells[column("run")] != "run") continue;
    seen_running = true;
    EXPECT_EQ(cells[column("errors_reliable")], "");
    EXPECT_EQ(cells[column("stationary")], "");
  }
  EXPECT_TRUE(seen_running);
  // a filter as in flocsim query
  const auto only24 = load_runs(db, std::nullopt, {orchestrator::parse_filter("Re_inf=24")});
  EXPECT_EQ(only24.size(), 3u);
  EXPECT_THROW(load_runs(db, std::string("nosuch"), {}), input::InputError);
}

TEST_F(Post, SeveralSweepsInOneDatabase) {
  // a second sweep shares the baseline and adds a run of its own: every run once, and
  // --sweep selects one sweep's runs
  const std::string db_path =
      write_db({{"base", suspension(0), "completed", 4.0, 0.12, 2.0, 0.1},
                {"agg", suspension(0.02), "completed", 3.0, 0.09, 8.0, 0.4}});
  {
    db::ResultsDb db(db_path, db::ResultsDb::Mode::kExisting);
    const auto other = db.upsert_sweep("other", "{}", "[]", 2);
    db.add_runs(
        other,
        {{"base", orchestrator::canonical_text(suspension(0)), (dir_ / "base").string(), "{}"},
         {"new", orchestrator::canonical_text(suspension(0.01)), (dir_ / "new").string(), "{}"}});
  }
  db::ResultsDb db(db_path, db::ResultsDb::Mode::kReadOnly);
  const auto all = load_runs(db, std::nullopt, {});
  EXPECT_EQ(all.size(), 3u);
  const auto rows = aggregation_table(all);
  ASSERT_EQ(rows.size(), 2u);
  for (const auto& r : rows) {
    if (r.run->id == "new") {
      EXPECT_THAT(r.reason, HasSubstr("this run is pending"));
    }
  }
  const auto other = load_runs(db, std::string("other"), {});
  EXPECT_EQ(other.size(), 2u);
}

TEST(RoundToError, OneSignificantDigitOfTheError) {
  using orchestrator::format_with_error;
  EXPECT_EQ(format_with_error(0.303742, 0.00189871), "0.304 ± 0.002");
  EXPECT_EQ(format_with_error(6, 0.5), "6.0 ± 0.5");
  EXPECT_EQ(format_with_error(12345, 678), "12300 ± 700");
  EXPECT_EQ(format_with_error(0.0963, 0.0096), "0.10 ± 0.01");  // 0.0096 rounds to 0.01
  EXPECT_EQ(format_with_error(3.14159, std::nullopt), "3.142");
}

TEST(ReferenceCurves, AgainstHandComputedValues) {
  // Beetstra eq. 4 at phi = 0.2, Re = 4: Stokes part 10 * 0.2 / 0.64 + 0.64 (1 + 1.5
  // sqrt 0.2) = 3.125 + 1.069325 = 4.194325; inertial part 0.413 * 4 / (24 * 0.64) = 0.107552
  // times (1.25 + 0.48 + 8.4 * 4^-0.343 = 6.951229) over (1 + 10^0.6 * 4^-0.9 = 2.143263)
  // = 0.348823; total 4.543148.
  EXPECT_NEAR(observables::beetstra_drag(0.2, 4), 4.543148, 2e-6);
  // Wylie eq. 5 at Re_T = 1: x = 0.25, amplitude 4 (0.0336 + 0.0212 + 0.0116 / 0.8^5)
  // = 0.360800; shape (1 + 0.125 - 0.00390625) erf(2.828427) + sqrt(2/pi) 0.25
  // (1.0625) exp(-8) = 1.121094; so F = Beetstra + 0.404491.
  EXPECT_NEAR(observables::wylie_drag(0.2, 4, 1) - observables::beetstra_drag(0.2, 4), 0.404491,
              2e-6);
  EXPECT_EQ(observables::wylie_drag(0.2, 4, 0), observables::beetstra_drag(0.2, 4));
  // Richardson-Zaki at Re_inf = 0.1 (n = 4.65): 0.8^4.65 = exp(4.65 * -0.2231436) =
  // exp(-1.0376176) = 0.367879 * 0.963081 = 0.354298
  EXPECT_NEAR(observables::richardson_zaki_velocity_ratio(0.2, 0.1), 0.354298, 2e-6);
}

bool starts_with(const fs::path& file, const std::string& magic) {
  std::ifstream in(file, std::ios::binary);
  std::string head(magic.size(), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  return head == magic;
}

TEST_F(Post, FiguresAreRealPngAndPdfFilesAndTheReportEmbedsThem) {
  const std::string db_path =
      write_db({{"base", suspension(0), "completed", 4.0, 0.12, 2.0, 0.1},
                {"agg", suspension(0.02), "completed", 3.0, 0.09, 8.0, 0.4},
                {"agg3", suspension(0.03), "completed", 2.8, 0.09, 12.0, 0.6}},
               /*with_series=*/true);
  db::ResultsDb db(db_path, db::ResultsDb::Mode::kReadOnly);
  const auto runs = load_runs(db, std::nullopt, {});
  const FigureSet set = write_figures(runs, dir_ / "figures");
  std::set<std::string> names;
  for (const Figure& f : set.figures) {
    names.insert(f.name);
    EXPECT_TRUE(starts_with(f.png, "\x89PNG\r\n\x1a\n")) << f.png;
    EXPECT_TRUE(starts_with(f.pdf, "%PDF")) << f.pdf;
    EXPECT_GT(fs::file_size(f.png), 5000u) << f.png;  // drawn, not an empty canvas
    EXPECT_GT(fs::file_size(f.pdf), 3000u) << f.pdf;
  }
  for (const char* want :
       {"drag_vs_Re", "ReT_vs_Re", "timeseries_phi0.2_Re12", "size_distribution_phi0.2_Re12",
        "pair_structure_phi0.2_Re12", "spacetime_phi0.2_Re12_du0.02", "n_a_vs_du",
        "drag_vs_Re_per_du", "drag_ratio_vs_size_ratio"})
    EXPECT_TRUE(names.count(want)) << want;
  // A two-panel figure draws both panels into the PDF too: every plot command appears once
  // per terminal (gnuplot 5.4's replot after a multiplot would redraw only the last panel).
  for (const char* two_panels : {"timeseries_phi0.2_Re12", "pair_structure_phi0.2_Re12"}) {
    std::ifstream gp(dir_ / "figures" / "scripts" / (std::string(two_panels) + ".gp"));
    std::string line;
    int plots_png = 0, plots_pdf = 0;
    bool pdf = false;
    while (std::getline(gp, line)) {
      if (line.rfind("set terminal pdfcairo", 0) == 0) pdf = true;
      if (line.rfind("plot ", 0) == 0) ++(pdf ? plots_pdf : plots_png);
      EXPECT_NE(line, "replot") << two_panels;
    }
    EXPECT_EQ(plots_png, 2) << two_panels;
    EXPECT_EQ(plots_pdf, 2) << two_panels;
  }
  write_report(runs, set, db_path, dir_ / "report.html");
  std::ifstream in(dir_ / "report.html");
  std::stringstream html;
  html << in.rdbuf();
  EXPECT_THAT(html.str(), HasSubstr("data:image/png;base64,iVBORw0KGgo"));  // an embedded PNG
  EXPECT_THAT(html.str(), HasSubstr("0.75 ± 0.03"));
  EXPECT_THAT(html.str(), HasSubstr(">completed</td>"));  // the provenance table's state
}

// Fig. 12 with the paper's comparison points: the paper states only their common
// normalised size (about 7.6 at phi 0.2), so the panel draws a line there and
// rings flocsim's run of a stated (Re_inf, du), and nothing at a phi without any.
TEST_F(Post, TheDragRatioPanelsDrawThePapersStatedSizeAndRingTheStatedRuns) {
  auto at_phi = [](json c, double phi) {
    c["phi"] = phi;
    return orchestrator::canonical(c);
  };
  // phi 0.2, Re_inf 12: baseline F0 4.0, <n_a>0 2.0; stated du 0.025: F 3.0, <n_a> 16
  // (by hand: 8 and 0.75); du 0.02 is not a stated point. phi 0.32: none stated.
  const std::string db_path =
      write_db({{"base", suspension(0), "completed", 4.0, 0.12, 2.0, 0.1},
                {"stated", suspension(0.025), "completed", 3.0, 0.09, 16.0, 0.4},
                {"other", suspension(0.02), "completed", 3.5, 0.09, 8.0, 0.4},
                {"base32", at_phi(suspension(0), 0.32), "completed", 6.0, 0.12, 2.0, 0.1},
                {"agg32", at_phi(suspension(0.025), 0.32), "completed", 5.0, 0.12, 4.0, 0.1}});
  db::ResultsDb db(db_path, db::ResultsDb::Mode::kReadOnly);
  const FigureSet set = write_figures(load_runs(db, std::nullopt, {}), dir_ / "figures");
  ASSERT_TRUE(std::any_of(set.figures.begin(), set.figures.end(),
                          [](const Figure& f) { return f.name == "drag_ratio_vs_size_ratio"; }));
  std::ifstream gp(dir_ / "figures" / "scripts" / "drag_ratio_vs_size_ratio.gp");
  std::stringstream script;
  script << gp.rdbuf();
  EXPECT_THAT(script.str(), HasSubstr("set arrow 1 from 7.6, graph 0 to 7.6, graph 1"));
  EXPECT_THAT(script.str(), HasSubstr("(48, 0.03), (12, 0.025), (6, 0.02)"));
  EXPECT_THAT(script.str(), Not(HasSubstr("set arrow 1 from 2.3")));  // no phi 0.12 panel
  // the ringed points: only the stated run, at its own ratios
  std::ifstream ringed(dir_ / "figures" / "data" / "drag_ratio_vs_size_ratio_phi0.2_stated.dat");
  std::string line, rows;
  while (std::getline(ringed, line)) rows += line + "\n";
  EXPECT_EQ(rows, "8 0.75\n");
  EXPECT_FALSE(
      fs::exists(dir_ / "figures" / "data" / "drag_ratio_vs_size_ratio_phi0.32_stated.dat"));
}

// Issue 41, item 2: a completed run whose series.h5 was missing or damaged
// was left out of the time-series figures without a word (exit 0, the tables
// still listing it). Each is named with its file, the reason and the figures.
TEST_F(Post, ACompletedRunWithoutItsSeriesIsNamedWithTheFiguresItIsMissingFrom) {
  const std::string db_path =
      write_db({{"base", suspension(0), "completed", 4.0, 0.12, 2.0, 0.1},
                {"agg", suspension(0.02), "completed", 3.0, 0.09, 8.0, 0.4},
                {"agg3", suspension(0.03), "completed", 2.8, 0.09, 12.0, 0.6},
                {"later", suspension(0.04), "pending"}},
               /*with_series=*/true);
  fs::remove(dir_ / "agg" / "series.h5");
  fs::resize_file(dir_ / "agg3" / "series.h5", 100);  // cut short
  db::ResultsDb db(db_path, db::ResultsDb::Mode::kReadOnly);
  const auto runs = load_runs(db, std::nullopt, {});
  const FigureSet set = write_figures(runs, dir_ / "figures");
  ASSERT_EQ(set.runs_left_out.size(), 2u);  // not the pending run: it has no series yet
  EXPECT_THAT(set.runs_left_out[0],
              AllOf(HasSubstr("run agg "), HasSubstr((dir_ / "agg" / "series.h5").string()),
                    HasSubstr("is missing"), HasSubstr("timeseries_phi0.2_Re12"),
                    HasSubstr("spacetime_phi0.2_Re12_du0.02")));
  EXPECT_THAT(set.runs_left_out[1], AllOf(HasSubstr("run agg3 "), HasSubstr("cannot be read"),
                                          HasSubstr("size_distribution_phi0.2_Re12")));
  write_report(runs, set, db_path, dir_ / "report.html");
  std::ifstream in(dir_ / "report.html");
  std::stringstream html;
  html << in.rdbuf();
  EXPECT_THAT(html.str(), AllOf(HasSubstr("Left out of figures: run agg "),
                                HasSubstr("Left out of figures: run agg3 ")));
}

TEST_F(Post, NoSingleValueWidensTheReportsTablesBeyondThePage) {
  // A sweep name a script made from every parameter: before, it stretched the
  // provenance table to ten page widths, and the tables ran off a 1400-pixel page.
  std::string long_name = "paper-grid";
  while (long_name.size() < 300)
    long_name += "-phi0.2-Re12-du0.02-a6-standard-seed" + std::to_string(long_name.size());
  const std::string db_path =
      write_db({{"base", suspension(0), "completed", 4.0, 0.12, 2.0, 0.1},
                {"agg", suspension(0.02), "completed", 3.0, 0.09, 8.0, 0.4}},
               false, long_name);
  db::ResultsDb db(db_path, db::ResultsDb::Mode::kReadOnly);
  const auto runs = load_runs(db, std::nullopt, {});
  write_report(runs, FigureSet{}, db_path, dir_ / "report.html");
  std::ifstream in(dir_ / "report.html");
  std::stringstream text;
  text << in.rdbuf();
  const std::string html = text.str();
  // the name is never a cell's whole visible text: it is cut, the whole on hover
  EXPECT_THAT(html, Not(HasSubstr(">" + long_name + "<")));
  EXPECT_THAT(html, HasSubstr("title='" + long_name + "'"));
  EXPECT_THAT(html, HasSubstr(">" + long_name.substr(0, 20)));
  EXPECT_THAT(html, HasSubstr("\u2026"));  // the ellipsis that marks the cut
  // every table scrolls inside its own box instead of widening the page
  std::size_t tables = 0, boxed = 0;
  for (std::size_t at = html.find("<table"); at != std::string::npos;
       at = html.find("<table", at + 1)) {
    ++tables;
    boxed +=
        html.rfind("<div class='scroll'>", at) == at - std::string("<div class='scroll'>").size();
  }
  EXPECT_GE(tables, 3u);
  EXPECT_EQ(boxed, tables);
  EXPECT_THAT(html, HasSubstr(".scroll{overflow:auto"));
}

}  // namespace
}  // namespace flocsim::postprocess
