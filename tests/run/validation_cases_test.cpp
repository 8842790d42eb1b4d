// The case files committed beside the validation results (docs/validation/)
// must still describe the runs that made those results: parsed by this
// version, each resolves to the case its result.json recorded (the same test a
// resume applies), so a changed default (an IB scheme a preset now picks, a
// lubrication model) cannot silently detach a committed case from its data.
// A case that a later floor refuses (the runs that measured it) carries a
// now-refused.txt whose first line the refusal must contain.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "engine/case/suspension_case.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/run/output_directory.hpp"

namespace flocsim {
namespace {

namespace fs = std::filesystem;

nlohmann::json read_json(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

TEST(CommittedValidationCases, ResolveToTheCaseTheirResultRan) {
  const fs::path root = FLOCSIM_SOURCE_DIR;
  // snapshot paths in the cases are relative to the repository root
  const fs::path was = fs::current_path();
  fs::current_path(root);
  int checked = 0;
  for (const auto& entry : fs::recursive_directory_iterator(root / "docs" / "validation")) {
    if (entry.path().filename() != "case.json") continue;
    const fs::path result = entry.path().parent_path() / "result.json";
    if (!fs::exists(result)) continue;
    SCOPED_TRACE(fs::relative(entry.path(), root).string());
    // A run that measured where flocsim now refuses to go (the study that set
    // a floor) keeps its record; now-refused.txt names the refusal it now meets.
    if (const fs::path refused = entry.path().parent_path() / "now-refused.txt";
        fs::exists(refused)) {
      std::ifstream in(refused);
      std::string expected;
      std::getline(in, expected);
      ASSERT_FALSE(expected.empty());
      try {
        cases::parse_suspension_case(read_json(entry.path()));
        ADD_FAILURE() << "accepted, but now-refused.txt says it is refused: " << expected;
      } catch (const input::InputError& e) {
        EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
      }
      ++checked;
      continue;
    }
    nlohmann::json ran = read_json(result).at("case");
    nlohmann::json now = cases::parse_suspension_case(read_json(entry.path())).to_json();
    // where the snapshot was read from is provenance, not physics
    ran.erase("positions_from");
    now.erase("positions_from");
    EXPECT_TRUE(run::resumable_under(ran, now)) << "differs: " << run::case_differences(ran, now);
    ++checked;
  }
  fs::current_path(was);
  EXPECT_GE(checked, 10);
}

// A point that was refused up front keeps its case.json and refused.txt (the
// refusal is the result: docs/corners.md). This
// version must still refuse it, with the message the record quotes, so a
// changed floor or remedy cannot leave a stale record behind.
TEST(CommittedValidationCases, RefusedPointsStillMeetTheRefusalTheirRecordQuotes) {
  const fs::path root = FLOCSIM_SOURCE_DIR;
  int checked = 0;
  for (const auto& entry : fs::recursive_directory_iterator(root / "docs" / "validation")) {
    if (entry.path().filename() != "refused.txt") continue;
    const fs::path case_file = entry.path().parent_path() / "case.json";
    SCOPED_TRACE(fs::relative(entry.path(), root).string());
    ASSERT_TRUE(fs::exists(case_file));
    std::ifstream in(entry.path());
    const std::string record((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
    try {
      cases::parse_suspension_case(read_json(case_file));
      ADD_FAILURE() << "accepted, but refused.txt records a refusal";
    } catch (const input::InputError& e) {
      EXPECT_NE(record.find(e.what()), std::string::npos)
          << "refused now with: " << e.what() << "\nrecorded: " << record;
    }
    ++checked;
  }
  EXPECT_GE(checked, 8);  // the draft and paper presets' four Re_inf 72 corners each
}

}  // namespace
}  // namespace flocsim
