#include "postprocess/tables.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include "engine/case/suspension_case.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/observables/reference_correlations.hpp"
#include "engine/result_names/result_names.hpp"
#include "orchestrator/sweep.hpp"
#include "orchestrator/terminal_table.hpp"
#include "postprocess/paper_values.hpp"

namespace flocsim::postprocess {

using json = nlohmann::json;

namespace {

std::optional<Measured> observable(const db::ResultsDb::ResultRow& r, const std::string& name) {
  for (const db::Observable& o : r.observables)
    if (o.name == name) return Measured{o.mean, o.error};
  return std::nullopt;
}

double number_at(const json& j, const std::string& path, double fallback) {
  const auto v = orchestrator::get_path(j, path);
  return v && v->is_number() ? v->get<double>() : fallback;
}

// The case's identity with the attraction switched off: what its baseline has.
std::string baseline_key(const json& case_json) {
  json c = case_json;
  c["du_over_Uinf"] = 0;
  return orchestrator::canonical_text(c);
}

}  // namespace

namespace {

// What the tables need from one readable run (orchestrator::select_runs has
// checked the types of every field read here).
RunSummary summary_of(const orchestrator::RunView& v) {
  const db::ResultsDb::ResultRow& r = v.row;
  RunSummary u;
  u.id = r.run.id;
  u.status = r.run.status;
  u.run_dir = r.run.run_dir;
  u.sweep = v.sweep;
  u.case_json = v.input_case;
  u.phi = number_at(u.case_json, "phi", 0);
  u.re_inf = number_at(u.case_json, "Re_inf", 0);
  u.du = number_at(u.case_json, "du_over_Uinf", 0);
  u.fidelity = u.case_json.value("fidelity", std::string("standard"));
  u.has_result = r.has_result;
  u.wall_s = r.wall_s;
  u.flocsim_version = r.flocsim_version;
  u.U_over_Uinf = observable(r, "U_over_Uinf");
  u.F = observable(r, "F");
  u.Re = observable(r, "Re");
  u.Re_T = observable(r, "Re_T");
  u.C_sph = observable(r, "C_sph");
  u.n_a = observable(r, "n_a_mean");
  if (v.result.is_object()) {
    const json& res = v.result;
    const json& obs = res.value("observables", json::object());
    for (const std::string_view summary : result_names::kSummaryObservables) {
      const std::string name(summary);
      if (obs.contains(name) && obs[name].is_object() && !obs[name].value("error_reliable", true))
        u.errors_reliable = false;
    }
    for (const auto& n : res.value("not_stationary", json::array()))
      if (n.is_string()) u.not_stationary.push_back(n.get<std::string>());
    if (obs.contains("window") && obs["window"].is_object()) {
      u.window_start = obs["window"].value("start", 0.0);
      u.window_end = obs["window"].value("end", 0.0);
    }
    if (res.contains("case") && res["case"].is_object()) {
      // as the current version writes it (older results lack fields that
      // had one value then), so that only a real difference counts
      const json rc = cases::with_older_versions_models(res["case"]);
      const json lubrication = rc.value("lubrication_model", json());
      const json numerics = rc.value("numerics", json::object());
      u.resolved_models =
          "lubrication_model " +
          (lubrication.is_string() ? lubrication.get<std::string>() : std::string("none")) +
          ", immersed boundary " +
          (numerics.is_object() ? numerics.value("immersed_boundary", json()) : json()).dump();
    }
    u.sphere_count = res.value("derived", json::object()).value("sphere_count", 0);
    if (u.phi == 0) u.phi = res.value("derived", json::object()).value("phi_realised", 0.0);
  }
  return u;
}

}  // namespace

std::vector<RunSummary> load_runs(db::ResultsDb& db, const std::optional<std::string>& sweep,
                                  const std::vector<orchestrator::Filter>& where,
                                  std::vector<orchestrator::DamagedRun>* left_out) {
  // the same selection as `flocsim query`
  const orchestrator::RunSelection chosen = orchestrator::select_runs(db, sweep, where);
  if (left_out) *left_out = chosen.damaged;
  // A baseline is the same case: looked up in the whole database, also where
  // the selection (a sweep, a filter on du) leaves it out.
  const orchestrator::RunSelection whole =
      sweep || !where.empty() ? orchestrator::select_runs(db, std::nullopt, {}) : chosen;
  std::map<std::string, std::vector<std::shared_ptr<const RunSummary>>> zero_du;
  for (const orchestrator::RunView& v : whole.runs) {
    auto b = std::make_shared<RunSummary>(summary_of(v));
    // keyed like the lookup below, so that a case that leaves du_over_Uinf
    // at its default 0 is found too
    if (b->du == 0) zero_du[baseline_key(b->case_json)].push_back(b);
  }
  for (const orchestrator::DamagedRun& d : whole.damaged) {
    if (!d.input_case.is_object() || number_at(d.input_case, "du_over_Uinf", 0) != 0) continue;
    auto b = std::make_shared<RunSummary>();
    b->id = d.run_id;
    b->sweep = d.sweep;
    b->case_json = d.input_case;
    b->damage = d.field + " " + d.problem;
    zero_du[baseline_key(b->case_json)].push_back(b);
  }
  std::vector<RunSummary> out;
  for (std::size_t i : chosen.selected) {
    RunSummary u = summary_of(chosen.runs[i]);
    if (u.du > 0)
      if (const auto it = zero_du.find(baseline_key(u.case_json)); it != zero_du.end())
        u.zero_du_runs = it->second;
    out.push_back(std::move(u));
  }
  return out;
}

Measured ratio(const Measured& a, const Measured& b) {
  Measured r{a.mean / b.mean, std::nullopt};
  if (a.error && b.error)
    r.error = std::abs(r.mean) * std::hypot(*a.error / a.mean, *b.error / b.mean);
  return r;
}

std::vector<AggregationRow> aggregation_table(const std::vector<RunSummary>& runs) {
  std::vector<AggregationRow> rows;
  for (const RunSummary& r : runs) {
    if (r.du <= 0) continue;
    AggregationRow row;
    row.run = &r;
    row.n_a_paper = paper_mean_aggregate_size(r.phi, r.re_inf, r.du);
    // the paper gives no error: the ratio carries flocsim's alone
    if (row.n_a_paper && r.n_a) row.n_over_paper = ratio(*r.n_a, {*row.n_a_paper, 0.0});
    row.n_over_n0_paper = paper_normalised_size(r.phi, r.re_inf, r.du);
    // The same input case may have resolved to other models under another
    // version (a changed default): such a pair is not a ratio of one model.
    auto same_models = [&r](const RunSummary* b) {
      return r.resolved_models.empty() || b->resolved_models.empty() ||
             r.resolved_models == b->resolved_models;
    };
    auto usable = [](const RunSummary* b) {
      return b->damage.empty() && b->status == db::RunState::kCompleted && b->F && b->n_a;
    };
    // the first du = 0 run of the case that can serve (completed, same
    // models); else the first one, to say why it cannot
    const RunSummary* base = nullptr;
    for (const auto& b : r.zero_du_runs)
      if (!base && usable(b.get()) && same_models(b.get())) base = b.get();
    if (!base && !r.zero_du_runs.empty()) base = r.zero_du_runs.front().get();
    const bool other_models = base && !same_models(base);
    if (r.status != db::RunState::kCompleted || !r.F || !r.n_a) {
      row.reason = "this run is " + to_string(r.status) + (r.has_result ? " (no F or <n_a>)" : "");
    } else if (!base) {
      row.reason =
          "no du = 0 run of the same case (same phi, Re_inf, fidelity, numerics, box, seed and "
          "protocol) in the database";
    } else if (!base->damage.empty()) {
      row.reason = "its du = 0 run " + base->id.substr(0, 12) +
                   " cannot be read and is left out (" + base->damage + ")";
    } else if (other_models) {
      row.reason = "its du = 0 run " + base->id.substr(0, 12) + " ran with " +
                   base->resolved_models + ", this one with " + r.resolved_models +
                   " (defaults of different flocsim versions); name them in the sweep's base";
    } else if (!usable(base)) {
      row.reason = "its baseline " + base->id.substr(0, 12) + " is " + to_string(base->status);
    } else {
      row.baseline = base;
      row.F_over_F0 = ratio(*r.F, *base->F);
      row.n_over_n0 = ratio(*r.n_a, *base->n_a);
    }
    rows.push_back(row);
  }
  return rows;
}

std::vector<NonAggregatingRow> non_aggregating_table(const std::vector<RunSummary>& runs) {
  std::vector<NonAggregatingRow> rows;
  for (const RunSummary& r : runs) {
    if (r.du != 0 || r.status != db::RunState::kCompleted || !r.F || !r.Re) continue;
    NonAggregatingRow row;
    row.run = &r;
    row.beetstra = observables::beetstra_drag(r.phi, r.Re->mean);
    row.wylie = observables::wylie_drag(r.phi, r.Re->mean, r.Re_T ? r.Re_T->mean : 0.0);
    row.richardson_zaki = observables::richardson_zaki_velocity_ratio(r.phi, r.re_inf);
    rows.push_back(row);
  }
  return rows;
}

namespace {

// A cell writer for the three formats: CSV keeps full precision with the
// error in its own column, Markdown and LaTeX round a mean to its error.
struct Writer {
  std::string format;
  std::ostream& out;
  std::vector<std::string> cells;
  // when set, rows (header first) are collected here as Markdown would show
  // their cells, instead of being written
  std::vector<std::vector<std::string>>* grid = nullptr;

