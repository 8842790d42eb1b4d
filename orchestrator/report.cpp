#include "orchestrator/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "engine/input/input_reader.hpp"
#include "orchestrator/process.hpp"
#include "orchestrator/sweep.hpp"
#include "orchestrator/terminal_table.hpp"

namespace flocsim::orchestrator {

using db::RunState;
using flocsim::input::InputError;
using nlohmann::json;
using nlohmann::ordered_json;

std::string format_with_error(double mean, std::optional<double> error,
                              const std::string& plus_minus) {
  char buf[96];
  if (!std::isfinite(mean)) return mean != mean ? "nan" : (mean > 0 ? "inf" : "-inf");
  if (!error || !(*error > 0) || !std::isfinite(*error)) {
    std::snprintf(buf, sizeof buf, "%.4g", mean);
    return buf;
  }
  // the decimal place of the error's first significant digit, after rounding
  int place = static_cast<int>(std::floor(std::log10(*error)));
  double rounded = std::round(*error / std::pow(10.0, place)) * std::pow(10.0, place);
  place = static_cast<int>(std::floor(std::log10(rounded)));  // 0.0096 -> 0.01
  const int decimals = std::max(0, -place);
  const double unit = std::pow(10.0, place);
  const double m = std::round(mean / unit) * unit;
  std::snprintf(buf, sizeof buf, "%.*f%s%.*f", decimals, m == 0 ? 0.0 : m, plus_minus.c_str(),
                decimals, rounded);
  return buf;
}

namespace {

std::string format_number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string value_text(const json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) return format_number(v.get<double>());
  return v.dump();
}

struct Table {
  std::vector<std::string> columns;
  std::vector<std::string> axes;                  // the sweeps' axes, in order
  std::vector<std::map<std::string, json>> rows;  // column -> value (null when absent)
};

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char ch : s) {
    if (ch == '"') out += '"';
    out += ch;
  }
  return out + "\"";
}

}  // namespace

