#include "orchestrator/sweep_fields.hpp"

#include "engine/case/case_fields.hpp"

// GCC 12 warns that the Range of a row that names no range "may be used
// uninitialized" (a known false positive of designated initializers of
// aggregates holding strings); every member has a default initializer.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

namespace flocsim::orchestrator {

using input::FieldSpec;
using input::FieldTable;
using input::FieldType;

namespace {

// One word of Slurm's syntax: it goes into the job script's #SBATCH lines,
// so that no value can end a line and start a shell command there.
const std::string kSlurmWord = "^[A-Za-z0-9:_.,-]*$";
const std::string kSlurmWordWhy = "one word of letters, digits and : - _ . , (Slurm's syntax)";

FieldTable make_table() {
  FieldTable table{.what = "sweep file"};
  auto& t = table.fields;
  t.push_back({.path = "name",
               .type = FieldType::string,
               .range = {.why = "a non-empty word without spaces or slashes"},
               .default_rule = "required",
               .doc = "identifies the sweep in the database",
               .pattern = "^[^\\s/\\\\]+$"});
  t.push_back({.path = "description",
               .type = FieldType::string,
               .fallback = "",
               .doc = "free text, stored with the sweep"});
  t.push_back({.path = "max_attempts",
               .type = FieldType::integer,
               .range = {.at_least = 1, .at_most = 100},
               .fallback = 3,
               .doc = "failed attempts per run before it is left failed"});
  t.push_back({.path = "fidelity",
               .type = FieldType::string,
               .default_rule = "base.fidelity, or the case's default",
               .doc = "written into every run's case as its fidelity (draft, standard, paper)",
               .rules = "not also in base, not also an axis; each grid point's case checks it"});
  t.push_back({.path = "base",
               .type = FieldType::object,
               .default_rule = "required",
               .doc = "the case every run starts from (docs/user-guide.md)",
               .rules = "each grid point is read as a case",
               .open = true});
  t.push_back({.path = "axes",
               .type = FieldType::object,
               .default_rule = "required",
               .doc = "dotted case paths, each with a non-empty array of values; the grid is "
                      "their product, the first axis slowest",
               .rules = "no value twice; no axis inside another; at most 100000 runs",
               .open = true});
  t.push_back({.path = "slurm",
               .type = FieldType::object,
               .doc = "settings of --backend slurm (also read from a database's stored copy)"});
  t.push_back({.path = "slurm.runs_per_task",
               .type = FieldType::integer,
               .range = {.at_least = 1, .at_most = 10000},
               .fallback = 1,
               .doc = "runs each array task works through"});
  t.push_back({.path = "slurm.time_limit",
               .type = FieldType::string,
               .range = {.why = kSlurmWordWhy},
               .fallback = "01:00:00",
               .doc = "sbatch --time of each task",
               .rules = "a Slurm time limit: MINUTES, MINUTES:SECONDS, HOURS:MINUTES:SECONDS, "
                        "DAYS-HOURS[:MINUTES[:SECONDS]] or UNLIMITED",
               .pattern = kSlurmWord});
  t.push_back({.path = "slurm.partition",
               .type = FieldType::string,
               .range = {.why = kSlurmWordWhy},
               .fallback = "",
               .doc = "sbatch --partition (empty: the cluster's default)",
               .pattern = kSlurmWord});
  t.push_back({.path = "slurm.gres",
               .type = FieldType::string,
               .range = {.why = kSlurmWordWhy},
               .fallback = "",
               .doc = "sbatch --gres per task (empty: gpu:1 when the sweep runs on cuda)",
               .pattern = kSlurmWord});
  t.push_back({.path = "slurm.max_parallel",
               .type = FieldType::integer,
               .range = {.at_least = 0, .at_most = 100000},
               .fallback = 0,
               .doc = "array throttle %k (0: none)"});
  t.push_back({.path = "slurm.cpus_per_task",
               .type = FieldType::integer,
               .range = {.at_least = 1, .at_most = 1024},
               .fallback = 1,
               .doc = "sbatch --cpus-per-task"});
  return table;
}

}  // namespace

const FieldTable& sweep_field_table() {
  static const FieldTable table = make_table();
  return table;
}

nlohmann::ordered_json sweep_schema() {
  const FieldTable& table = sweep_field_table();
  nlohmann::ordered_json properties = input::schema_properties(table, "");
  nlohmann::ordered_json base = cases::partial_case_schema();
  base["description"] = properties["base"]["description"];
  properties["base"] = base;
  properties["axes"]["additionalProperties"] = {
      {"type", "array"}, {"minItems", 1}, {"items", {{"type", {"number", "string", "boolean"}}}}};
  properties["axes"]["propertyNames"] = {{"pattern", "^[^.]+(\\.[^.]+)*$"}};
  return {{"$schema", "https://json-schema.org/draft/2020-12/schema"},
          {"title", "flocsim sweep file"},
          {"description",
           "A flocsim sweep (docs/orchestrator.md). Generated by `flocsim case schema --sweep` "
           "from the sweep field table (orchestrator/sweep_fields.cpp) and the case field "
           "table; each grid point is checked by flocsim as a case."},
          {"type", "object"},
          {"properties", properties},
          {"additionalProperties", false},
          {"required", {"name", "base", "axes"}}};
}

}  // namespace flocsim::orchestrator
