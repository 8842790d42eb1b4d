#pragma once
// Input files described as data: one declaration per field (its dotted path,
// type, range or choices, default or the rule that derives it, unit, where it
// applies and one line of documentation), read by everything that needs to
// know the fields: the readers' checks, `flocsim case fields|explain`, the
// generated tables of docs/user-guide.md and the JSON Schemas in schemas/.
//
// A table serves several contexts (the scenes of a case); each field names
// the contexts it applies to. What `check_fields` does with a document:
//   - every key the table does not know is refused, naming the nearest known
//     field ("did you mean ...") and the known keys at that level;
//   - a field given in a context it does not apply to is refused, or, where the
//     table says so (cases reused across scenes), warned about;
//   - types, ranges and choices are checked, and a refused value is printed
//     exactly as given (the shortest text that reads back as the same number).
// Rules that tie fields together (a range that depends on another field, a
// limit per scheme) are not in the table: the readers keep them as named
// functions, and a field's `rules` names them for the documentation.
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "engine/input/input_reader.hpp"

namespace flocsim::input {

enum class FieldType { number, integer, boolean, string, choice, numbers, object };

// Every context (bit mask over a table's contexts).
inline constexpr unsigned kEveryContext = ~0u;

struct FieldSpec {
  std::string path;  // dotted, from the document's root: "numerics.viscosity"
  FieldType type = FieldType::number;
  Range range;                        // number, integer, and each element of numbers
  std::vector<std::string> choices;   // choice
  std::size_t length = 0;             // numbers: the array's length
  nlohmann::json fallback;            // the default when it is one value (null otherwise)
  std::string default_rule;           // "required", or the named rule deriving the default
  std::string unit;                   // "" when dimensionless or not a quantity
  unsigned contexts = kEveryContext;  // bit i: applies in context i (a case's scene)
  // A field given where it does not apply: refused (false) or warned about
  // (true: fields of one scene's case reused for another, e.g. a suspension's
  // for its fixed array); `unused` completes the sentence after the context's
  // name ("has no lubrication, so no model runs; not recorded").
  bool warn_when_unused = false;
  std::string unused;
  std::string doc;    // one line
  std::string rules;  // the cross-field rules that bound it further, named ("" when none)
  // string: an ECMAScript pattern the whole value must match (refused with
  // range.why, "must be ..."); also the JSON Schema's "pattern"
  std::string pattern;
  // object: its keys are checked elsewhere (a sweep's base case, its axes),
  // not against this table
  bool open = false;
};

struct FieldTable {
  std::string what;                        // "case", "sweep file": for messages
  std::string context_field;               // the field that selects the context ("scene")
  std::vector<std::string> context_names;  // bit i -> its name
  std::vector<FieldSpec> fields;

  const FieldSpec* find(std::string_view path) const;
  // The names of the keys a table knows directly under `parent` ("" for the
  // root) in `context` (every context when negative).
  std::vector<std::string> keys_under(const std::string& parent, int context = -1) const;
  // The names of the contexts a field applies to, comma-separated.
  std::string contexts_text(const FieldSpec& field) const;
};

// The known name nearest to `given` (edit distance, case-insensitive), empty
// when none is near enough to be a plausible misspelling.
std::string nearest_name(const std::string& given, const std::vector<std::string>& known);

// Checks `document` against `table` in `context` (every context when
// negative): throws InputError for the first refusal and returns the warnings.
std::vector<std::string> check_fields(const FieldTable& table, const nlohmann::json& document,
                                      int context);

// A number exactly as given (shortest round trip), for messages.
std::string exact_number(double value);

// What a field allows, as the documentation says it: "> 0 and <= 0.35",
// "\"double\", \"float\"", "3 numbers, each >= 1".
std::string allowed_text(const FieldSpec& field);
// Its default as the documentation says it: "0.25", "required", "the preset's".
std::string default_text(const FieldSpec& field);
// Its type as a word: "number", "integer", ...
std::string type_text(const FieldSpec& field);

// One field, described for a person (`flocsim case explain`).
std::string explain(const FieldTable& table, const FieldSpec& field);

// A Markdown table of the fields whose path starts with one of `sections`
// (an empty list: all), in table order, for the documentation.
std::string markdown_table(const FieldTable& table, const std::vector<std::string>& sections);

// The JSON Schema (draft 2020-12) `properties` object of the fields under
// `parent`, nested objects with `additionalProperties: false`.
nlohmann::ordered_json schema_properties(const FieldTable& table, const std::string& parent);
// The schema of one field (type, range, choices, default, description).
nlohmann::ordered_json field_schema(const FieldTable& table, const FieldSpec& field);

}  // namespace flocsim::input
