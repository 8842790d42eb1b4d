#pragma once
// The science from a results database (paper section 4.4): the drag per
// sphere of an aggregating suspension relative to the same suspension without
// attraction, F/F0, against the normalised mean aggregate size <n_a>/<n_a>0,
// and the non-aggregating drag against the published correlations.
//
// A run with du/U_inf > 0 is paired with its baseline: the run whose canonical
// case is identical but for du_over_Uinf = 0 (same phi, Re_inf, fidelity,
// numerics, box, seed, protocol). Nothing else is ever paired, and a run
// without a usable baseline is listed with the reason, never dropped.
//
// Errors: each mean carries its batch-means standard error; a ratio r = a/b of
// two independent runs carries e_r = |r| sqrt((e_a/a)^2 + (e_b/b)^2) (first
// order). docs/postprocess.md.
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "db/results_db.hpp"
#include "orchestrator/report.hpp"
#include "orchestrator/run_selection.hpp"
#include "postprocess/paper_values.hpp"

namespace flocsim::postprocess {

// A mean with its standard error (absent for plain numbers or missing data).
struct Measured {
  double mean = 0;
  std::optional<double> error;
};

// One run of the database, with what the tables need from its result.json.
struct RunSummary {
  std::string id;
  db::RunState status = db::RunState::kPending;
  std::string run_dir, sweep;
  nlohmann::json case_json;  // canonical case
  bool has_result = false;
  std::optional<Measured> U_over_Uinf, F, Re, Re_T, C_sph, n_a;
  bool errors_reliable = true;  // every error in the table's observables is
  std::vector<std::string> not_stationary;
  double window_start = 0, window_end = 0;  // statistics window, t U_inf / a
  int sphere_count = 0;
  double phi = 0, re_inf = 0, du = 0;
  std::optional<double> wall_s;
  std::string flocsim_version, fidelity;
  // The models the run resolved (result.json's case: lubrication model and
  // immersed-boundary scheme), which the input case may leave to defaults
  // that changed between versions; empty without a result.
  std::string resolved_models;
  // A run with du/U_inf > 0: every du = 0 run of the same case in the whole
  // database, whatever the selection (load_runs fills it), in grid order.
  std::vector<std::shared_ptr<const RunSummary>> zero_du_runs;
  // A du = 0 run whose row cannot be read: what is wrong (it is never a
  // baseline, only named as the reason there is none).
  std::string damage;
};

// The runs of the database (of one sweep when given), selected as `flocsim
// query` selects them (orchestrator/run_selection.hpp: the same columns, case
// fields and refusals), in grid order. Rows that cannot be read are left out
// and, when `left_out` is given, listed there.
std::vector<RunSummary> load_runs(db::ResultsDb& db, const std::optional<std::string>& sweep,
                                  const std::vector<orchestrator::Filter>& where,
                                  std::vector<orchestrator::DamagedRun>* left_out = nullptr);

// r = a / b with its first-order error for independent a and b.
Measured ratio(const Measured& a, const Measured& b);

struct AggregationRow {
  const RunSummary* run = nullptr;
  const RunSummary* baseline = nullptr;  // null: see reason
  std::string reason;                    // why there is no pairing (empty when paired)
  std::optional<Measured> F_over_F0, n_over_n0;
  std::optional<double> n_a_paper;       // the paper's stated <n_a> for this case, if any
  std::optional<Measured> n_over_paper;  // <n_a> / n_a_paper (flocsim's error only)
  // the paper's statement on <n_a>/<n_a>0 for this (phi, Re_inf): a value at its
  // own du, a bound at any other (paper_values.hpp)
  std::optional<PaperNormalisedSize> n_over_n0_paper;
};
// One row per run with du/U_inf > 0, paired where a completed baseline exists
// (among its zero_du_runs: the whole database, not only the selection).
std::vector<AggregationRow> aggregation_table(const std::vector<RunSummary>& runs);

struct NonAggregatingRow {
  const RunSummary* run = nullptr;
  double beetstra = 0, wylie = 0, richardson_zaki = 0;  // F, F, U/U_inf
};
// One row per completed run with du/U_inf = 0.
std::vector<NonAggregatingRow> non_aggregating_table(const std::vector<RunSummary>& runs);

// The tables in the formats of `flocsim post tables`; `format` is csv, md or tex.
void write_aggregation(const std::vector<AggregationRow>& rows, const std::string& format,
                       std::ostream& out);
void write_non_aggregating(const std::vector<NonAggregatingRow>& rows, const std::string& format,
                           std::ostream& out);
// Definitions and units of every column (the CSV files' sidecar).
std::string column_definitions();

// The tables' cells as Markdown shows them (means rounded to their errors), one
// vector per row, the column names first: for the terminal and the HTML page.
std::vector<std::vector<std::string>> aggregation_cells(const std::vector<AggregationRow>& rows);
std::vector<std::vector<std::string>> non_aggregating_cells(
    const std::vector<NonAggregatingRow>& rows);

// A column as the quantity reads: "F/F0", "<n_a>/<n_a>0", "du/U_inf" in plain
// text; in HTML with sub- and superscripts and entities. Unknown names as given.
std::string column_label(const std::string& name, bool html);

// Short marks for a row, with their details: u = errors not reliable, s = a
// window still drifts (not stationary), b = no F/F0 (the reason).
struct RowFlags {
  std::string marks;   // "", "u", "us", ...
  std::string detail;  // one line per mark
};
RowFlags run_flags(const RunSummary& run, const RunSummary* baseline = nullptr);
RowFlags aggregation_flags(const AggregationRow& row);

// The columns a user reads first: phi, Re_inf, du/U_inf, F/F0, <n_a>/<n_a>0, U/U_inf.
const std::vector<std::string>& aggregation_first_columns();

// The aggregation table for a terminal: the first columns and the flags, or
// `columns` (names as in the files, "flags" too), or every column (`all`),
// fitted to `width` characters (0: no limit), then the flags' legend and the
// columns left out. Throws input::InputError for an unknown column.
void write_aggregation_terminal(const std::vector<AggregationRow>& rows,
                                const std::vector<std::string>& columns, bool all,
                                std::size_t width, std::ostream& out);

}  // namespace flocsim::postprocess
