// flocsim case fields [--scene S | --sweep] [--markdown] | explain FIELD | schema [--sweep] | check
// CASE.json The case file's fields as the parser declares them (engine/case/case_fields.cpp): a
// list with ranges, defaults and units, one field explained, the JSON Schema of case (or sweep)
// files, and a case checked as `flocsim run` would check it, without running it.
#include <iostream>

#include "apps/flocsim/command_registry.hpp"
#include "apps/flocsim/gpu_fit.hpp"
#include "engine/case/case_fields.hpp"
#include "engine/case/case_file.hpp"
#include "engine/input/input_reader.hpp"
#include "orchestrator/sweep_fields.hpp"

namespace flocsim::app {
namespace {

struct CaseOptions {
  std::string scene, field, file;
  bool markdown = false, sweep = false;
};

// The fields of one scene (or of every scene), one line each.
int list_fields(const CaseOptions& o) {
  const input::FieldTable& table =
      o.sweep ? orchestrator::sweep_field_table() : cases::case_field_table();
  if (o.sweep && o.markdown) {
    std::cout << input::markdown_table(table, {});
    return kExitOk;
  }
  if (o.markdown) {
    const bool spheres =
        o.scene.empty() || cases::modules_of(cases::scene_from_name(o.scene, "--scene")).spheres;
    std::cout << cases::case_fields_markdown(spheres);
    return kExitOk;
  }
  const int context = o.scene.empty() || o.sweep
                          ? -1
                          : cases::scene_context(cases::scene_from_name(o.scene, "--scene"));
  for (const input::FieldSpec& f : table.fields) {
    if (context >= 0 && !((f.contexts >> context) & 1u)) continue;
    std::cout << f.path << "  " << input::type_text(f) << "  " << input::allowed_text(f)
              << "  default " << input::default_text(f)
              << (f.unit.empty() ? "" : "  [" + f.unit + "]") << "\n";
  }
  return kExitOk;
}

int explain_field(const CaseOptions& o) {
  const input::FieldTable& cases_table = cases::case_field_table();
  const input::FieldTable& sweep_table = orchestrator::sweep_field_table();
  if (const input::FieldSpec* f = cases_table.find(o.field)) {
    std::cout << input::explain(cases_table, *f);
    return kExitOk;
  }
  if (const input::FieldSpec* f = sweep_table.find(o.field)) {
    std::cout << "(sweep file) " << input::explain(sweep_table, *f);
    return kExitOk;
  }
  std::vector<std::string> known;
  for (const auto& f : cases_table.fields) known.push_back(f.path);
  for (const auto& f : sweep_table.fields) known.push_back(f.path);
  std::string near = input::nearest_name(o.field, known);
  if (near.empty()) {  // "viscocity" for numerics.viscosity: the last part alone
    std::vector<std::string> leaves;
    for (const std::string& k : known) leaves.push_back(k.substr(k.rfind('.') + 1));
    const std::string leaf = input::nearest_name(o.field, leaves);
    for (const std::string& k : known)
      if (!leaf.empty() && near.empty() && k.substr(k.rfind('.') + 1) == leaf) near = k;
  }
  std::cerr << "flocsim case explain: " << o.field << ": no such case or sweep field"
            << (near.empty() ? "" : "; did you mean " + near + "?")
            << " (`flocsim case fields` lists them)\n";
  return kExitBadInput;
}

int check_case(const CaseOptions& o) {
  try {
    const cases::ParsedCase parsed = cases::parse_case(input::read_json_file(o.file));
    // what `flocsim run` would refuse on this machine (no usable GPU, or one
    // too small) is said, not refused: a GPU case is often checked on a
    // login node and run on a GPU node
    if (const std::string why = gpu_refusal(parsed); !why.empty())
      std::cerr << "flocsim case check: warning: `flocsim run` on this machine would refuse this "
                   "case: "
                << printable(why) << "\n";
    const auto& warnings = parsed.fluid_scene ? parsed.fluid.warnings : parsed.spheres.warnings;
    for (const std::string& w : warnings) std::cerr << "flocsim case check: warning: " << w << "\n";
    const nlohmann::json resolved =
        parsed.fluid_scene ? parsed.fluid.to_json() : parsed.spheres.to_json();
    std::cout << resolved.dump(2) << "\n";
    return kExitOk;
  } catch (const input::InputError& e) {
    const std::string what = e.what();
    const bool named = what.rfind(o.file + ":", 0) == 0;
    std::cerr << "flocsim case check: input error" << (named ? "" : " in " + o.file) << ": " << what
              << "\n";
    return kExitBadInput;
  }
}

const bool registered = register_command(
    {"case", "The case file's fields: list, explain, JSON Schema, check a case without running it",
     [](CLI::App& cmd) {
       auto o = std::make_shared<CaseOptions>();
       cmd.require_subcommand(1);
       CLI::App* fields =
           cmd.add_subcommand("fields", "List the fields with ranges, defaults, units");
       fields->add_option("--scene", o->scene, "Only the fields this scene uses");
       fields->add_flag("--markdown", o->markdown,
                        "The documentation's table (sphere scenes, or the fluid scene's with "
                        "--scene fluid)");
       fields->add_flag("--sweep", o->sweep, "The fields of sweep files instead");
       CLI::App* explain = cmd.add_subcommand("explain", "Describe one field (a dotted path)");
       explain->add_option("FIELD", o->field, "e.g. numerics.viscosity, slurm.time_limit")
           ->required();
       CLI::App* schema =
           cmd.add_subcommand("schema", "Print the JSON Schema (draft 2020-12) of case files");
       schema->add_flag("--sweep", o->sweep, "The schema of sweep files instead");
       CLI::App* check = cmd.add_subcommand(
           "check", "Check a case as `flocsim run` does and print it resolved; runs nothing");
       check->add_option("CASE", o->file, "Case file (JSON)")->required();
       return CommandHandler([o, fields, explain, schema, check]() -> int {
         try {
           if (fields->parsed()) return list_fields(*o);
           if (explain->parsed()) return explain_field(*o);
           if (check->parsed()) return check_case(*o);
           if (schema->parsed()) {
             std::cout << (o->sweep ? orchestrator::sweep_schema() : cases::case_schema()).dump(2)
                       << "\n";
             return kExitOk;
           }
         } catch (const input::InputError& e) {
           std::cerr << "flocsim case: " << e.what() << "\n";
           return kExitBadInput;
         }
         return kExitBadInput;
       });
     }});

}  // namespace
}  // namespace flocsim::app
