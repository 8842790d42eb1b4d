// Sweep files: canonical cases and their hashes, grid expansion, and the
// errors a bad sweep file gets.
#include "orchestrator/sweep.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

#include "engine/input/input_reader.hpp"
#include "engine/text/printable.hpp"

using flocsim::input::InputError;
using nlohmann::json;
using nlohmann::ordered_json;
namespace orc = flocsim::orchestrator;

namespace {

orc::SweepSpec parse(const std::string& text) {
  return orc::parse_sweep(ordered_json::parse(text), "t.json");
}

// The message of the InputError that parsing (and expanding) `text` raises.
std::string error_of(const std::string& text) {
  try {
    orc::expand(parse(text));
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Sha256, MatchesFipsTestVectors) {
  EXPECT_EQ(orc::sha256_hex(""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(orc::sha256_hex("abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(orc::sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

// Issue 41, item 6: the words of the commands flocsim suggests.
TEST(ShellWord, PlainWordsStayAndEverythingElseIsSingleQuoted) {
  EXPECT_EQ(orc::shell_word("demo-1.sqlite"), "demo-1.sqlite");
  EXPECT_EQ(orc::shell_word("/runs/a_b/c:d"), "/runs/a_b/c:d");
  EXPECT_EQ(orc::shell_word("$(touch${IFS}X)"), "'$(touch${IFS}X)'");
  EXPECT_EQ(orc::shell_word("my runs/d.sqlite"), "'my runs/d.sqlite'");
  EXPECT_EQ(orc::shell_word("bob's"), "'bob'\\''s'");
  EXPECT_EQ(orc::shell_word(""), "''");
}

// Issue 41, item 7: what a terminal is given of a name, a value or a path.
// Each expectation is worked by hand from the bytes (UTF-8, RFC 3629).
TEST(Printable, ControlsAndBidiAreEscapedAndOtherUtf8IsKept) {
  using flocsim::text::printable;
  EXPECT_EQ(printable("demo phi=0.2 Å φ 😀"), "demo phi=0.2 Å φ 😀");
  EXPECT_EQ(printable("red\x1b[31m!"), "red\\x1b[31m!");
  EXPECT_EQ(printable("a\nb\rc\td\x7f"), "a\\x0ab\\x0dc\\x09d\\x7f");
  EXPECT_EQ(printable(std::string("nul\0x", 5)), "nul\\x00x");
  EXPECT_EQ(printable("evil\xe2\x80\xaegpj.exe"), "evil\\u202egpj.exe");  // U+202E
  EXPECT_EQ(printable("\xe2\x80\xaa\xe2\x80\xab\xe2\x80\xac\xe2\x80\xad"),
            "\\u202a\\u202b\\u202c\\u202d");
  EXPECT_EQ(printable("\xe2\x81\xa6x\xe2\x81\xa9"), "\\u2066x\\u2069");  // LRI, PDI
  EXPECT_EQ(printable("\xe2\x80\x8f\xd8\x9c"), "\\u200f\\u061c");        // RLM, ALM
  EXPECT_EQ(printable("l\xe2\x80\xa8p"), "l\\u2028p");                   // line separator
  EXPECT_EQ(printable("csi\xc2\x9b"
                      "31m \xc2\x85"),
            "csi\\u009b31m \\u0085");  // C1
  // not UTF-8: each byte as it is
  EXPECT_EQ(printable("\xff\xfe"), "\\xff\\xfe");
  EXPECT_EQ(printable("lone\x80"), "lone\\x80");
  EXPECT_EQ(printable("cut\xe2\x80"), "cut\\xe2\\x80");
  EXPECT_EQ(printable("\xc0\xaf"), "\\xc0\\xaf");                    // overlong "/"
  EXPECT_EQ(printable("\xed\xa0\x80"), "\\xed\\xa0\\x80");           // a surrogate
  EXPECT_EQ(printable("\xf4\x90\x80\x80"), "\\xf4\\x90\\x80\\x80");  // above U+10FFFF
  EXPECT_EQ(printable("\xe2\x80\xaeZ\xe2"), "\\u202eZ\\xe2");
  // only printable ASCII is added: escaping twice changes nothing more
  const std::string hostile = "n\x1b[2J\xe2\x80\xae\n\xff\xc2\x9b";
  EXPECT_EQ(printable(printable(hostile)), printable(hostile));
  EXPECT_EQ(printable(hostile), "n\\x1b[2J\\u202e\\x0a\\xff\\u009b");
}

TEST(Printable, JsonTextKeepsItsMeaning) {
  using flocsim::text::printable_json;
  // nlohmann writes C0 as \u001b already; DEL, C1 and bidi become JSON escapes
  const json j = {{"name", "a\x1b\x7f\xc2\x9b\xe2\x80\xae Å"}};
  const std::string shown = printable_json(j.dump());
  EXPECT_EQ(shown, "{\"name\":\"a\\u001b\\u007f\\u009b\\u202e Å\"}");
  EXPECT_EQ(json::parse(shown), j);
}

// A word holding what a terminal would obey is written as bash's $'...'; the
// shell gives back the very bytes (checked by bash itself where it is found).
TEST(ShellWord, ControlBidiAndNonUtf8WordsAreAnsiCQuoted) {
  EXPECT_EQ(orc::shell_word("a\x1b[31mb"), "$'a\\x1b[31mb'");
  EXPECT_EQ(orc::shell_word("it's\n"), "$'it\\'s\\x0a'");
  EXPECT_EQ(orc::shell_word("x\xe2\x80\xae\\y"), "$'x\\xe2\\x80\\xae\\\\y'");
  EXPECT_EQ(orc::shell_word("\xff Å"), "$'\\xff Å'");
  if (access("/bin/bash", X_OK) != 0) GTEST_SKIP() << "no /bin/bash to paste into";
  for (const std::string& word : {std::string("a\x1b[31mb"), std::string("it's\n"),
                                  std::string("x\xe2\x80\xae\\y"), std::string("\xff Å $(id)")}) {
    const std::string file = testing::TempDir() + "shell_word_" + std::to_string(getpid());
    // the command line goes through sh first: quoted once more for it
    const std::string sh =
        "/bin/bash -c " + orc::shell_word("printf %s " + orc::shell_word(word) + " > " + file);
    ASSERT_EQ(std::system(sh.c_str()), 0) << sh;
    std::ifstream in(file, std::ios::binary);
    const std::string back((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(back, word);
    std::filesystem::remove(file);
  }
}

TEST(Canonical, SortsKeysAndNormalisesNumbers) {
  const json a =
      json::parse(R"({"b": 1.0, "a": [2e3, 0.20, -0.0, 1.5], "c": {"z": true, "y": "s"}})");
  EXPECT_EQ(orc::canonical_text(a), R"({"a":[2000,0.2,0,1.5],"b":1,"c":{"y":"s","z":true}})");
  const json b = json::parse(R"({"c": {"y": "s", "z": true}, "a": [2000, 0.2, 0, 1.50], "b": 1})");
  EXPECT_EQ(orc::case_id(a), orc::case_id(b));
  const json c = json::parse(R"({"c": {"y": "s", "z": true}, "a": [2000, 0.2, 0, 1.5], "b": 2})");
  EXPECT_NE(orc::case_id(a), orc::case_id(c));
  EXPECT_EQ(orc::case_id(a).size(), 64u);
}

TEST(Expand, CartesianProductFirstAxisSlowest) {
  const auto s = parse(R"({
    "name": "g", "base": {"scene": "fluid", "fluid": {"viscosity": 0.01}, "run": {"steps": 10}},
    "axes": {"fluid.viscosity": [0.01, 0.02], "run.steps": [10, 20, 30]}})");
  const auto runs = orc::expand(s);
  ASSERT_EQ(runs.size(), 6u);
  EXPECT_EQ(runs[0].point.dump(), R"({"fluid.viscosity":0.01,"run.steps":10})");
  EXPECT_EQ(runs[1].point.dump(), R"({"fluid.viscosity":0.01,"run.steps":20})");
  EXPECT_EQ(runs[3].point.dump(), R"({"fluid.viscosity":0.02,"run.steps":10})");
  EXPECT_EQ(runs[5].case_json.dump(),
            R"({"fluid":{"viscosity":0.02},"run":{"steps":30},"scene":"fluid"})");
  std::set<std::string> ids;
  for (const auto& r : runs) ids.insert(r.id);
  EXPECT_EQ(ids.size(), 6u);
  EXPECT_EQ(runs[5].id, orc::case_id(runs[5].case_json));
}

TEST(Expand, NewAxisPathsCreateObjectsAndFidelityIsACaseField) {
  const auto s = parse(R"({"name": "p", "base": {"scene": "suspension"}, "fidelity": "quick",
    "axes": {"phi": [0.12], "well.du_over_Uinf": [0, 0.005]}})");
  const auto runs = orc::expand(s);
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(
      runs[1].case_json.dump(),
      R"({"fidelity":"quick","phi":0.12,"scene":"suspension","well":{"du_over_Uinf":0.005}})");
  EXPECT_EQ(s.max_attempts, 3);
}

TEST(Expand, NoAxesIsOneRun) {
  const auto runs = orc::expand(parse(R"({"name": "one", "base": {"x": 1}, "axes": {}})"));
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].case_json.dump(), R"({"x":1})");
}

// A grown grid keeps the ids of the points it had: their runs are reused.
TEST(Expand, GrowingAGridKeepsTheIdsOfOldPoints) {
  const auto small = orc::expand(
      parse(R"({"name": "g", "base": {"x": 0, "y": 1.0}, "axes": {"x": [1, 2], "y": [1.0]}})"));
  const auto grown = orc::expand(
      parse(R"({"name": "g", "base": {"y": 1, "x": 0}, "axes": {"x": [1.0, 2, 3], "y": [1, 2]}})"));
  std::set<std::string> grown_ids;
  for (const auto& r : grown) grown_ids.insert(r.id);
  for (const auto& r : small) EXPECT_TRUE(grown_ids.count(r.id)) << r.point.dump();
  EXPECT_EQ(grown.size(), 6u);
}

TEST(SweepErrors, NameTheFieldTheValueAndWhatIsAllowed) {
  EXPECT_NE(error_of(R"({"name": "a", "axes": {}})").find("base is missing"), std::string::npos)
      << error_of(R"({"name": "a", "axes": {}})");
  EXPECT_NE(error_of(R"({"name": "a", "base": {}, "axes": {"x": []}})")
                .find("axes.x = []: must be a non-empty array"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "base": {}, "axes": {"x": 3}})")
                .find("axes.x = 3: must be a non-empty array"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "base": {}, "axes": {"x": [1, 1.0]}})").find("lists 1 twice"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "base": {}, "axes": {"x": [[1]]}})")
                .find("must be numbers, strings or booleans"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "base": {"fluid": 2}, "axes": {"fluid.nu": [1]}})")
                .find("goes through base.fluid = 2, which is not an object"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "base": {}, "axes": {"a..b": [1]}})").find("empty segment"),
            std::string::npos);
  EXPECT_NE(
      error_of(R"({"name": "a", "base": {}, "axes": {"f": [1], "f.g": [2]}})").find("overlap"),
      std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "base": {}, "axes": {}, "axis": {}})").find("axis"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a b", "base": {}, "axes": {}})").find("without spaces"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"name": "a", "base": {}, "axes": {}, "max_attempts": 0})")
                .find("max_attempts = 0: must be >= 1"),
            std::string::npos)
      << error_of(R"({"name": "a", "base": {}, "axes": {}, "max_attempts": 0})");
  EXPECT_NE(error_of(R"({"name": "a", "base": {"fidelity": "x"}, "axes": {}, "fidelity": "y"})")
                .find("give it once"),
            std::string::npos);
  EXPECT_NE(error_of(R"([1, 2])").find("must hold a JSON object"), std::string::npos);
  // Every message names the file.
  EXPECT_EQ(
      error_of(R"({"name": "a", "base": {}, "axes": {"x": []}})").rfind("sweep file t.json", 0),
      0u);
}

