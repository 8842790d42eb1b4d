#pragma once
// Snapshots of the macroscopic liquid fields (density, velocity) in one HDF5
// file, group /step_NNNNNNNNNN per snapshot, arrays shaped [nz][ny][nx] (x
// fastest, as the lattice stores them), plus an XDMF file next to it so that
// ParaView opens the time series directly.
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

// Appends a snapshot to `h5` (created if absent; a snapshot of the same step is
// replaced) and rewrites the XDMF index `h5` with extension .xdmf.
void append_field_snapshot(const std::filesystem::path& h5, const FieldSnapshot& s);

// Steps present in the file, ascending.
std::vector<long> snapshot_steps(const std::filesystem::path& h5);

}  // namespace flocsim::output