int write_query(db::ResultsDb& db, const QueryOptions& o, std::ostream& out) {
  if (o.format != "table" && o.format != "csv" && o.format != "json")
    throw InputError("--format " + o.format + ": must be one of table, csv, json");
  // the runs and the filters shared with `flocsim post`
  RunSelection selection = select_runs(db, o.sweep, o.where);
  if (o.left_out)
    for (const DamagedRun& d : selection.damaged)
      *o.left_out << "left out, unreadable: " << printable(d.text()) << "\n";
  Table t{selection.columns, selection.axes, {}};
  std::vector<json> cases;
  for (RunView& r : selection.runs) {
    t.rows.push_back(std::move(r.columns));
    cases.push_back(std::move(r.input_case));
  }
  const std::vector<std::size_t>& keep = selection.selected;
  // Columns no kept row fills (observables of other scenes) are left out.
  std::vector<std::string> cols;
  for (const std::string& c : t.columns) {
    bool any = c == "run" || c == "status";
    for (std::size_t i : keep) {
      auto it = t.rows[i].find(c);
      any = any || (it != t.rows[i].end() && !it->second.is_null());
    }
    if (any) cols.push_back(c);
  }
  if (!o.columns.empty()) {
    std::vector<std::string> chosen;
    for (const std::string& c : o.columns) {
      if (std::find(t.columns.begin(), t.columns.end(), c) == t.columns.end()) {
        std::string all;
        for (const auto& a : t.columns) all += (all.empty() ? "" : ", ") + a;
        throw InputError("--columns " + c + ": no such column (columns: " + all + ")");
      }
      // each value brings its error column; one named as well is not repeated
      auto add = [&chosen](const std::string& name) {
        if (std::find(chosen.begin(), chosen.end(), name) == chosen.end()) chosen.push_back(name);
      };
      add(c);
      const std::string err = c + "_err";
      if (std::find(t.columns.begin(), t.columns.end(), err) != t.columns.end()) add(err);
    }
    cols = chosen;
  }
  if (o.format == "json") {
    ordered_json arr = ordered_json::array();
    for (std::size_t i : keep) {
      ordered_json row = ordered_json::object();
      row["id"] = t.rows[i].at("run");
      for (const std::string& c : cols) {
        if (c == "run") continue;
        auto it = t.rows[i].find(c);
        row[c] = it == t.rows[i].end() ? ordered_json() : ordered_json(it->second);
      }
      row["case"] = cases[i];
      if (!t.rows[i]["error"].get<std::string>().empty()) row["error"] = t.rows[i]["error"];
      arr.push_back(row);
    }
    std::string text;
    try {
      text = arr.dump(2);
    } catch (const json::type_error&) {
      // JSON holds only UTF-8: said, not silent
      text = arr.dump(2, ' ', false, json::error_handler_t::replace);
      if (o.left_out)
        *o.left_out << "bytes that are not UTF-8 in the database are written as U+FFFD\n";
    }
    // C1 and bidirectional controls as JSON's own \uXXXX escapes: the same
    // document, and a terminal shows them rather than obeying them
    out << text::printable_json(text) << "\n";
    return static_cast<int>(keep.size());
  }
  if (o.format == "csv") {
    // as the table shows them (printable): CSV has no escapes of its own for
    // ESC or U+202E, and this may be read on a terminal; --format json keeps
    // every character
    for (std::size_t c = 0; c < cols.size(); ++c)
      out << (c ? "," : "") << csv_field(printable(cols[c]));
    out << "\n";
    for (std::size_t i : keep) {
      for (std::size_t c = 0; c < cols.size(); ++c) {
        auto it = t.rows[i].find(cols[c]);
        out << (c ? "," : "")
            << csv_field(it == t.rows[i].end() ? "" : printable(value_text(it->second)));
      }
      out << "\n";
    }
    return static_cast<int>(keep.size());
  }
  // Aligned table: an observable and its error share a column as "mean ± error".
  std::vector<std::string> shown;
  for (const std::string& c : cols)
    if (!(c.size() > 4 && c.compare(c.size() - 4, 4, "_err") == 0 &&
          std::find(cols.begin(), cols.end(), c.substr(0, c.size() - 4)) != cols.end()))
      shown.push_back(c);
  bool any_flags = false;
  for (std::size_t i : keep)
    any_flags = any_flags || !t.rows[i]["flags"].get<std::string>().empty();
  if (o.columns.empty()) {
    // what a user reads first: the run, its state and point, the settling
    // velocity, drag and aggregation, the flags; then the rest
    static const std::vector<std::string> first{"U_over_Uinf", "F",  "n_a_mean",
                                                "C_sph",       "Re", "Re_T"};
    std::vector<std::string> ordered{"run", "status"};
    auto take = [&](const std::string& c) {
      if (std::find(shown.begin(), shown.end(), c) != shown.end() &&
          std::find(ordered.begin(), ordered.end(), c) == ordered.end())
        ordered.push_back(c);
    };
    for (const std::string& c : t.axes) take(c);
    for (const std::string& c : first) take(c);
    if (any_flags) ordered.push_back("flags");
    for (const std::string& c : shown) take(c);
    shown = ordered;
  }
  std::vector<TerminalColumn> table;
  for (const std::string& c : shown) {
    TerminalColumn col{c, {}};
    for (std::size_t i : keep) {
      auto it = t.rows[i].find(c);
      std::string cell = it == t.rows[i].end() ? "" : value_text(it->second);
      auto e = t.rows[i].find(c + "_err");
      if (e != t.rows[i].end() && !e->second.is_null() && it != t.rows[i].end() &&
          it->second.is_number())
        cell = format_with_error(it->second.get<double>(), e->second.get<double>());
      col.cells.push_back(cell);
    }
    table.push_back(std::move(col));
  }
  const std::vector<std::string> left_out = write_fitted(table, o.width, out);
  out << "(" << keep.size() << " of " << t.rows.size() << " runs";
  if (!selection.damaged.empty())
    out << "; " << selection.damaged.size() << " unreadable row"
        << (selection.damaged.size() > 1 ? "s" : "") << " left out";
  out << ")\n";
  if (any_flags && std::find(shown.begin(), shown.end(), "flags") != shown.end())
    out << "flags: s = a window still drifts (not stationary), u = an error is not reliable "
           "(`--format json` has the details)\n";
  if (!left_out.empty()) {
    std::string names;
    for (const std::string& n : left_out) names += (names.empty() ? "" : ", ") + n;
    out << left_out.size() << " more column" << (left_out.size() == 1 ? "" : "s") << " to fit "
        << o.width << " characters: " << names << " (--all shows every column, --columns "
        << "chooses; csv and json keep them all)\n";
  }
  return static_cast<int>(keep.size());
}

