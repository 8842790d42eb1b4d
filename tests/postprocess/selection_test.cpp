// `flocsim query` and `flocsim post` select runs with one implementation
// (orchestrator/run_selection.hpp): filters act on the case as each run ran
// it, defaults filled in; post refuses what query refuses; a baseline is
// found in the whole database whatever the selection; a row that cannot be
// read is listed with its run and field and never shown as a result.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <set>
#include <sstream>

#include "db/results_db.hpp"
#include "engine/case/resolved_case.hpp"
#include "engine/input/input_reader.hpp"
#include "orchestrator/report.hpp"
#include "orchestrator/run_selection.hpp"
#include "orchestrator/sweep.hpp"
#include "postprocess/tables.hpp"
#include "tests/run/scratch_dir.hpp"

namespace flocsim::postprocess {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::UnorderedElementsAre;

// A draft suspension at a = 4 (quick to resolve), with extra fields.
json draft(double du, const json& extra = json::object()) {
  json c = {{"scene", "suspension"}, {"fidelity", "draft"}, {"phi", 0.2},
            {"Re_inf", 12},          {"du_over_Uinf", du},  {"numerics", {{"a_over_dx", 4}}}};
  c.merge_patch(extra);
  return orchestrator::canonical(c);
}

// One row as the orchestrator writes it: the case as given, and for a
// completed run the result as `flocsim run` writes it, or any text.
struct Row {
  std::string id;
  std::string case_text;
  bool completed = false;
  std::string result_text;  // empty: the result a run of this case writes
  double F = 4, n_a = 2;
};

class Selection : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = flocsim::testing::fresh_dir(
        std::string("selection_") +
        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    db_ = (dir_ / "results.db").string();
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }

  // The result.json a run of this case writes, with these observables.
  static std::string result_of(const json& input_case, double F, double n_a) {
    const json obs = {{"F", {{"mean", F}, {"error", 0.1}, {"error_reliable", true}}},
                      {"n_a_mean", {{"mean", n_a}, {"error", 0.1}, {"error_reliable", true}}},
                      {"window", {{"start", 10}, {"end", 30}}}};
    return json{{"case", cases::resolved_case(input_case)},
                {"observables", obs},
                {"not_stationary", json::array()},
                {"derived", {{"sphere_count", 49}}}}
        .dump();
  }

  void add(const std::string& sweep, const std::vector<Row>& rows) {
    db::ResultsDb db(db_, db::ResultsDb::Mode::kCreate);
    const auto id = db.upsert_sweep(sweep, "{}", "[\"du_over_Uinf\"]", 3);
    std::vector<db::ResultsDb::NewRun> news;
    for (const Row& r : rows) news.push_back({r.id, r.case_text, (dir_ / r.id).string(), "{}"});
    db.add_runs(id, news);
    for (const Row& r : rows) {
      if (!r.completed) continue;
      db::ClaimRequest req;
      req.sweep_id = id;
      req.states = {db::RunState::kPending};
      req.run_id = r.id;
      db::AttemptStart start;
      start.owner_pid = getpid();
      const auto claim = db.claim_run(req, start);
      ASSERT_TRUE(claim);
      db::ResultRecord rec;
      rec.run_id = r.id;
      rec.flocsim_version = "test";
      rec.completed_at = "now";
      rec.wall_s = 10;
      rec.result_json =
          r.result_text.empty() ? result_of(json::parse(r.case_text), r.F, r.n_a) : r.result_text;
      rec.observables = {{"F", r.F, 0.1}, {"n_a_mean", r.n_a, 0.1}, {"Re", 4.0, 0.1}};
      db.record_result(claim->attempt_id, rec);
    }
  }

