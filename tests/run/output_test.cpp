// Output files: atomic writes leave either nothing or the complete file, and
// field snapshots read back exactly with an XDMF index that names them.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "engine/output/atomic_file.hpp"
#include "engine/output/field_snapshots.hpp"
#include "engine/output/hdf5_file.hpp"
#include "engine/run/run_log.hpp"
#include "tests/run/scratch_dir.hpp"

namespace flocsim::output {
namespace {

namespace fs = std::filesystem;

TEST(AtomicFile, ReplacesContentWithoutLeavingTemporaries) {
  const fs::path dir = flocsim::testing::fresh_dir("atomic");
  fs::create_directories(dir);
  write_file_atomically(dir / "a.json", "first\n");
  write_file_atomically(dir / "a.json", std::string(100000, 'x'));
  std::stringstream s;
  s << std::ifstream(dir / "a.json").rdbuf();
  EXPECT_EQ(s.str(), std::string(100000, 'x'));
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
  fs::remove_all(dir);
}

// A sphere scene's step total is an estimate (stage 1 ends at stationarity):
// a run that ran past it reported 100.4 % and a negative ETA in progress.json
// (what `sweep status` shows). The total now grows to the steps done.
TEST(Progress, ARunPastItsEstimatedTotalReadsOneHundredPercent) {
  const fs::path dir = flocsim::testing::fresh_dir("progress");
  fs::create_directories(dir);
  run::RunLog log(dir / "run.log", true);
  run::ProgressReporter progress(log, dir / "progress.json", 0, 2002, 0, 1e9);
  progress.finish(1001);
  auto read = [&] { return nlohmann::json::parse(std::ifstream(dir / "progress.json")); };
  EXPECT_DOUBLE_EQ(read()["fraction"].get<double>(), 1001.0 / 2002);
  progress.finish(2010);
  const auto j = read();
  EXPECT_EQ(j["step"], 2010);
  EXPECT_EQ(j["steps_total"], 2010);
  EXPECT_DOUBLE_EQ(j["fraction"].get<double>(), 1.0);
  EXPECT_GE(j["eta_s"].get<double>(), 0.0);
  fs::remove_all(dir);
}

TEST(FieldSnapshots, OneCompleteFilePerSnapshotWithXdmfIndex) {
  const fs::path dir = flocsim::testing::fresh_dir("fields");
  const int nx = 5, ny = 3, nz = 2;
  std::vector<double> rho(nx * ny * nz), ux(rho.size()), uy(rho.size()), uz(rho.size());
  for (std::size_t i = 0; i < rho.size(); ++i) {
    rho[i] = 1 + 1e-3 * i;
    ux[i] = 0.1 * i;
    uy[i] = -0.2 * i;
    uz[i] = 1.0 / (1 + i);
  }
  write_field_snapshot(dir / "fields", {10, nx, ny, nz, &rho, &ux, &uy, &uz});
  write_field_snapshot(dir / "fields", {20, nx, ny, nz, &rho, &ux, &uy, &uz});
  // a temporary left by a killed writer is not a snapshot
  std::ofstream(dir / "fields" / ".step_0000000030.h5.tmp.1") << "partial";
  EXPECT_EQ(snapshot_steps(dir / "fields"), (std::vector<long>{10, 20}));
  std::vector<hsize_t> shape;
  const auto back = Hdf5File(snapshot_file(dir / "fields", 20), Hdf5File::Mode::read)
                        .read<double>("/velocity_z", &shape);
  EXPECT_EQ(shape, (std::vector<hsize_t>{2, 3, 5}));  // [nz][ny][nx]
  EXPECT_EQ(back, uz);
  std::stringstream x;
  x << std::ifstream(dir / "fields.xdmf").rdbuf();
  EXPECT_NE(x.str().find("fields/step_0000000010.h5:/density"), std::string::npos);
  EXPECT_NE(x.str().find("fields/step_0000000020.h5:/velocity_x"), std::string::npos);
  EXPECT_EQ(x.str().find("0000000030"), std::string::npos);
  fs::remove_all(dir);
}

TEST(TemporaryFile, AnAbandonedWriteLeavesThePreviousFileAndNoDebris) {
  const fs::path dir = flocsim::testing::fresh_dir("tmpfile");
  fs::create_directories(dir);
  write_file_atomically(dir / "checkpoint.h5", "good");
  try {
    TemporaryFile tmp(dir / "checkpoint.h5");
    std::ofstream(tmp.path()) << "half written";
    throw std::runtime_error("disk full");  // the writer fails before commit()
  } catch (const std::runtime_error&) {
  }
  std::stringstream s;
  s << std::ifstream(dir / "checkpoint.h5").rdbuf();
  EXPECT_EQ(s.str(), "good");
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace flocsim::output
