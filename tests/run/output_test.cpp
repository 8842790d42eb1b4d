// Output files: atomic writes leave either nothing or the complete file, and
// field snapshots read back exactly with an XDMF index that names them.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "engine/output/atomic_file.hpp"
#include "engine/output/field_snapshots.hpp"
#include "engine/output/hdf5_file.hpp"

namespace flocsim::output {
namespace {

namespace fs = std::filesystem;

TEST(AtomicFile, ReplacesContentWithoutLeavingTemporaries) {
  const fs::path dir = fs::temp_directory_path() / ("flocsim_atomic_" + std::to_string(::getpid()));
  fs::remove_all(dir);
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

TEST(FieldSnapshots, ReadBackExactlyWithXdmfIndex) {
  const fs::path dir = fs::temp_directory_path() / ("flocsim_fields_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const int nx = 5, ny = 3, nz = 2;
  std::vector<double> rho(nx * ny * nz), ux(rho.size()), uy(rho.size()), uz(rho.size());
  for (std::size_t i = 0; i < rho.size(); ++i) {
    rho[i] = 1 + 1e-3 * i;
    ux[i] = 0.1 * i;
    uy[i] = -0.2 * i;
    uz[i] = 1.0 / (1 + i);
  }
  append_field_snapshot(dir / "fields.h5", {10, nx, ny, nz, &rho, &ux, &uy, &uz});
  append_field_snapshot(dir / "fields.h5", {20, nx, ny, nz, &rho, &ux, &uy, &uz});
  EXPECT_EQ(snapshot_steps(dir / "fields.h5"), (std::vector<long>{10, 20}));
  std::vector<hsize_t> shape;
  const auto back = Hdf5File(dir / "fields.h5", Hdf5File::Mode::read).read<double>("/step_0000000020/velocity_z", &shape);
  EXPECT_EQ(shape, (std::vector<hsize_t>{2, 3, 5}));  // [nz][ny][nx]
  EXPECT_EQ(back, uz);
  std::stringstream x;
  x << std::ifstream(dir / "fields.xdmf").rdbuf();
  EXPECT_NE(x.str().find("fields.h5:/step_0000000010/density"), std::string::npos);
  EXPECT_NE(x.str().find("fields.h5:/step_0000000020/velocity_x"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace flocsim::output
