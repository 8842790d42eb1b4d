#pragma once
// The runs of a results database as `flocsim query` and `flocsim post` see
// them, and the one implementation of their `--sweep` and `--where`: the same
// columns, the same case fields, the same refusals for both.
//
// A filter's FIELD is looked up, in this order, among the columns (run, sweep,
// status, the sweeps' axes, each observable and NAME_err, wall_s, mlups,
// attempts, error), in the case as the run ran it, and in the case file as
// given. The case as it ran is result.json's "case" (every default filled in,
// fields older versions did not write given the one value they had then);
// for a run without a result it is the case as this version resolves it, which
// is what the run will run (the case file as given where this version refuses
// it). So `--where lubrication_model=calibrated` selects a run that left the
// model at its default.
//
// A row the database holds but that cannot be read (a case or result that is
// not JSON, a result field of the wrong type) is never shown as a run: it is
// left out and listed, with the run, the field and what is wrong.
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "db/results_db.hpp"

namespace flocsim::orchestrator {

// One filter of `--where`: FIELD OP VALUE with OP one of = != < <= > >=.
// Numbers compare as numbers, anything else as text.
struct Filter {
  std::string field, op, value;
};
// Parses "phi>=0.2"; throws flocsim::input::InputError with the accepted forms.
Filter parse_filter(const std::string& text);
// Whether a value (a number, or text) satisfies the filter; numbers compare as
// numbers, with equality to the last printed digits. Null never matches.
bool filter_matches(const nlohmann::json& value, const Filter& filter);

// One readable run.
struct RunView {
  db::ResultsDb::ResultRow row;
  std::string sweep;          // the first chosen sweep that lists it
  nlohmann::json input_case;  // the case file as given (the database's case_json)
  nlohmann::json ran_case;    // the case as it ran (see above)
  nlohmann::json result;      // result.json, an object; null without a result
  // column -> value (null where the run has none): run (the id's first 12
  // characters), sweep, status, the axes, observables and NAME_err, wall_s,
  // mlups, attempts, error, and flags (the terminal table's marks: s = a
  // window still drifts, u = an error is not reliable)
  std::map<std::string, nlohmann::json> columns;
};

// A row left out because part of it cannot be read.
struct DamagedRun {
  std::string run_id, sweep;
  std::string field;          // "case_json", "result_json", "result_json.observables.F", ...
  std::string problem;        // what is wrong with it
  nlohmann::json input_case;  // the case file when it could be read, else null
  std::string text() const;   // "run ID (sweep S): FIELD: PROBLEM"
};

struct RunSelection {
  std::vector<std::string> columns;   // every column, in query order
  std::vector<std::string> axes;      // the chosen sweeps' axes, in order
  std::vector<RunView> runs;          // the readable runs of the chosen sweeps, in grid order
  std::vector<std::size_t> selected;  // indices into runs passing every filter
  std::vector<DamagedRun> damaged;    // rows left out, in grid order
};

// The runs of `sweep` (every sweep when empty) and those passing `where`.
// Throws flocsim::input::InputError for an unknown sweep, a FIELD that is no
// column and no case field of any run, or a value that is not a number where
// the field holds numbers.
RunSelection select_runs(db::ResultsDb& db, const std::optional<std::string>& sweep,
                         const std::vector<Filter>& where);

// The value a filter on `field` sees for this run (null when it has none).
nlohmann::json filter_value(const RunView& run, const std::string& field);

}  // namespace flocsim::orchestrator