std::string duration_text(double s) {
  char buf[64];
  if (s < 120)
    std::snprintf(buf, sizeof buf, "%.0f s", s);
  else if (s < 7200)
    std::snprintf(buf, sizeof buf, "%.1f min", s / 60);
  else if (s < 5 * 86400)
    std::snprintf(buf, sizeof buf, "%.1f h", s / 3600);
  else
    std::snprintf(buf, sizeof buf, "%.1f days", s / 86400);
  return buf;
}

std::optional<SweepEta> estimate_sweep_eta(const std::vector<double>& completed_wall_s,
                                           const std::vector<RunningProgress>& running,
                                           int waiting) {
  if (running.empty() && waiting == 0) return std::nullopt;
  SweepEta eta;
  eta.lanes = std::max<int>(static_cast<int>(running.size()), 1);
  for (const RunningProgress& r : running) {
    if (!r.eta_s || *r.eta_s < 0) return std::nullopt;  // a worker writes -1 before it has a rate
    eta.remaining_s = std::max(eta.remaining_s, *r.eta_s);
  }
  if (waiting == 0) return eta;
  if (!completed_wall_s.empty()) {
    double sum = 0;
    for (double w : completed_wall_s) sum += w;
    eta.per_run_s = sum / static_cast<double>(completed_wall_s.size());
  } else {
    // A whole run at each running attempt's current rate; attempts that have
    // not yet measured a rate (no progress) say nothing.
    double sum = 0;
    int n = 0;
    for (const RunningProgress& r : running)
      if (r.fraction > 0 && r.fraction < 1) sum += *r.eta_s / (1 - r.fraction), ++n;
    if (n == 0) return std::nullopt;
    eta.per_run_s = sum / n;
    eta.from_running_rate = true;
  }
  eta.remaining_s += waiting * eta.per_run_s / eta.lanes;
  return eta;
}

namespace {

// Columns padded to their widest cell, two spaces apart, indented.
void write_columns(const std::vector<std::vector<std::string>>& given, const std::string& indent,
                   std::ostream& out) {
  // as a terminal should show them: errors and points carry text from files
  std::vector<std::vector<std::string>> rows = given;
  for (auto& row : rows)
    for (std::string& cell : row) cell = printable(cell);
  auto width = [](const std::string& s) {
    std::size_t w = 0;
    for (unsigned char ch : s) w += (ch & 0xC0) != 0x80;
    return w;
  };
  std::vector<std::size_t> w;
  for (const auto& row : rows)
    for (std::size_t i = 0; i < row.size(); ++i) {
      if (w.size() <= i) w.push_back(0);
      w[i] = std::max(w[i], width(row[i]));
    }
  for (const auto& row : rows) {
    std::string line = indent;
    for (std::size_t i = 0; i < row.size(); ++i)
      line += row[i] + (i + 1 < row.size() ? std::string(w[i] - width(row[i]) + 2, ' ') : "");
    line.erase(line.find_last_not_of(' ') + 1);
    out << line << "\n";
  }
}

std::string first_line(const std::string& text, std::size_t most = 160) {
  std::string line = text.substr(0, text.find('\n'));
  if (line.size() > most) line = line.substr(0, most - 3) + "...";
  return line;
}

}  // namespace