  static std::string number(double v) {
    char b[40];
    std::snprintf(b, sizeof b, "%.10g", v);
    return b;
  }
  void text(const std::string& s) { cells.push_back(s); }
  void value(double v, int digits = 4) {
    char b[40];
    std::snprintf(b, sizeof b, "%.*g", digits, v);
    cells.push_back(format == "csv" ? number(v) : b);
  }
  void measured(const std::optional<Measured>& m) {
    if (format == "csv") {
      cells.push_back(m ? number(m->mean) : "");
      cells.push_back(m && m->error ? number(*m->error) : "");
      return;
    }
    cells.push_back(
        m ? orchestrator::format_with_error(m->mean, m->error, format == "tex" ? " \\pm " : " ± ")
          : "");
    if (format == "tex" && m) cells.back() = "$" + cells.back() + "$";
  }
  void header(const std::vector<std::string>& names, const std::vector<bool>& with_error) {
    for (std::size_t i = 0; i < names.size(); ++i) {
      cells.push_back(names[i]);
      if (format == "csv" && with_error[i]) cells.push_back(names[i] + "_err");
    }
    if (format == "tex" && !grid) {
      out << "\\begin{tabular}{" << std::string(cells.size(), 'l') << "}\n\\toprule\n";
    }
    end_row();
    if (grid) return;
    if (format == "md") {
      out << "|";
      for (std::size_t i = 0; i < names.size(); ++i) out << "---|";
      out << "\n";
    }
    if (format == "tex") out << "\\midrule\n";
  }
  void end_row() {
    if (grid) {
      grid->push_back(cells);
      cells.clear();
      return;
    }
    for (std::size_t i = 0; i < cells.size(); ++i) {
      std::string c = cells[i];
      if (format == "csv" && c.find_first_of(",\"\n") != std::string::npos) {
        std::string q = "\"";
        for (char ch : c) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
        c = q + "\"";
      }
      if (format == "tex") {
        std::string e;
        for (char ch : c)
          e += (ch == '_' || ch == '%' || ch == '&' || ch == '#') ? std::string("\\") + ch
                                                                  : std::string(1, ch);
        if (c.size() > 1 && c.front() == '$') e = c;  // already math
        c = e;
      }
      if (format == "md")
        out << (i ? " | " : "| ") << c;
      else if (format == "tex")
        out << (i ? " & " : "") << c;
      else
        out << (i ? "," : "") << c;
    }
    if (format == "md") out << " |";
    if (format == "tex") out << " \\\\";
    out << "\n";
    cells.clear();
  }
  void finish() {
    if (format == "tex" && !grid) out << "\\bottomrule\n\\end{tabular}\n";
  }
};

std::string yes_no(bool b) {
  return b ? "yes" : "no";
}

// A run with no result yet (pending, running, failed) has neither verdict: blank, not "yes".
std::string reliable_text(const RunSummary& r) {
  return r.has_result ? yes_no(r.errors_reliable) : "";
}

std::string stationary_text(const RunSummary& r) {
  if (!r.has_result) return "";
  if (r.not_stationary.empty()) return "yes";
  std::string s = "no:";
  for (const auto& n : r.not_stationary) s += " " + n;
  return s;
}

// "about 7.6" at the stated case's own du, else the interval its text implies:
// "at most 2.3", "at least 7.6" or "2.44-7.6" (words and ASCII, which every
// format carries unescaped).
std::string paper_bound_text(const PaperNormalisedSize& p) {
  char b[80];
  if (p.about)
    std::snprintf(b, sizeof b, "about %.3g", p.low);
  else if (std::isinf(p.high))
    std::snprintf(b, sizeof b, "at least %.3g", p.low);
  else if (p.low <= 1)
    std::snprintf(b, sizeof b, "at most %.3g", p.high);
  else
    std::snprintf(b, sizeof b, "%.3g-%.3g", p.low, p.high);
  return b;
}

std::string window_text(const RunSummary& r) {
  if (r.window_end <= r.window_start) return "";
  char b[64];
  std::snprintf(b, sizeof b, "%.0f-%.0f", r.window_start, r.window_end);
  return b;
}

}  // namespace

namespace {

void fill_aggregation(Writer& w, const std::vector<AggregationRow>& rows) {
  w.header({"phi",
            "Re_inf",
            "du_over_Uinf",
            "Re",
            "F",
            "F0",
            "F_over_F0",
            "n_a",
            "n_a0",
            "n_a_over_n_a0",
            "n_a_paper",
            "n_a_over_paper",
            "n_a_over_n_a0_paper",
            "U_over_Uinf",
            "C_sph",
            "Re_T",
            "window",
            "N",
            "errors_reliable",
            "stationary",
            "run",
            "baseline",
            "note"},
           {false, false, false, true, true,  true,  true,  true,  true,  true,  false, true,
            false, true,  true,  true, false, false, false, false, false, false, false});
  for (const AggregationRow& row : rows) {
    const RunSummary& r = *row.run;
    const RunSummary* b = row.baseline;
    w.value(r.phi, 3);
    w.value(r.re_inf, 3);
    w.value(r.du, 3);
    w.measured(r.Re);
    w.measured(r.F);
    w.measured(b ? b->F : std::nullopt);
    w.measured(row.F_over_F0);
    w.measured(r.n_a);
    w.measured(b ? b->n_a : std::nullopt);
    w.measured(row.n_over_n0);
    if (row.n_a_paper)
      w.value(*row.n_a_paper);
    else
      w.text("");
    w.measured(row.n_over_paper);
    w.text(row.n_over_n0_paper ? paper_bound_text(*row.n_over_n0_paper) : "");
    w.measured(r.U_over_Uinf);
    w.measured(r.C_sph);
    w.measured(r.Re_T);
    w.text(window_text(r));
    w.text(r.sphere_count ? std::to_string(r.sphere_count) : "");
    w.text(b && r.has_result ? yes_no(r.errors_reliable && b->errors_reliable) : reliable_text(r));
    w.text(b && !b->not_stationary.empty()
               ? stationary_text(r) + "; baseline " + stationary_text(*b)
               : stationary_text(r));
    w.text(r.id.substr(0, 12));
    w.text(b ? b->id.substr(0, 12) : "");
    w.text(row.reason);
    w.end_row();
  }
  w.finish();
}

void fill_non_aggregating(Writer& w, const std::vector<NonAggregatingRow>& rows) {
  w.header({"phi", "Re_inf", "Re", "F", "Re_T", "F_Beetstra", "dev_Beetstra_pct", "F_Wylie",
            "dev_Wylie_pct", "U_over_Uinf", "U_over_Uinf_RZ", "dev_RZ_pct", "window", "N",
            "errors_reliable", "stationary", "run"},
           {false, false, true, true, true, false, false, false, false, true, false, false, false,
            false, false, false, false});
  for (const NonAggregatingRow& row : rows) {
    const RunSummary& r = *row.run;
    w.value(r.phi, 3);
    w.value(r.re_inf, 3);
    w.measured(r.Re);
    w.measured(r.F);
    w.measured(r.Re_T);
    w.value(row.beetstra);
    w.value(100 * (r.F->mean / row.beetstra - 1), 3);
    w.value(row.wylie);
    w.value(100 * (r.F->mean / row.wylie - 1), 3);
    w.measured(r.U_over_Uinf);
    w.value(row.richardson_zaki);
    if (r.U_over_Uinf)
      w.value(100 * (r.U_over_Uinf->mean / row.richardson_zaki - 1), 3);
    else
      w.text("");
    w.text(window_text(r));
    w.text(r.sphere_count ? std::to_string(r.sphere_count) : "");
    w.text(reliable_text(r));
    w.text(stationary_text(r));
    w.text(r.id.substr(0, 12));
    w.end_row();
  }
  w.finish();
}

}  // namespace

void write_aggregation(const std::vector<AggregationRow>& rows, const std::string& format,
                       std::ostream& out) {
  Writer w{format, out, {}};
  fill_aggregation(w, rows);
}

void write_non_aggregating(const std::vector<NonAggregatingRow>& rows, const std::string& format,
                           std::ostream& out) {
  Writer w{format, out, {}};
  fill_non_aggregating(w, rows);
}

std::vector<std::vector<std::string>> aggregation_cells(const std::vector<AggregationRow>& rows) {
  std::ostringstream unused;
  std::vector<std::vector<std::string>> grid;
  Writer w{"md", unused, {}, &grid};
  fill_aggregation(w, rows);
  return grid;
}

std::vector<std::vector<std::string>> non_aggregating_cells(
    const std::vector<NonAggregatingRow>& rows) {
  std::ostringstream unused;
  std::vector<std::vector<std::string>> grid;
  Writer w{"md", unused, {}, &grid};
  fill_non_aggregating(w, rows);
  return grid;
}

RowFlags run_flags(const RunSummary& r, const RunSummary* baseline) {
  RowFlags f;
  if (!r.has_result) return f;
  const bool reliable = r.errors_reliable && (!baseline || baseline->errors_reliable);
  if (!reliable) {
    f.marks += "u";
    f.detail += "u: errors not reliable (fewer than 5 batches of at least 5 correlation times";
    f.detail += baseline ? ", in this run or its baseline)" : ")";
  }
  std::string drifting;
  if (!r.not_stationary.empty()) drifting = stationary_text(r).substr(4);
  if (baseline && !baseline->not_stationary.empty())
    drifting += (drifting.empty() ? "" : "; ") + std::string("baseline:") +
                stationary_text(*baseline).substr(3);
  if (!drifting.empty()) {
    f.marks += "s";
    f.detail += std::string(f.detail.empty() ? "" : "\n") + "s: not stationary: " + drifting;
  }
  return f;
}

RowFlags aggregation_flags(const AggregationRow& row) {
  RowFlags f = run_flags(*row.run, row.baseline);
  if (!row.reason.empty()) {
    f.marks += "b";
    f.detail += std::string(f.detail.empty() ? "" : "\n") + "b: no F/F0: " + row.reason;
  }
  return f;
}

std::string column_label(const std::string& name, bool html) {
  struct Label {
    const char *name, *text, *html;
  };
  static const Label labels[] = {
      {"phi", "phi", "&phi;"},
      {"Re_inf", "Re_inf", "Re<sub>&infin;</sub>"},
      {"du_over_Uinf", "du/U_inf", "du/U<sub>&infin;</sub>"},
      {"Re", "Re", "Re"},
      {"F", "F", "F"},
      {"F0", "F0", "F<sub>0</sub>"},
      {"F_over_F0", "F/F0", "F/F<sub>0</sub>"},
      {"n_a", "<n_a>", "&lang;n<sub>a</sub>&rang;"},
      {"n_a0", "<n_a>0", "&lang;n<sub>a</sub>&rang;<sub>0</sub>"},
      {"n_a_over_n_a0", "<n_a>/<n_a>0",
       "&lang;n<sub>a</sub>&rang;/&lang;n<sub>a</sub>&rang;<sub>0</sub>"},
      {"n_a_paper", "<n_a> paper", "&lang;n<sub>a</sub>&rang; paper"},
      {"n_a_over_paper", "<n_a>/paper", "&lang;n<sub>a</sub>&rang; / paper"},
      {"n_a_over_n_a0_paper", "<n_a>/<n_a>0 paper",
       "&lang;n<sub>a</sub>&rang;/&lang;n<sub>a</sub>&rang;<sub>0</sub> paper"},
      {"U_over_Uinf", "U/U_inf", "U/U<sub>&infin;</sub>"},
      {"C_sph", "C_sph", "C<sub>sph</sub>"},
      {"Re_T", "Re_T", "Re<sub>T</sub>"},
      {"window", "window (a/U_inf)", "window (a/U<sub>&infin;</sub>)"},
      {"N", "N", "N"},
      {"errors_reliable", "errors reliable", "errors reliable"},
      {"stationary", "stationary", "stationary"},
      {"run", "run", "run"},
      {"baseline", "baseline", "baseline"},
      {"note", "note", "note"},
      {"F_Beetstra", "F Beetstra", "F<sub>Beetstra</sub>"},
      {"dev_Beetstra_pct", "F/F_Beetstra - 1 (%)", "F/F<sub>Beetstra</sub> &minus; 1 (%)"},
      {"F_Wylie", "F Wylie", "F<sub>Wylie</sub>"},
      {"dev_Wylie_pct", "F/F_Wylie - 1 (%)", "F/F<sub>Wylie</sub> &minus; 1 (%)"},
      {"U_over_Uinf_RZ", "U/U_inf R-Z", "U/U<sub>&infin;</sub> R&ndash;Z"},
      {"dev_RZ_pct", "U/U_RZ - 1 (%)", "U/U<sub>RZ</sub> &minus; 1 (%)"},
      {"flags", "flags", "flags"},
  };
  for (const Label& l : labels)
    if (name == l.name) return html ? l.html : l.text;
  return name;
}

const std::vector<std::string>& aggregation_first_columns() {
  static const std::vector<std::string> first{"phi",       "Re_inf",        "du_over_Uinf",
                                              "F_over_F0", "n_a_over_n_a0", "U_over_Uinf"};
  return first;
}

void write_aggregation_terminal(const std::vector<AggregationRow>& rows,
                                const std::vector<std::string>& columns, bool all,
                                std::size_t width, std::ostream& out) {
  const auto grid = aggregation_cells(rows);
  const std::vector<std::string>& names = grid.front();
  std::vector<std::string> wanted = columns;
  if (all) wanted = names;
  if (wanted.empty()) wanted = aggregation_first_columns();
  std::vector<orchestrator::TerminalColumn> table;
  for (const std::string& name : wanted) {
    if (name == "flags") continue;
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) {
      std::string known;
      for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
      throw input::InputError("--columns " + name + ": no such column (columns: " + known +
                              ", flags)");
    }
    const std::size_t c = static_cast<std::size_t>(it - names.begin());
    orchestrator::TerminalColumn col{column_label(name, false), {}};
    for (std::size_t r = 1; r < grid.size(); ++r) col.cells.push_back(grid[r][c]);
    table.push_back(std::move(col));
  }
  // the flags follow the first columns (they stand for the verdict columns)
  orchestrator::TerminalColumn flags{"flags", {}};
  std::string seen;
  for (const AggregationRow& row : rows) {
    flags.cells.push_back(aggregation_flags(row).marks);
    for (char m : flags.cells.back())
      if (seen.find(m) == std::string::npos) seen += m;
  }
  // by default only where a row has a mark; always when asked for
  const bool show_flags = (columns.empty() && !seen.empty()) ||
                          std::find(columns.begin(), columns.end(), "flags") != columns.end();
  if (show_flags) {
    // right after the first-read columns, so that fitting never drops it first
    const std::size_t at = std::min(table.size(), aggregation_first_columns().size());
    table.insert(table.begin() + static_cast<long>(columns.empty() ? at : table.size()), flags);
  }
  const std::vector<std::string> left_out = orchestrator::write_fitted(table, width, out);
  if (show_flags && !seen.empty()) {
    out << "flags:";
    if (seen.find('u') != std::string::npos) out << " u = errors not reliable;";
    if (seen.find('s') != std::string::npos) out << " s = a window still drifts;";
    if (seen.find('b') != std::string::npos) out << " b = no F/F0 (the note column says why);";
    out << " details in aggregation.md\n";
  }
  if (!left_out.empty()) {
    std::string n;
    for (const auto& h : left_out) n += (n.empty() ? "" : ", ") + h;
    out << left_out.size() << " column" << (left_out.size() == 1 ? "" : "s") << " left out to fit "
        << width << " characters: " << n << "\n";
  }
}

