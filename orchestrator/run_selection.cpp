#include "orchestrator/run_selection.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>

#include "engine/case/resolved_case.hpp"
#include "engine/case/suspension_case.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/result_names/result_names.hpp"
#include "orchestrator/sweep.hpp"

namespace flocsim::orchestrator {

using flocsim::input::InputError;
using nlohmann::json;

Filter parse_filter(const std::string& text) {
  static const char* ops[] = {"!=", "<=", ">=", "==", "=", "<", ">"};
  for (std::size_t pos = 0; pos < text.size(); ++pos)
    for (const char* op : ops) {
      const std::string o(op);
      if (text.compare(pos, o.size(), o) == 0) {
        Filter f{text.substr(0, pos), o == "==" ? "=" : o, text.substr(pos + o.size())};
        auto trim = [](std::string& s) {
          s.erase(0, s.find_first_not_of(" \t"));
          s.erase(s.find_last_not_of(" \t") + 1);
        };
        trim(f.field);
        trim(f.value);
        if (f.field.empty() || f.value.empty()) break;
        return f;
      }
    }
  throw InputError("--where \"" + text +
                   "\": expected FIELD OP VALUE with OP one of = != < <= > >= "
                   "(e.g. --where phi=0.2 --where 'F>10' --where status=completed)");
}

namespace {

bool as_number(const json& v, double& out) {
  if (v.is_number()) {
    out = v.get<double>();
    return true;
  }
  if (v.is_string()) {
    const std::string s = v.get<std::string>();
    char* end = nullptr;
    out = std::strtod(s.c_str(), &end);
    return !s.empty() && end == s.c_str() + s.size();
  }
  return false;
}

}  // namespace

bool filter_matches(const json& v, const Filter& f) {
  if (v.is_null()) return false;
  double a = 0, b = 0;
  if (as_number(v, a) && as_number(json(f.value), b)) {
    // inf, nan, 1e999 against a number: a bound no stored value compares with
    // sensibly (F<inf matched nothing: the tolerance of = became inf too);
    // against text ("sweep=inf") it stays a text comparison
    if (!std::isfinite(b))
      throw InputError("--where \"" + f.field + f.op + f.value + "\": " + f.value +
                       " is not a finite number; compare " + f.field +
                       " with a finite bound (every stored value is finite)");
    // Equality tolerates the last digits lost in printing (0.1+0.2 vs 0.3).
    const bool eq = std::fabs(a - b) <= 1e-12 * std::max(std::fabs(a), std::fabs(b));
    if (f.op == "=") return eq;
    if (f.op == "!=") return !eq;
    if (f.op == "<") return a < b && !eq;
    if (f.op == "<=") return a < b || eq;
    if (f.op == ">") return a > b && !eq;
    return a > b || eq;
  }
  const std::string s = v.is_string() ? v.get<std::string>() : v.dump();
  if (f.op == "=") return s == f.value;
  if (f.op == "!=") return s != f.value;
  if (f.op == "<") return s < f.value;
  if (f.op == "<=") return s <= f.value;
  if (f.op == ">") return s > f.value;
  return s >= f.value;
}

std::string DamagedRun::text() const {
  return "run " + run_id.substr(0, 12) + " (sweep " + sweep + "): " + field + ": " + problem;
}

namespace {

// "not JSON (parse error at byte 2)" for text that is not JSON, empty when it is.
std::string parse_problem(const std::string& text, json& parsed) {
  try {
    parsed = json::parse(text);
    return "";
  } catch (const json::parse_error& e) {
    return "is not JSON (" +
           std::string(text.empty() ? "empty" : "bad syntax at byte " + std::to_string(e.byte)) +
           ")";
  }
}

std::string kind(const json& v) {
  return v.is_object()   ? "an object"
         : v.is_array()  ? "an array"
         : v.is_string() ? "the text " + v.dump()
         : v.is_null()   ? "null"
                         : v.dump();
}

// The fields of result.json that query and post read, each of the type they
// read it as: the first that is not, as {field, problem}. What they do not
// read is not checked.
std::optional<std::pair<std::string, std::string>> result_problem(const json& r) {
  using P = std::optional<std::pair<std::string, std::string>>;
  const std::string f = "result_json";
  if (!r.is_object()) return P({f, "is " + kind(r) + ", not a JSON object"});
  auto expect = [&](const json& parent, const std::string& key, const std::string& path,
                    bool (json::*is)() const noexcept, const char* what) -> P {
    if (!parent.contains(key) || (parent[key].*is)()) return std::nullopt;
    return P({path, "is " + kind(parent[key]) + ", must be " + what});
  };
  if (auto p = expect(r, "case", f + ".case", &json::is_object, "an object")) return p;
  if (auto p = expect(r, "not_stationary", f + ".not_stationary", &json::is_array,
                      "a list of observable names"))
    return p;
  for (const json& n : r.value("not_stationary", json::array()))
    if (!n.is_string())
      return P({f + ".not_stationary", "holds " + kind(n) + ", must hold observable names"});
  if (auto p = expect(r, "derived", f + ".derived", &json::is_object, "an object")) return p;
  if (r.contains("derived"))
    for (const char* key : {"sphere_count", "phi_realised"})
      if (auto p = expect(r["derived"], key, f + ".derived." + key, &json::is_number, "a number"))
        return p;
  // the observables' own values come from the database's table; of the
  // result's copy only these are read (a window may also be a list: older
  // and other workers write [start, end], which is not read)
  if (!r.contains("observables") || !r["observables"].is_object()) return std::nullopt;
  const json& obs = r["observables"];
  if (obs.contains("window") && obs["window"].is_object())
    for (const char* key : {"start", "end"})
      if (auto p = expect(obs["window"], key, f + ".observables.window." + key, &json::is_number,
                          "a number"))
        return p;
  for (const std::string_view summary : result_names::kSummaryObservables) {
    const std::string name(summary), path = f + ".observables." + name;
    if (!obs.contains(name) || !obs[name].is_object()) continue;
    if (auto p = expect(obs[name], "error_reliable", path + ".error_reliable", &json::is_boolean,
                        "true or false"))
      return p;
  }
  return std::nullopt;
}

// The case fields the tables and the report read, each of the type they read
// it as (the case parser refuses anything else, so a row breaking this was
// not written by a run).
std::optional<std::pair<std::string, std::string>> case_problem(const json& c) {
  if (!c.is_object())
    return std::pair<std::string, std::string>{"case_json",
                                               "is " + kind(c) + ", not a case (a JSON object)"};
  for (const char* key : {"phi", "Re_inf", "du_over_Uinf"})
    if (c.contains(key) && !c[key].is_number())
      return std::pair<std::string, std::string>{std::string("case_json.") + key,
                                                 "is " + kind(c[key]) + ", must be a number"};
  for (const char* key : {"scene", "fidelity"})
    if (c.contains(key) && !c[key].is_string())
      return std::pair<std::string, std::string>{std::string("case_json.") + key,
                                                 "is " + kind(c[key]) + ", must be a name"};
  return std::nullopt;
}

// The case as the run ran it (see the header).
json ran_case(const json& input_case, const json& result) {
  if (result.is_object() && result.contains("case"))
    return cases::with_older_versions_models(result["case"]);
  try {
    return cases::resolved_case(input_case);
  } catch (const std::exception&) {
    return input_case;  // this version refuses it: the case as given
  }
}

}  // namespace

json filter_value(const RunView& run, const std::string& field) {
  if (auto it = run.columns.find(field); it != run.columns.end()) return it->second;
  if (auto v = get_path(run.ran_case, field)) return *v;
  return get_path(run.input_case, field).value_or(json());
}

RunSelection select_runs(db::ResultsDb& db, const std::optional<std::string>& sweep,
                         const std::vector<Filter>& where) {
  std::vector<db::SweepRecord> sweeps;
  if (sweep) {
    auto s = db.find_sweep(*sweep);
    if (!s) {
      std::string known;
      for (const auto& k : db.sweeps()) known += (known.empty() ? "" : ", ") + k.name;
      throw InputError("--sweep " + *sweep + ": no such sweep in " + db.path() +
                       " (known: " + (known.empty() ? "none" : known) + ")");
    }
    sweeps.push_back(*s);
  } else {
    sweeps = db.sweeps();
  }
  RunSelection sel;
  sel.columns = {"run", "sweep", "status"};
  std::vector<std::string> axes, observables;
  for (const db::SweepRecord& s : sweeps) {
    json list;
    if (!parse_problem(s.axes_json, list).empty() || !list.is_array()) continue;
    for (const json& a : list)
      if (a.is_string() && std::find(axes.begin(), axes.end(), a.get<std::string>()) == axes.end())
        axes.push_back(a.get<std::string>());
  }
  std::set<std::string> seen_runs;
  for (const db::SweepRecord& s : sweeps) {
    for (db::ResultsDb::ResultRow& r : db.result_rows(s.id)) {
      if (!seen_runs.insert(r.run.id).second) continue;  // shared by two sweeps: listed once
      RunView v;
      v.sweep = s.name;
      auto damaged = [&](const std::string& field, const std::string& problem) {
        sel.damaged.push_back(
            {r.run.id, s.name, field, problem, v.input_case.is_object() ? v.input_case : json()});
      };
      if (const std::string p = parse_problem(r.run.case_json, v.input_case); !p.empty()) {
        damaged("case_json", p);
        continue;
      }
      if (const auto p = case_problem(v.input_case)) {
        damaged(p->first, p->second);
        continue;
      }
      if (r.has_result) {
        if (const std::string p = parse_problem(r.result_json, v.result); !p.empty()) {
          damaged("result_json", p);
          continue;
        }
        if (const auto p = result_problem(v.result)) {
          damaged(p->first, p->second);
          continue;
        }
      }
      v.ran_case = ran_case(v.input_case, v.result);
      auto& c = v.columns;
      c["run"] = r.run.id.substr(0, 12);
      c["sweep"] = s.name;
      c["status"] = to_string(r.run.status);
      for (const std::string& a : axes) c[a] = get_path(v.input_case, a).value_or(json());
      for (const db::Observable& ob : r.observables) {
        if (std::find(observables.begin(), observables.end(), ob.name) == observables.end())
          observables.push_back(ob.name);
        c[ob.name] = ob.mean;
        c[ob.name + "_err"] = ob.error ? json(*ob.error) : json();
      }
      // short marks for the terminal table: s = a window still drifts, u = an
      // error is not reliable (result.json's verdicts)
      std::string flags;
      if (v.result.is_object()) {
        if (!v.result.value("not_stationary", json::array()).empty()) flags += "s";
        const json measured = v.result.value("observables", json::object());
        if (measured.is_object())
          for (const auto& entry : measured.items())
            if (entry.value().is_object() &&
                entry.value().value("error_reliable", json(true)) == json(false) &&
                flags.find('u') == std::string::npos)
              flags += "u";
      }
      c["flags"] = flags;
      c["wall_s"] = r.wall_s ? json(*r.wall_s) : json();
      c["mlups"] = r.mlups ? json(*r.mlups) : json();
      c["attempts"] = r.run.attempts;
      c["error"] = r.run.error;
      v.row = std::move(r);
      sel.runs.push_back(std::move(v));
    }
  }
  for (const std::string& a : axes) sel.columns.push_back(a);
  sel.axes = axes;
  for (const std::string& ob : observables) {
    sel.columns.push_back(ob);
    sel.columns.push_back(ob + "_err");
  }
  for (const char* c : {"wall_s", "mlups", "attempts"}) sel.columns.push_back(c);

  // A field no run has (a misspelling) would select nothing: refuse it.
  for (const Filter& f : where) {
    bool known = f.field == "error" ||
                 std::find(sel.columns.begin(), sel.columns.end(), f.field) != sel.columns.end();
    for (const RunView& v : sel.runs) known = known || !filter_value(v, f.field).is_null();
    if (!known && !sel.runs.empty()) {
      std::string cols;
      for (const auto& c : sel.columns) cols += (cols.empty() ? "" : ", ") + c;
      throw InputError("--where " + f.field + f.op + f.value + ": no column or case field \"" +
                       f.field + "\" (columns: " + cols + "; or a dotted case path)");
    }
  }
  // A numeric field against a value that is not a number would compare as
  // text (every row "matches" 'nu<abc'): refuse it.
  for (const Filter& f : where) {
    double number = 0;
    if (as_number(json(f.value), number)) continue;
    for (const RunView& v : sel.runs)
      if (filter_value(v, f.field).is_number())
        throw InputError("--where " + f.field + f.op + f.value + ": " + f.field +
                         " is a number, \"" + f.value +
                         "\" is not; give a number (e.g. 0.02 or 2e-2)");
  }
  for (std::size_t i = 0; i < sel.runs.size(); ++i) {
    bool ok = true;
    for (const Filter& f : where) ok = ok && filter_matches(filter_value(sel.runs[i], f.field), f);
    if (ok) sel.selected.push_back(i);
  }
  return sel;
}

}  // namespace flocsim::orchestrator