  // The runs `flocsim query --where ...` lists (first 12 characters of their ids).
  std::set<std::string> query(const std::vector<std::string>& where,
                              const std::optional<std::string>& sweep = std::nullopt,
                              std::string* left_out = nullptr) {
    db::ResultsDb db(db_, db::ResultsDb::Mode::kReadOnly);
    orchestrator::QueryOptions q;
    q.sweep = sweep;
    q.format = "json";
    for (const auto& w : where) q.where.push_back(orchestrator::parse_filter(w));
    std::ostringstream out, problems;
    q.left_out = &problems;
    orchestrator::write_query(db, q, out);
    if (left_out) *left_out = problems.str();
    std::set<std::string> ids;
    for (const json& row : json::parse(out.str())) ids.insert(row["id"].get<std::string>());
    return ids;
  }
  // The runs `flocsim post --where ...` takes.
  std::set<std::string> post(const std::vector<std::string>& where,
                             const std::optional<std::string>& sweep = std::nullopt) {
    db::ResultsDb db(db_, db::ResultsDb::Mode::kReadOnly);
    std::vector<orchestrator::Filter> filters;
    for (const auto& w : where) filters.push_back(orchestrator::parse_filter(w));
    std::set<std::string> ids;
    for (const RunSummary& r : load_runs(db, sweep, filters)) ids.insert(r.id.substr(0, 12));
    return ids;
  }

  fs::path dir_;
  std::string db_;
};

TEST_F(Selection, FiltersSeeTheCaseAsItRanWithDefaultsFilledIn) {
  // Two runs name Nguyen-Ladd's model, one completed run and one pending run
  // leave it to the default, which a case file resolves to "calibrated"
  // (docs/user-guide.md); one names the paper's immersed-boundary method, the
  // others leave it to the draft preset's one-sweep option.
  const json paper_ib = {
      {"numerics", {{"immersed_boundary", {{"marker_spacing", 0.7}, {"sweeps", 2}}}}}};
  add("demo", {{"nl0", draft(0, {{"lubrication_model", "nguyen-ladd"}}).dump(), true},
               {"nl2", draft(0.02, {{"lubrication_model", "nguyen-ladd"}}).dump(), true},
               {"def1", draft(0.01).dump(), true},
               {"def3", draft(0.03).dump(), false},
               {"ib2", draft(0.025, paper_ib).dump(), true}});
  ASSERT_EQ(cases::resolved_case(draft(0.01))["lubrication_model"], "calibrated");
  ASSERT_EQ(cases::resolved_case(draft(0.01))["numerics"]["immersed_boundary"]["sweeps"], 1);
  for (const bool by_post : {false, true}) {
    SCOPED_TRACE(by_post ? "post" : "query");
    const auto q = [&](const std::vector<std::string>& w) { return by_post ? post(w) : query(w); };
    EXPECT_THAT(q({"lubrication_model=calibrated"}), UnorderedElementsAre("def1", "def3", "ib2"));
    EXPECT_THAT(q({"lubrication_model!=nguyen-ladd"}), UnorderedElementsAre("def1", "def3", "ib2"));
    EXPECT_THAT(q({"lubrication_model=nguyen-ladd"}), UnorderedElementsAre("nl0", "nl2"));
    EXPECT_THAT(q({"numerics.immersed_boundary.sweeps=1"}),
                UnorderedElementsAre("nl0", "nl2", "def1", "def3"));
    EXPECT_THAT(q({"numerics.immersed_boundary.marker_spacing<1"}), UnorderedElementsAre("ib2"));
  }
}

TEST_F(Selection, PostRefusesAndSelectsExactlyAsQuery) {
  add("demo", {{"b0", draft(0).dump(), true, "", 4, 2},
               {"b2", draft(0.02).dump(), true, "", 3, 8},
               {"b3", draft(0.03).dump(), false}});
  db::ResultsDb db(db_, db::ResultsDb::Mode::kReadOnly);
  for (const std::string bad : {"phii=0.2", "Re_inf<abc", "F_err<abc"}) {
    const auto filter = orchestrator::parse_filter(bad);
    std::string query_refusal, post_refusal;
    try {
      query({bad});
    } catch (const input::InputError& e) {
      query_refusal = e.what();
    }
    try {
      load_runs(db, std::nullopt, {filter});
    } catch (const input::InputError& e) {
      post_refusal = e.what();
    }
    EXPECT_THAT(query_refusal, HasSubstr(filter.field)) << bad;
    EXPECT_EQ(post_refusal, query_refusal) << bad;
  }
  for (const std::vector<std::string>& where : {std::vector<std::string>{"sweep=demo"},
                                                {"F_err<1"},
                                                {"F<3.5"},
                                                {"status=pending"},
                                                {"wall_s>=10"},
                                                {"du_over_Uinf>0.01", "status=completed"}}) {
    EXPECT_EQ(post(where), query(where)) << where.front();
    EXPECT_FALSE(post(where).empty()) << where.front();
  }
  EXPECT_THAT(post({"sweep=demo"}), UnorderedElementsAre("b0", "b2", "b3"));
  EXPECT_THAT(post({"F_err<1"}), UnorderedElementsAre("b0", "b2"));
}

