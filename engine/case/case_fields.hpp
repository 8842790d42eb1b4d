#pragma once
// Every field of a case file, declared once (engine/input/field_table.hpp):
// name, type, range or choices, default or the rule that derives it, unit, the
// scenes it applies to and one line of documentation. The case readers
// (suspension_case.cpp, fluid_case.cpp) check a document against this table
// before they read it, and read each field's range and default from it;
// `flocsim case fields|explain|schema`, the field tables of docs/user-guide.md
// and schemas/case.schema.json are generated from it.
//
// Adding a field: one row here (kept in the order the reader reads), the read
// in the case reader (through case_number/case_integer/... so that range and
// default come from the row), its place in the canonical case (to_json) if it
// is recorded, then `flocsim case schema > schemas/case.schema.json` and the
// user guide's generated table (`flocsim case fields --markdown`); the tests
// CaseFields.* and case_schema fail until both are regenerated.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "engine/case/scene.hpp"
#include "engine/input/field_table.hpp"

namespace flocsim::cases {

// The table: its contexts are the scenes, in kScenes order (bit i = Scene i).
const input::FieldTable& case_field_table();

// The row of `path`; throws std::logic_error when the table lacks it (a
// reader asking for an undeclared field is a programming error).
const input::FieldSpec& case_field(std::string_view path);

inline int scene_context(Scene scene) {
  return static_cast<int>(scene);
}

// Reads one field of `reader` (whose path prefixes `key`) with the range and
// default of its row; `range` or `fallback` override the row's where a rule
// makes them depend on other fields.
double case_number(input::InputReader& reader, const std::string& key,
                   const std::optional<input::Range>& range = std::nullopt,
                   std::optional<double> fallback = std::nullopt);
long case_integer(input::InputReader& reader, const std::string& key);
bool case_boolean(input::InputReader& reader, const std::string& key);
std::string case_choice(input::InputReader& reader, const std::string& key,
                        std::optional<std::string> fallback = std::nullopt);

// The fields of the scenes with spheres (with_spheres) or of the fluid scene
// as a Markdown table, for docs/user-guide.md.
std::string case_fields_markdown(bool with_spheres);

// The JSON Schema (draft 2020-12) of a case file, as shipped in
// schemas/case.schema.json.
nlohmann::ordered_json case_schema();
// The properties of a case without its required fields and scene rules: the
// `base` of a sweep file, which its axes complete.
nlohmann::ordered_json partial_case_schema();

}  // namespace flocsim::cases
