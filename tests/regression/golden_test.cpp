// Golden-output regression: the CI-sized fluid, granular and suspension cases
// in tests/regression/golden/<scene>/case.json (double precision, one thread)
// must reproduce the observables of result.json and every dataset of
// series.h5 committed beside them, bit for bit. A restructuring of the code
// (time loop, modules, interfaces) must leave them unchanged; a deliberate
// change of the physics or numerics rewrites them, in its own commit that
// says why:
//
//   FLOCSIM_WRITE_GOLDEN=1 build/release/tests/regression/test_golden
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>

#include "engine/case/fluid_case.hpp"
#include "engine/case/suspension_case.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/output/hdf5_file.hpp"
#include "engine/run/fluid_run.hpp"
#include "engine/run/sphere_run.hpp"
#include "tests/run/scratch_dir.hpp"

namespace flocsim::run {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

const fs::path kGolden = fs::path(FLOCSIM_SOURCE_DIR) / "tests" / "regression" / "golden";

// Bit-for-bit holds for one instruction set: the build uses -march=native, and
// another vector width or FMA contraction changes the last bits, which the
// suspension's collisions then amplify. The golden files record the machine's
// set; on another one the comparison is skipped with the way to make new ones.
std::string instruction_set() {
  std::string s = "x86-64";
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2")) s += " avx2";
  if (__builtin_cpu_supports("fma")) s += " fma";
  if (__builtin_cpu_supports("avx512f")) s += " avx512f";
#else
  s = "other";
#endif
  return s;
}

bool writing_golden() {
  const char* w = std::getenv("FLOCSIM_WRITE_GOLDEN");
  return w && std::string(w) == "1";
}

// Every dataset in an HDF5 file, by path.
std::set<std::string> datasets(const fs::path& file) {
  std::set<std::string> out;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return out;
  H5Ovisit(
      f, H5_INDEX_NAME, H5_ITER_NATIVE,
      [](hid_t, const char* name, const H5O_info_t* info, void* data) -> herr_t {
        if (info->type == H5O_TYPE_DATASET)
          static_cast<std::set<std::string>*>(data)->insert(std::string("/") + name);
        return 0;
      },
      &out);
  H5Fclose(f);
  return out;
}

// Exact comparison of two JSON documents: same keys, same strings, numbers
// equal to the last bit (nlohmann writes doubles in shortest round-trip form).
void expect_identical(const json& want, const json& got, const std::string& path) {
  ASSERT_EQ(want.type(), got.type()) << path;
  if (want.is_object()) {
    std::set<std::string> a, b;
    for (auto it = want.begin(); it != want.end(); ++it) a.insert(it.key());
    for (auto it = got.begin(); it != got.end(); ++it) b.insert(it.key());
    EXPECT_EQ(a, b) << path;
    for (const auto& k : a)
      if (b.count(k)) expect_identical(want[k], got[k], path + "." + k);
  } else if (want.is_array()) {
    ASSERT_EQ(want.size(), got.size()) << path;
    for (std::size_t i = 0; i < want.size(); ++i)
      expect_identical(want[i], got[i], path + "[" + std::to_string(i) + "]");
  } else if (want.is_number_float() || got.is_number_float()) {
    EXPECT_EQ(want.get<double>(), got.get<double>()) << path;  // exact on purpose
  } else {
    EXPECT_EQ(want, got) << path;
  }
}

json read_json(const fs::path& p) {
  std::ifstream in(p);
  return json::parse(in);
}

// Runs one golden case and compares (or, with FLOCSIM_WRITE_GOLDEN=1, writes).
void check_scene(const std::string& scene) {
  const fs::path golden = kGolden / scene;
  if (!writing_golden()) {
    std::string recorded;
    std::getline(std::ifstream(kGolden / "instruction_set.txt"), recorded);
    if (recorded != instruction_set())
      GTEST_SKIP() << "the golden files were written on a machine with instruction set '"
                   << recorded << "', this one has '" << instruction_set()
                   << "': write them here from the commit before the change with "
                      "FLOCSIM_WRITE_GOLDEN=1 and compare the change against them";
  }
  const json document = input::read_json_file((golden / "case.json").string());
  const fs::path out = flocsim::testing::fresh_dir("golden_" + scene);
  RunOptions o;
  o.out_dir = out;
  o.quiet = true;
  const RunReport r = scene == "fluid" ? run_fluid_case(cases::parse_fluid_case(document), o)
                                       : run_sphere_case(cases::parse_suspension_case(document), o);
  ASSERT_EQ(r.outcome, RunOutcome::completed) << r.message;
  const json observables = read_json(out / "result.json")["observables"];
  const bool series = fs::exists(out / "series.h5");
  if (writing_golden()) {
    std::ofstream(kGolden / "instruction_set.txt") << instruction_set() << "\n";
    std::ofstream(golden / "observables.json") << observables.dump(2) << "\n";
    if (series)
      fs::copy_file(out / "series.h5", golden / "series.h5", fs::copy_options::overwrite_existing);
    fs::remove_all(out);
    GTEST_SKIP() << "wrote the golden files of " << scene;
  }
  expect_identical(read_json(golden / "observables.json"), observables, scene + ".observables");
  ASSERT_EQ(series, fs::exists(golden / "series.h5")) << scene;
  if (series) {
    const auto want = datasets(golden / "series.h5"), got = datasets(out / "series.h5");
    EXPECT_FALSE(want.empty());
    EXPECT_EQ(want, got) << scene;
    const output::Hdf5File a(golden / "series.h5", output::Hdf5File::Mode::read);
    const output::Hdf5File b(out / "series.h5", output::Hdf5File::Mode::read);
    for (const std::string& name : want) {
      if (!got.count(name)) continue;
      std::vector<hsize_t> shape_a, shape_b;
      const auto va = a.read<double>(name, &shape_a), vb = b.read<double>(name, &shape_b);
      EXPECT_EQ(shape_a, shape_b) << scene << " " << name;
      ASSERT_EQ(va.size(), vb.size()) << scene << " " << name;
      std::size_t differing = 0, first = 0;
      for (std::size_t i = 0; i < va.size(); ++i)
        if (!(va[i] == vb[i] || (std::isnan(va[i]) && std::isnan(vb[i]))))
          first = differing++ ? first : i;
      EXPECT_EQ(differing, 0u) << scene << " " << name << ": first at " << first << " ("
                               << va[first] << " vs " << vb[first] << ")";
    }
  }
  fs::remove_all(out);
}

TEST(Golden, FluidScene) {
  check_scene("fluid");
}
TEST(Golden, GranularScene) {
  check_scene("granular");
}
TEST(Golden, SuspensionScene) {
  check_scene("suspension");
}

}  // namespace
}  // namespace flocsim::run