// slurm.partition and slurm.time_limit go into the job script's #SBATCH lines:
// a line break there started a shell command in the script.
TEST(SweepErrors, SlurmValuesCannotEndAJobScriptLine) {
  for (const char* field : {"partition", "time_limit"}) {
    const std::string file = std::string(R"({"name": "a", "base": {}, "axes": {}, "slurm": {")") +
                             field + R"(": "debug\ntouch PWNED"}})";
    EXPECT_NE(error_of(file).find(std::string("slurm.") + field), std::string::npos)
        << error_of(file);
    EXPECT_NE(error_of(file).find("one word"), std::string::npos) << error_of(file);
  }
  EXPECT_NE(error_of("{\"name\": \"a\\rb\", \"base\": {}, \"axes\": {}}").find("without spaces"),
            std::string::npos);
}

// Issue 41, item 9: slurm.time_limit "abc" was accepted until sbatch refused
// it after the sweep was registered; twenty digits gave "error: stol".
TEST(SweepErrors, SlurmTimeLimitIsParsedWhenTheSweepIsRead) {
  for (const char* limit : {"abc", "99999999999999999999", "1:2:3:4", "1-"}) {
    const std::string file =
        std::string(R"({"name": "a", "base": {}, "axes": {}, "slurm": {"time_limit": ")") + limit +
        R"("}})";
    EXPECT_NE(error_of(file).find(std::string("slurm.time_limit = \"") + limit + "\""),
              std::string::npos)
        << error_of(file);
    EXPECT_NE(error_of(file).find("HOURS:MINUTES:SECONDS"), std::string::npos) << error_of(file);
  }
  for (const char* limit : {"90", "10:30", "01:00:00", "2-00:00:00", "1-12", "UNLIMITED"})
    EXPECT_EQ(
        error_of(std::string(R"({"name": "a", "base": {}, "axes": {}, "slurm": {"time_limit": ")") +
                 limit + R"("}})"),
        "(no error)")
        << limit;
}