std::string column_definitions() {
  return R"(# Columns of the flocsim post tables

All quantities are dimensionless (paper section 2 and docs/model.md).

| column | meaning |
|---|---|
| phi | solids volume fraction of the case |
| Re_inf | single-sphere settling Reynolds number U_inf 2a / nu (input) |
| du_over_Uinf | square-well strength: escape velocity over U_inf (input) |
| Re | U 2a / nu, U the superficial slip velocity (1 - phi)(<u> - <u_p>) |
| F | drag per sphere F_h / (6 pi rho nu a U), F_h = f (4/3) pi a^3 (1/phi - 1) |
| F0 | F of the baseline: the same case with du_over_Uinf = 0 |
| F_over_F0 | F / F0 |
| n_a | mass-weighted mean aggregate size <n_a> (spheres within 2(a + delta) are bonded) |
| n_a0 | <n_a> of the baseline (du = 0: clusters of spheres that merely touch) |
| n_a_over_n_a0 | <n_a> / <n_a>0 |
| n_a_paper | the paper's <n_a> where its text states one (Fig. 9: phi 0.2, Re_inf 12, du/U_inf 0.01, 0.02, 0.03; a = 6, N = 1320; no error given) |
| n_a_over_paper | n_a / n_a_paper, with flocsim's error only |
| n_a_over_n_a0_paper | what the paper's text fixes about its <n_a>/<n_a>0 for this phi and Re_inf (its default box, a = 6): "about" its stated value at the stated du (about 2.3 at phi 0.12 for (Re_inf, du/U_inf) = (72, 0.03), (24, 0.025), (12, 0.02), and (6, 0.05), not used: 0.05 is outside the du range it simulated; about 7.6 at phi 0.20 for (48, 0.03), (12, 0.025), (6, 0.02)); at another du the interval that implies, because <n_a> grows with du while <n_a>0 does not depend on it (at most the stated value below its du, at least above; at phi 0.2, Re_inf 12 also the Fig. 9 values over the implied <n_a>0 range 1.57-4.88) |
| U_over_Uinf | U / U_inf |
| C_sph | contacts per sphere: other centres within 2(a + delta) |
| Re_T | T^(1/2) 2a / nu, T the granular temperature |
| window | statistics window, t U_inf / a |
| N | number of spheres |
| errors_reliable | every batch of the batch-means errors spans at least 5 correlation times (for the pair: in both runs) |
| stationary | "yes", or "no:" with the observables whose window still drifts (|z| > 3 on a fitted trend whose change over the window exceeds 1e-4 of the mean) |
| F_Beetstra | Beetstra et al. (2007), paper eq. 4, at the run's phi and Re (static random arrays) |
| F_Wylie | Wylie et al. (2003), paper eq. 5, at the run's phi, Re and Re_T |
| U_over_Uinf_RZ | Richardson-Zaki (1 - phi)^n, n from Re_inf |
| dev_*_pct | 100 (measured / reference - 1) |
| run, baseline | the first 12 hex digits of the runs' ids (flocsim query shows them) |
| note | why a run has no F/F0: it did not complete, or has no usable baseline |

Errors (CSV columns *_err, "±" elsewhere) are batch-means standard errors of the mean. A ratio
r = a / b of two runs carries e_r = |r| sqrt((e_a / a)^2 + (e_b / b)^2): first-order propagation
for independent runs. Markdown and LaTeX show each mean rounded to its error's first significant
digit; CSV keeps full precision.
)";
}

}  // namespace flocsim::postprocess
