// flocsim calibrate as a process: bad numbers, tables and options refused
// before any work, and two calibrations into one table keep both entries.
#include <gmock/gmock.h>
#include <signal.h>

#include <chrono>
#include <cstdlib>
#include <functional>

#include "cli_fixture.hpp"

namespace flocsim {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using ::testing::AllOf;
using ::testing::HasSubstr;

class Calibrate : public Cli {};

// A refusal before any work: quick, and no table written.
void expect_refused_up_front(const t::Output& o, const std::vector<std::string>& words,
                             const fs::path& table, double seconds) {
  EXPECT_EQ(o.code, 2) << o.out;
  for (const auto& w : words) EXPECT_THAT(o.out, HasSubstr(w));
  EXPECT_LT(seconds, 5.0) << "refused only after work";
  EXPECT_FALSE(fs::exists(table)) << o.out;
}

double seconds_of(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// `--tolerance nan` hung; `--radius nan` and `--pair-box nan` failed with
// "lattice extent 0 x 0 x 0".
TEST_F(Calibrate, RefusesNonFiniteNumbersNamingTheOption) {
  const std::string table = (dir_ / "t.json").string();
  for (const std::vector<std::string>& bad :
       {std::vector<std::string>{"--radius", "3", "--tolerance", "nan"},
        {"--radius", "nan"},
        {"--radius", "3", "--close-pairs", "--pair-box", "nan"},
        {"--radius", "3", "--viscosity", "inf"},
        {"--radius", "3", "--marker-spacing", "-inf"},
        {"--radius", "3", "--forcing", "control", "--gains", "nan", "0"},
        {"--radius", "3", "--grid-offsets", "0", "nan"},
        {"--radius", "3", "--close-pairs", "--input-radius", "nan"},
        {"--radius", "3", "--close-pairs", "--gaps", "0.1", "nan"}}) {
    std::vector<std::string> args = {"calibrate", "--table", table};
    args.insert(args.end(), bad.begin(), bad.end());
    t::Output o;
    const double s = seconds_of([&] { o = t::run(flocsim(args)); });
    std::string option;  // the last one named: the one given a non-finite value
    for (const std::string& word : bad)
      if (word.rfind("--", 0) == 0) option = word;
    SCOPED_TRACE(option);
    expect_refused_up_front(o, {option, "finite"}, table, s);
  }
}

// The box offset is read at the last gap (measured minus exact there). A gap
// list stopping at 0.1a made a table whose offset held the lattice's own
// close-pair share (+2.93 instead of +0.20 at a = 6, control forcing) and
// so a wrong correction at every gap, without a word.
TEST_F(Calibrate, RefusesCloseGapsThatEndBeforeTheBoxOffsetGap) {
  const std::string table = (dir_ / "t.json").string();
  t::Output o;
  const double s = seconds_of([&] {
    o = t::run(flocsim({"calibrate", "--table", table, "--radius", "4", "--close-pairs", "--gaps",
                        "0.005", "0.01", "0.1"}));
  });
  expect_refused_up_front(o, {"--gaps", "0.1", "box offset", "0.5"}, table, s);
}

// Options of a scheme other than the chosen one were ignored (a radius entry
// written for a scheme the user did not mean); unstable gains and control
// forcing's dense markers ran for minutes before the lattice said why.
TEST_F(Calibrate, RefusesOptionsOfAnotherSchemeAndControlForcingOutsideItsRegion) {
  const std::string table = (dir_ / "t.json").string();
  const std::vector<std::pair<std::vector<std::string>, std::vector<std::string>>> cases = {
      {{"--gains", "2", "0"}, {"--gains", "only with --forcing control"}},
      {{"--forcing", "control", "--sweeps", "2"}, {"--sweeps", "one correction per step"}},
      {{"--coupling", "partially-saturated", "--marker-spacing", "1"},
       {"--marker-spacing", "no markers"}},
      {{"--coupling", "partially-saturated", "--kernel", "linear2"}, {"--kernel", "no markers"}},
      {{"--forcing", "control", "--marker-spacing", "0.7"},
       {"--marker-spacing 0.7", "must be >= 1", "held"}},
      {{"--forcing", "control", "--gains", "4", "0"},
       {"--gains 4 0", "integral + 2 proportional <= 3"}},
      {{"--forcing", "control", "--gains", "0.5", "0"}, {"--gains 0.5 0", "integral >= 1"}}};
  for (const auto& [options, words] : cases) {
    std::vector<std::string> args = {"calibrate", "--table", table, "--radius", "4"};
    args.insert(args.end(), options.begin(), options.end());
    t::Output o;
    const double s = seconds_of([&] { o = t::run(flocsim(args)); });
    SCOPED_TRACE(options.front());
    expect_refused_up_front(o, words, table, s);
  }
}

// `--table nodir/t.json` (or a read-only folder) computed for minutes and then
// failed without a reason; a folder gave "parse error ... unexpected end of
// input"; a close-pair table gave "key 'input_radius' not found", no file named.
TEST_F(Calibrate, ChecksTheTableBeforeAnyWork) {
  const std::vector<std::string> quick = {"--radius",    "2",   "--boxes",     "8",
                                          "--viscosity", "0.5", "--tolerance", "1e-3"};
  auto calibrate = [&](const std::string& table, std::vector<std::string> instead = {}) {
    std::vector<std::string> args = {"calibrate", "--table", table};
    const auto& options = instead.empty() ? quick : instead;
    args.insert(args.end(), options.begin(), options.end());
    t::Output o;
    const double s = seconds_of([&] { o = t::run(flocsim(args)); });
    return std::pair{o, s};
  };
  const std::string missing = (dir_ / "nodir" / "t.json").string();
  auto [o, s] = calibrate(missing);
  expect_refused_up_front(o, {missing, "No such file or directory"}, missing, s);

  std::tie(o, s) = calibrate(dir_.string());
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_THAT(o.out, AllOf(HasSubstr(dir_.string()), HasSubstr("is a folder")));

  const fs::path pairs = fs::path(FLOCSIM_SOURCE_DIR) / "engine/calibration/pair_resistance.json";
  const fs::path copy = dir_ / "pairs.json";
  fs::copy_file(pairs, copy);
  std::tie(o, s) = calibrate(copy.string());
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_THAT(o.out, AllOf(HasSubstr(copy.string()), HasSubstr("is a close-pair table"),
                           HasSubstr("--close-pairs")));
  EXPECT_EQ(t::read_text(copy), t::read_text(pairs)) << "the table was changed";
  const fs::path radii =
      fs::path(FLOCSIM_SOURCE_DIR) / "engine/calibration/hydrodynamic_radius.json";
  std::tie(o, s) = calibrate(radii.string(), {"--close-pairs", "--radius", "4"});
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_THAT(o.out, AllOf(HasSubstr(radii.string()), HasSubstr("is a hydrodynamic-radius table")));

  const fs::path garbage = dir_ / "notes.json";
  t::write_text(garbage, "my notes\n");
  std::tie(o, s) = calibrate(garbage.string());
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_THAT(o.out, AllOf(HasSubstr(garbage.string()), HasSubstr("not JSON")));
  EXPECT_EQ(t::read_text(garbage), "my notes\n");

  // a read-only folder: root ignores permissions, so mount one (skipped where
  // that is not possible)
  const fs::path rw = dir_ / "rw", ro = dir_ / "ro";
  fs::create_directories(rw);
  fs::create_directories(ro);
  if (::geteuid() == 0 &&
      std::system(("mount --bind " + rw.string() + " " + ro.string() +
                   " 2>/dev/null && mount -o remount,ro,bind " + ro.string() + " 2>/dev/null")
                      .c_str()) == 0) {
    const std::string table = (ro / "t.json").string();
    std::tie(o, s) = calibrate(table);
    std::system(("umount " + ro.string()).c_str());
    expect_refused_up_front(o, {table, "Read-only file system"}, table, s);
  } else {
    std::system(("umount " + ro.string() + " 2>/dev/null").c_str());
    std::cout << "read-only folder not checked: cannot mount one here\n";
  }
}

// --separating, --gaps and --pair-box without --close-pairs were ignored and a
// radius entry written; a box too small for the radius failed once the work
// had started (the default boxes at --radius 2 on the third).
TEST_F(Calibrate, RefusesOptionsTheCalibrationDoesNotUse) {
  const std::string table = (dir_ / "t.json").string();
  for (const std::vector<std::string>& extra : {std::vector<std::string>{"--separating"},
                                                {"--gaps", "0.1", "0.5"},
                                                {"--pair-box", "12"},
                                                {"--input-radius", "2"},
                                                {"--close-pairs", "--boxes", "8"},
                                                {"--close-pairs", "--tolerance", "1e-6"},
                                                {"--close-pairs", "--grid-offsets", "0", "0.5"}}) {
    std::vector<std::string> args = {"calibrate", "--table", table, "--radius", "2"};
    args.insert(args.end(), extra.begin(), extra.end());
    t::Output o;
    const double s = seconds_of([&] { o = t::run(flocsim(args)); });
    const std::string option = extra[0] == "--close-pairs" ? extra[1] : extra[0];
    SCOPED_TRACE(option);
    expect_refused_up_front(o, {option, "does not use it"}, table, s);
  }
  t::Output o;
  double s = seconds_of([&] {
    o = t::run(flocsim({"calibrate", "--table", table, "--radius", "3", "--boxes", "8"}));
  });
  expect_refused_up_front(o, {"--boxes 8", "--radius 3", "must exceed 2 a_g + 3 = 8.4"}, table, s);
  s = seconds_of([&] { o = t::run(flocsim({"calibrate", "--table", table, "--radius", "2"})); });
  expect_refused_up_front(o, {"the default box 6", "--radius 2", "must exceed 2 a_g + 3 = 6.4"},
                          table, s);
  // the default boxes at a = 4 (16, 11: what the shipped a = 4 entries used)
  // pass this check: the refusal is then the table's, in a missing folder
  s = seconds_of([&] {
    o = t::run(
        flocsim({"calibrate", "--table", (dir_ / "no" / "t.json").string(), "--radius", "4"}));
  });
  EXPECT_THAT(o.out, ::testing::Not(HasSubstr("must exceed")));
  EXPECT_NE(o.code, 0);
}

// Two calibrations into one table, the first paused while the second
// completed: both said "table written", the second entry was gone (the first
// had read the table at its start and wrote it back from memory).
TEST_F(Calibrate, ConcurrentCalibrationsKeepEveryEntry) {
  const std::string table = (dir_ / "t.json").string();
  const std::string log = (dir_ / "first.log").string();
  t::Background first = t::start(flocsim({"calibrate", "--table", table, "--radius", "2", "--boxes",
                                          "8", "12", "--viscosity", "0.5", "--tolerance", "1e-3"}),
                                 log);
  // paused once it has measured its first box (its table read long before)
  ASSERT_TRUE(t::wait_for([&] { return t::read_text(log).find("a_g =") != std::string::npos; }, 60))
      << t::read_text(log);
  ASSERT_EQ(kill(first.pid, SIGSTOP), 0);
  const t::Output second =
      t::run(flocsim({"calibrate", "--table", table, "--radius", "3", "--boxes", "10",
                      "--viscosity", "0.5", "--tolerance", "1e-3"}));
  kill(first.pid, SIGCONT);
  EXPECT_EQ(second.code, 0) << second.out;
  EXPECT_EQ(first.wait(120), 0) << t::read_text(log);
  const json written = t::read_json(table);
  ASSERT_TRUE(written.contains("entries")) << written.dump();
  std::vector<double> radii;
  for (const json& e : written["entries"]) radii.push_back(e["hydrodynamic_radius"].get<double>());
  EXPECT_THAT(radii, ::testing::UnorderedElementsAre(2.0, 3.0));
  // nothing left beside the table (no lock, no temporary)
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir_))
    files += e.path().filename().string().rfind(".t.json", 0) == 0;
  EXPECT_EQ(files, 0);
}

}  // namespace
}  // namespace flocsim