TEST(SweepErrors, UnreadableOrInvalidFilesNameTheFile) {
  try {
    orc::read_sweep_file("/nonexistent/sweep.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/sweep.json: cannot be opened"),
              std::string::npos);
  }
}

// Issue 41, item 17: a relative positions_from resolved against the folder the
// sweep was launched from. It names a file beside the sweep file, stored absolute.
TEST(SweepFiles, ARelativePositionsFromIsBesideTheSweepFile) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("flocsim_sweep_pf_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir / "sub");
  {
    std::ofstream(dir / "sub" / "s.json") << R"({"name": "pf", "axes": {},
      "base": {"scene": "fixed-array", "positions_from": "snaps/step_0000000010.h5"}})";
    std::ofstream(dir / "sub" / "t.json") << R"({"name": "pf2", "base": {"scene": "fixed-array"},
      "axes": {"positions_from": ["../a.h5", "/abs/b.h5"]}})";
  }
  const auto s = orc::read_sweep_file((dir / "sub" / "s.json").string());
  EXPECT_EQ(s.base["positions_from"], (dir / "sub" / "snaps" / "step_0000000010.h5").string());
  EXPECT_EQ(s.source["base"]["positions_from"], s.base["positions_from"]);  // as stored
  const auto runs = orc::expand(orc::read_sweep_file((dir / "sub" / "t.json").string()));
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[0].case_json["positions_from"], (dir / "a.h5").string());
  EXPECT_EQ(runs[1].case_json["positions_from"], "/abs/b.h5");
  std::filesystem::remove_all(dir);
}

