#pragma once
// Snapshots of the macroscopic liquid fields (density, velocity): one HDF5
// file per snapshot, <directory>/step_NNNNNNNNNN.h5, written atomically (a
// crash can lose the snapshot being written, never an earlier one), arrays
// shaped [nz][ny][nx] (x fastest, as the lattice stores them), plus the XDMF
// index <directory>.xdmf that ParaView opens as a time series.
#include <filesystem>
#include <vector>

namespace flocsim::output {

struct FieldSnapshot {
  long step = 0;
  int nx = 0, ny = 0, nz = 0;
  const std::vector<double>* density = nullptr;
  const std::vector<double>* ux = nullptr;
  const std::vector<double>* uy = nullptr;
  const std::vector<double>* uz = nullptr;
};

void write_field_snapshot(const std::filesystem::path& directory, const FieldSnapshot& s);

// Steps of the snapshot files in a snapshot directory, ascending.
std::vector<long> snapshot_steps(const std::filesystem::path& directory);
std::filesystem::path snapshot_file(const std::filesystem::path& directory, long step);

}  // namespace flocsim::output
