#pragma once
// Every field of a sweep file, declared once (engine/input/field_table.hpp),
// as case_fields.hpp does for a case: parse_sweep checks a sweep file, and a
// database's stored copy of one, against this table before it reads it;
// `flocsim case schema --sweep`, docs/orchestrator.md's field table and
// schemas/sweep.schema.json are generated from it. The base case and the
// axes' values are a case's fields: the schema describes `base` with the
// case's properties, and every grid point is read by the case parsers.
#include <nlohmann/json.hpp>

#include "engine/input/field_table.hpp"

namespace flocsim::orchestrator {

const input::FieldTable& sweep_field_table();

// The JSON Schema (draft 2020-12) of a sweep file, as shipped in
// schemas/sweep.schema.json.
nlohmann::ordered_json sweep_schema();

}  // namespace flocsim::orchestrator
