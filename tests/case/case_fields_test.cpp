// The case and sweep field tables (engine/case/case_fields.cpp,
// orchestrator/sweep_fields.cpp): the documentation's tables are generated
// from them, every declared field is read by the parser with the checks the
// table declares, and the probe cases that the schema test also holds against
// schemas/*.schema.json are refused by the parser.
#include "engine/case/case_fields.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "engine/case/case_file.hpp"
#include "engine/input/input_reader.hpp"
#include "orchestrator/sweep.hpp"
#include "orchestrator/sweep_fields.hpp"

namespace flocsim::cases {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using json = nlohmann::json;

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The text between "<!-- generated: NAME -->" and "<!-- end generated: NAME -->".
std::string generated_part(const std::string& doc, const std::string& name) {
  const std::string begin = "<!-- generated: " + name + " -->\n";
  const std::string end = "<!-- end generated: " + name + " -->";
  const auto b = doc.find(begin);
  const auto e = doc.find(end);
  if (b == std::string::npos || e == std::string::npos || e < b) return "(markers missing)";
  return doc.substr(b + begin.size(), e - b - begin.size());
}

std::string refusal(const json& document) {
  try {
    parse_case(document);
  } catch (const input::InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(CaseFields, TheUserGuidesTablesAreTheTables) {
  const std::string guide = read_text(FLOCSIM_SOURCE_DIR "/docs/user-guide.md");
  EXPECT_EQ(generated_part(guide, "flocsim case fields --markdown"), case_fields_markdown(true))
      << "regenerate with: flocsim case fields --markdown";
  EXPECT_EQ(generated_part(guide, "flocsim case fields --markdown --scene fluid"),
            case_fields_markdown(false))
      << "regenerate with: flocsim case fields --markdown --scene fluid";
  const std::string orchestrator = read_text(FLOCSIM_SOURCE_DIR "/docs/orchestrator.md");
  EXPECT_EQ(generated_part(orchestrator, "sweep fields"),
            input::markdown_table(orchestrator::sweep_field_table(), {}));
}

TEST(CaseFields, TheShippedSchemasAreTheTables) {
  EXPECT_EQ(json::parse(read_text(FLOCSIM_SOURCE_DIR "/schemas/case.schema.json")),
            json(case_schema()))
      << "regenerate with: flocsim case schema > schemas/case.schema.json";
  EXPECT_EQ(json::parse(read_text(FLOCSIM_SOURCE_DIR "/schemas/sweep.schema.json")),
            json(orchestrator::sweep_schema()))
      << "regenerate with: flocsim case schema --sweep > schemas/sweep.schema.json";
}

// A valid case of `scene` (the smallest the parser accepts quickly).
json valid_case(const std::string& scene) {
  if (scene == "fluid")
    return {{"scene", "fluid"}, {"fluid", {{"size", {8, 8, 8}}, {"viscosity", 0.1}}}};
  json c = {{"scene", scene}, {"fidelity", "draft"}};
  if (scene != "single-sphere") c["phi"] = 0.1;
  return c;
}

// Puts `value` at the dotted `path` of `document`.
void put(json& document, const std::string& path, const json& value) {
  json* node = &document;
  std::string rest = path;
  for (auto dot = rest.find('.'); dot != std::string::npos; dot = rest.find('.')) {
    node = &(*node)[rest.substr(0, dot)];
    rest = rest.substr(dot + 1);
  }
  (*node)[rest] = value;
}

// Every number field: a string, and a value past its static range, are
// refused naming the field and the value as given; in a scene that does not
// use it, it is refused or warned about naming the scene.
TEST(CaseFields, EveryNumberFieldIsCheckedAsDeclared) {
  const input::FieldTable& table = case_field_table();
  for (const input::FieldSpec& f : table.fields) {
    if (f.type != input::FieldType::number && f.type != input::FieldType::integer) continue;
    // the first scene the field applies to
    std::string scene;
    for (std::size_t i = 0; i < table.context_names.size() && scene.empty(); ++i)
      if ((f.contexts >> i) & 1u) scene = table.context_names[i];
    SCOPED_TRACE(f.path + " in " + scene);
    json wrong = valid_case(scene);
    put(wrong, f.path, "12");
    EXPECT_THAT(refusal(wrong),
                AllOf(HasSubstr(f.path), HasSubstr("\"12\""), HasSubstr("must be")));
    if (f.range.at_most || f.range.below) {
      const double past = f.range.at_most ? *f.range.at_most : *f.range.below;
      const double value = past + std::max(1.0, std::abs(past)) * 1e-7;
      json out = valid_case(scene);
      put(out, f.path,
          f.type == input::FieldType::integer ? json(std::llround(past) + 1) : json(value));
      const std::string why = refusal(out);
      EXPECT_THAT(why, HasSubstr(f.path));
      if (f.type == input::FieldType::number)
        EXPECT_THAT(why, HasSubstr(input::exact_number(value))) << "the value as given";
    }
  }
}

TEST(CaseFields, UnknownFieldsNameTheNearestKnownOne) {
  json c = valid_case("suspension");
  c["numerics"] = {{"viscocity", 0.02}};
  EXPECT_THAT(refusal(c), AllOf(HasSubstr("numerics.viscocity: unknown key"),
                                HasSubstr("did you mean numerics.viscosity?")));
  c = valid_case("suspension");
  c["restituion"] = 0.9;
  EXPECT_THAT(refusal(c), HasSubstr("did you mean restitution?"));
  c = valid_case("fluid");
  c["run"] = {{"step", 10}};
  EXPECT_THAT(refusal(c), HasSubstr("did you mean run.steps?"));
}

TEST(CaseFields, FieldsOfOtherScenesAreRefusedOrWarnedUniformly) {
  // refused: the field names the scenes it is for
  json c = valid_case("single-sphere");
  c["phi"] = 0.1;
  EXPECT_THAT(refusal(c), AllOf(HasSubstr("phi = 0.1: only for scene"), HasSubstr("suspension"),
                                HasSubstr("scene = \"single-sphere\"")));
  c = valid_case("suspension");
  c["run"] = {{"steps", 10}};
  EXPECT_THAT(refusal(c), AllOf(HasSubstr("run.steps = 10: only for scene \"fluid\"")));
  c = valid_case("fluid");
  c["Re_inf"] = 12;
  EXPECT_THAT(refusal(c),
              AllOf(HasSubstr("Re_inf = 12: only for scene"), HasSubstr("scene = \"fluid\"")));
  // warned: a suspension's case reused for its fixed array keeps its contact fields
  c = valid_case("fixed-array");
  c["restitution"] = 0.9;
  std::string warnings;
  for (const std::string& w : parse_case(c).spheres.warnings) warnings += w + "\n";
  EXPECT_THAT(warnings, AllOf(HasSubstr("restitution: scene \"fixed-array\" has no "
                                        "contacts"),
                              HasSubstr("(given: 0.9)")));
}

// The probe cases of tests/case/schema_probes.json: each refused by the
// parser (the schema test holds the schema to the same).
TEST(CaseFields, SchemaProbesAreRefusedByTheParser) {
  const json probes = json::parse(read_text(FLOCSIM_SOURCE_DIR "/tests/case/schema_probes.json"));
  ASSERT_FALSE(probes["cases"].empty());
  for (const json& probe : probes["cases"]) {
    SCOPED_TRACE(probe["why"].get<std::string>());
    EXPECT_THAT(refusal(probe["case"]), HasSubstr(probe["names"].get<std::string>()));
  }
  for (const json& probe : probes["sweeps"]) {
    SCOPED_TRACE(probe["why"].get<std::string>());
    std::string why = "(accepted)";
    try {
      orchestrator::parse_sweep(nlohmann::ordered_json(probe["sweep"]), "probe");
    } catch (const input::InputError& e) {
      why = e.what();
    }
    EXPECT_THAT(why, HasSubstr(probe["names"].get<std::string>()));
  }
}

// The viscosity ceiling is one rule for a viscosity given and one implied by
// Re_inf and U_inf (issue 41 item 11; docs/numerics.md "Viscosity ceiling").
TEST(CaseFields, TheViscosityCeilingHoldsHoweverTheViscosityIsGiven) {
  json given = valid_case("suspension");
  given["numerics"] = {{"viscosity", 0.2000001}};
  EXPECT_THAT(refusal(given),
              AllOf(HasSubstr("numerics.viscosity = 0.2000001"), HasSubstr("viscosity ceiling")));
  json implied = valid_case("single-sphere");
  implied["Re_inf"] = 0.5;  // draft: nu = 2 x 4 x 0.07 / 0.5 = 1.12
  implied["numerics"] = {{"U_inf", 0.07}};
  EXPECT_THAT(refusal(implied),
              AllOf(HasSubstr("implies numerics.viscosity = 2 a U_inf / Re_inf = 1.12"),
                    HasSubstr("U_inf <= 0.0125")));
  implied["numerics"] = {{"U_inf", 0.0124}};  // nu = 0.1984
  EXPECT_EQ(refusal(implied), "(accepted)");
  implied["numerics"].erase("U_inf");  // the preset's U_inf, lowered onto the ceiling
  const SuspensionCase lowered = parse_case(implied).spheres;
  EXPECT_DOUBLE_EQ(lowered.numerics.viscosity, kLargestViscosity);
  // granular: no liquid, no ceiling (its viscosity only names the time unit)
  json granular = valid_case("granular");
  granular["Re_inf"] = 0.1;
  EXPECT_EQ(refusal(granular), "(accepted)");
}

}  // namespace
}  // namespace flocsim::cases
