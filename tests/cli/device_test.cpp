// Where a case runs (engine/case/device.hpp): a GPU asked for where none can
// be used is refused before any work, with the reason, for the fluid scene and
// a sphere scene alike, and so is a sweep launched on cuda, before it records
// anything. On a machine with a usable GPU the refusals have nothing to show
// and skip (test_gpu_lattice and test_gpu_coupling run the GPU itself there).
#include <gtest/gtest.h>

#include "cli_fixture.hpp"
#include "engine/lattice_gpu/gpu_runtime.hpp"

namespace flocsim {
namespace {

namespace fs = std::filesystem;

const char* kShearWave = R"({"scene": "fluid", "fluid": {"size": [16, 4, 4], "viscosity": 0.02,
  "initial": {"type": "shear_wave", "amplitude": 0.01}}, "run": {"steps": 20}})";

TEST_F(Cli, DeviceCudaWithoutAUsableGpuIsRefusedBeforeAnyWork) {
  const gpu::GpuQuery q = gpu::query_gpus();
  if (!q.devices.empty()) GTEST_SKIP() << "a GPU is usable here: " << q.devices[0].name;
  t::write_text(dir_ / "case.json", kShearWave);
  const fs::path out = dir_ / "out";
  const t::Output o = t::run(
      flocsim({"run", (dir_ / "case.json").string(), "--out", out.string(), "--device", "cuda"}));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.out.find("device = \"cuda\""), std::string::npos) << o.out;
  EXPECT_NE(o.out.find(q.why_none), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("--device cpu"), std::string::npos) << o.out;  // what would work
  EXPECT_FALSE(fs::exists(out)) << "work started: " << out;
  // the same case on the CPU runs, and says where it ran
  const t::Output cpu = t::run(flocsim(
      {"run", (dir_ / "case.json").string(), "--out", out.string(), "--device", "cpu", "--quiet"}));
  ASSERT_EQ(cpu.code, 0) << cpu.out;
  const auto result = t::read_json(out / "result.json");
  EXPECT_EQ(result["device"]["kind"], "cpu");
  EXPECT_FALSE(result["device"]["name"].get<std::string>().empty());
  EXPECT_GE(result["device"]["threads"].get<int>(), 1);
  EXPECT_FALSE(result["case"].contains("device"));  // the default is not written
}

TEST_F(Cli, ASphereSceneOnCudaWithoutAUsableGpuIsRefusedBeforeAnyWork) {
  const gpu::GpuQuery q = gpu::query_gpus();
  if (!q.devices.empty()) GTEST_SKIP() << "a GPU is usable here: " << q.devices[0].name;
  t::write_text(dir_ / "case.json",
                R"({"scene": "suspension", "fidelity": "draft", "phi": 0.2, "Re_inf": 6})");
  const fs::path out = dir_ / "out";
  const t::Output o = t::run(
      flocsim({"run", (dir_ / "case.json").string(), "--out", out.string(), "--device", "cuda"}));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.out.find("device = \"cuda\""), std::string::npos) << o.out;
  EXPECT_NE(o.out.find(q.why_none), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("--device cpu"), std::string::npos) << o.out;
  EXPECT_FALSE(fs::exists(out)) << "work started: " << out;
}

TEST_F(Cli, SweepOnCudaIsRefusedBeforeAnythingIsRecorded) {
  // whichever reason applies here (no GPU, or sphere scenes), nothing is
  // recorded and no run starts
  t::write_text(dir_ / "sweep.json", R"({"name": "gpu", "fidelity": "draft",
    "base": {"scene": "suspension", "phi": 0.2, "Re_inf": 6}, "axes": {"seed": [1, 2]}})");
  const fs::path db = dir_ / "sweep.sqlite";
  const t::Output o = t::run(flocsim({"sweep", "launch", (dir_ / "sweep.json").string(), "--db",
                                      db.string(), "--device", "cuda"}));
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.out.find("--device cuda"), std::string::npos) << o.out;
  EXPECT_FALSE(fs::exists(db)) << "the sweep was recorded";
}

}  // namespace
}  // namespace flocsim