bool write_status(db::ResultsDb& db, const std::optional<std::string>& sweep_name,
                  std::ostream& out) {
  bool active = false;
  std::vector<db::SweepRecord> sweeps;
  if (sweep_name) {
    auto s = db.find_sweep(*sweep_name);
    if (!s) throw InputError("--sweep " + *sweep_name + ": no such sweep in " + db.path());
    sweeps.push_back(*s);
  } else {
    sweeps = db.sweeps();
  }
  if (sweeps.empty()) out << "no sweeps in " << printable(db.path()) << "\n";
  const double now = db::unix_now();
  std::map<std::string, db::AttemptRecord> live;
  for (db::AttemptRecord& a : db.live_attempts()) live[a.run_id] = a;
  for (const db::SweepRecord& s : sweeps) {
    const auto runs = db.runs(s.id);
    // lost and recovered: runs now lost, and completed runs that were lost before
    int recovered = 0, lost_attempts = 0;
    for (const db::RunRecord& r : runs) {
      bool was_lost = false;
      for (const db::AttemptRecord& a : db.attempts(r.id))
        if (a.state == RunState::kLost) was_lost = true, ++lost_attempts;
      if (was_lost && r.status == RunState::kCompleted) ++recovered;
    }
    out << "sweep " << printable(s.name) << ": " << runs.size() << " runs:";
    int lost_now = 0;
    for (const db::StateCount& c : db.count_states(s.id)) {
      if (c.status == RunState::kLost) lost_now = c.runs;
      if (c.runs > 0 || c.status == RunState::kCompleted || c.status == RunState::kPending)
        out << " " << c.status << " " << c.runs;
    }
    out << "; lost " << lost_now << " (" << lost_attempts << " attempt"
        << (lost_attempts == 1 ? "" : "s") << " lost in all), recovered " << recovered << "\n";
    std::vector<double> completed_wall_s;
    int waiting = 0;
    for (const db::ResultsDb::ResultRow& r : db.result_rows(s.id)) {
      if (r.wall_s) completed_wall_s.push_back(*r.wall_s);
      if (r.run.status == RunState::kPending || r.run.status == RunState::kInterrupted ||
          r.run.status == RunState::kLost)
        ++waiting;
    }
    // Running runs: where each stands (stage and simulated time from its
    // progress.json, which Slurm jobs write on the shared file system too).
    std::vector<RunningProgress> progress;
    std::vector<std::vector<std::string>> table{
        {"run", "point", "stage", "time", "done", "ETA", "MLUPS", "worker", "heartbeat"}};
    for (const db::RunRecord& r : runs) {
      auto it = live.find(r.id);
      if (it == live.end()) continue;
      db::AttemptRecord a = it->second;
      // the worker's own progress.json is fresher than the database's copy
      // (written every few seconds by a local pool, by a Slurm task on its node)
      if (const auto beat = read_progress(r.run_dir); beat && beat->at >= a.started_at) {
        a.fraction = beat->fraction ? beat->fraction : a.fraction;
        a.eta_s = beat->eta_s ? beat->eta_s : a.eta_s;
        a.mlups = beat->mlups ? beat->mlups : a.mlups;
        a.heartbeat_at = std::max(a.heartbeat_at.value_or(0), beat->at);
      }
      const RunStage stage = read_run_stage(r.run_dir);
      char time[64] = "-", done[32], mlups[32] = "-";
      if (stage.time && stage.time_total)
        std::snprintf(time, sizeof time, "%.1f/%.0f %s", *stage.time, *stage.time_total,
                      stage.time_unit.c_str());
      else if (stage.time)
        std::snprintf(time, sizeof time, "%.1f %s", *stage.time, stage.time_unit.c_str());
      std::snprintf(done, sizeof done, "%.1f%%", 100 * a.fraction.value_or(0));
      if (a.mlups) std::snprintf(mlups, sizeof mlups, "%.3g", *a.mlups);
      const double beat = a.heartbeat_at.value_or(a.started_at);
      table.push_back(
          {r.id.substr(0, 12), point_text(r.point_json), stage.stage.empty() ? "-" : stage.stage,
           time, done, a.eta_s && *a.eta_s >= 0 ? duration_text(*a.eta_s) : "?", mlups,
           a.host + " pid " + std::to_string(a.pid) + (a.job_id.empty() ? "" : " job " + a.job_id),
           duration_text(now - beat) + " ago"});
      progress.push_back({a.fraction.value_or(0), a.eta_s});
    }
    const int running = static_cast<int>(progress.size());
    if (running > 0) {
      out << "  running (" << running << "):\n";
      write_columns(table, "    ", out);
    }
    // Runs that did not finish, with the first line of why and what to do.
    std::vector<std::vector<std::string>> stopped;
    bool retryable = false, exhausted_any = false, refused_any = false;
    for (const db::RunRecord& r : runs) {
      if (r.status != RunState::kFailed && r.status != RunState::kRefused &&
          r.status != RunState::kLost && r.status != RunState::kInterrupted)
        continue;
      const bool exhausted = r.status == RunState::kFailed && r.failures >= s.max_attempts;
      if (r.status == RunState::kRefused)
        refused_any = true;
      else if (exhausted)
        exhausted_any = true;
      else
        retryable = true;
      stopped.push_back(
          {to_string(r.status), r.id.substr(0, 12), point_text(r.point_json),
           "attempts " + std::to_string(r.attempts) + (exhausted ? ", retry limit reached" : ""),
           first_line(r.error)});
    }
    if (!stopped.empty()) {
      out << "  not finished (" << stopped.size() << "):\n";
      write_columns(stopped, "    ", out);
      if (retryable)
        out << "    retry the failed, lost and interrupted runs (from their checkpoints): "
            << "flocsim sweep resume --db " << shell_word(db.path()) << " --sweep "
            << shell_word(s.name) << "\n";
      if (exhausted_any)
        out << "    runs at the retry limit (max_attempts " << s.max_attempts
            << ") are not retried: raise max_attempts in the sweep file and launch it again "
               "(flocsim sweep launch SWEEP.json --db "
            << shell_word(db.path()) << ")\n";
      if (refused_any)
        out << "    refused runs are not retried: change the case as the message says\n";
    }
    active = active || running > 0;
    if (running > 0 || waiting > 0) {
      const std::optional<SweepEta> eta = estimate_sweep_eta(completed_wall_s, progress, waiting);
      if (!eta) {
        out << (running > 0 ? "  ETA: unknown until the running runs report progress\n"
                            : "  ETA: unknown until a run completes\n");
      } else if (waiting == 0) {
        out << "  ETA: about " << duration_text(eta->remaining_s) << "\n";
      } else if (running == 0) {
        out << "  ETA: about " << duration_text(eta->remaining_s)
            << " once resumed, one run at a time (" << waiting << " waiting at "
            << duration_text(eta->per_run_s) << " each; nothing is running now)\n";
      } else {
        out << "  ETA: about " << duration_text(eta->remaining_s) << " (" << waiting
            << " waiting at " << duration_text(eta->per_run_s) << " each"
            << (eta->from_running_rate ? " at the running rate, no run completed yet" : "") << ", "
            << eta->lanes << " worker" << (eta->lanes > 1 ? "s" : "") << ")\n";
      }
    }
  }
  return active;
}

}  // namespace flocsim::orchestrator