TEST(ShippedSweeps, ParseAndExpandToTheirGrids) {
  const std::string dir = FLOCSIM_SOURCE_DIR "/sweeps/";
  EXPECT_EQ(orc::expand(orc::read_sweep_file(dir + "paper.json")).size(), 4u * 5u * 6u);
  const auto demo = orc::expand(orc::read_sweep_file(dir + "demo.json"));
  EXPECT_GE(demo.size(), 4u);
  EXPECT_LE(demo.size(), 12u);
  EXPECT_GE(orc::expand(orc::read_sweep_file(dir + "ci.json")).size(), 2u);
  // the device check's runs: du 0 and 0.025, each in float and double, the
  // comparison sweep's case in all else but the progress cadence (its float
  // runs on the CPU, committed, are the GPU's reference)
  const auto trade = orc::expand(orc::read_sweep_file(dir + "gpu-precision-a4.json"));
  ASSERT_EQ(trade.size(), 4u);
  std::map<std::string, nlohmann::json> comparison;
  for (const auto& run : orc::expand(orc::read_sweep_file(dir + "comparison/phi0.20-Re12.json")))
    comparison[run.case_json["du_over_Uinf"].dump()] = run.case_json;
  int doubles = 0;
  for (const auto& run : trade) {
    nlohmann::json c = run.case_json;
    doubles += c["precision"] == "double";
    ASSERT_TRUE(comparison.count(c["du_over_Uinf"].dump())) << c.dump();
    nlohmann::json reference = comparison[c["du_over_Uinf"].dump()];
    for (nlohmann::json* j : {&c, &reference}) {
      j->erase("precision");
      (*j)["protocol"].erase("progress_every_s");
    }
    EXPECT_EQ(c, reference);
  }
  EXPECT_EQ(doubles, 2);
}

}  // namespace