TEST_F(Selection, TheBaselineIsFoundOutsideTheSelection) {
  // the du = 0 run of the same case sits in sweep A, the aggregating run in B
  add("A", {{"base", draft(0).dump(), true, "", 4.0, 2.0}});
  add("B", {{"agg", draft(0.02).dump(), true, "", 3.0, 8.0}});
  db::ResultsDb db(db_, db::ResultsDb::Mode::kReadOnly);
  for (const auto& [sweep, where] :
       {std::pair<std::optional<std::string>, std::string>{"B", "du_over_Uinf>=0"},
        {std::nullopt, "du_over_Uinf=0.02"}}) {
    const auto runs = load_runs(db, sweep, {orchestrator::parse_filter(where)});
    ASSERT_EQ(runs.size(), 1u) << where;
    const auto rows = aggregation_table(runs);
    ASSERT_EQ(rows.size(), 1u);
    ASSERT_NE(rows[0].baseline, nullptr) << rows[0].reason;
    EXPECT_EQ(rows[0].baseline->id, "base");
    EXPECT_DOUBLE_EQ(rows[0].F_over_F0->mean, 3.0 / 4.0);
    EXPECT_DOUBLE_EQ(rows[0].n_over_n0->mean, 8.0 / 2.0);
  }
}

TEST_F(Selection, UnreadableRowsAreListedAndNeverShownAsResults) {
  json bad_window = json::parse(Selection::result_of(draft(0.01), 3, 8));
  bad_window["observables"]["window"]["start"] = "abc";
  add("demo", {{"base", draft(0).dump(), true, "garbage", 4.0, 2.0},
               {"agg", draft(0.02).dump(), true, "", 3.0, 8.0},
               {"broken", "{not json", false},
               {"window", draft(0.01).dump(), true, bad_window.dump()},
               {"good", draft(0.03).dump(), false}});
  // query lists the readable runs and names each unreadable one: run, field, what
  std::string left_out;
  EXPECT_THAT(query({}, std::nullopt, &left_out), UnorderedElementsAre("agg", "good"));
  EXPECT_THAT(left_out, AllOf(HasSubstr("run base"), HasSubstr("result_json: is not JSON")));
  EXPECT_THAT(left_out, AllOf(HasSubstr("run broken"), HasSubstr("case_json: is not JSON")));
  EXPECT_THAT(left_out,
              AllOf(HasSubstr("run window"), HasSubstr("result_json.observables.window.start"),
                    HasSubstr("must be a number")));
  // post leaves the same rows out and says so; the baseline with a garbage
  // result is no baseline, and the row says why
  db::ResultsDb db(db_, db::ResultsDb::Mode::kReadOnly);
  std::vector<orchestrator::DamagedRun> damaged;
  const auto runs = load_runs(db, std::nullopt, {}, &damaged);
  std::set<std::string> ids, damaged_ids;
  for (const auto& r : runs) ids.insert(r.id);
  for (const auto& d : damaged) damaged_ids.insert(d.run_id);
  EXPECT_THAT(ids, UnorderedElementsAre("agg", "good"));
  EXPECT_THAT(damaged_ids, UnorderedElementsAre("base", "broken", "window"));
  EXPECT_TRUE(non_aggregating_table(runs).empty());
  for (const AggregationRow& row : aggregation_table(runs)) {
    EXPECT_EQ(row.baseline, nullptr) << row.run->id;
    if (row.run->id == "agg") {
      EXPECT_THAT(row.reason,
                  AllOf(HasSubstr("base"), HasSubstr("cannot be read"), HasSubstr("result_json")));
    }
  }
}

}  // namespace
}  // namespace flocsim::postprocess
