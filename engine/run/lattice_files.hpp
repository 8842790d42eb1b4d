#pragma once
// The lattice in a run's files, shared by every scene with a liquid: the
// populations in a checkpoint (group /fluid, one array per direction, the
// storage as it is, so a resumed run continues bit-identically) and the
// density/velocity snapshots under DIR/fields with their XDMF index.
#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/lattice/fluid_lattice.hpp"
#include "engine/output/field_snapshots.hpp"
#include "engine/output/hdf5_file.hpp"

namespace flocsim::run {

template <class Real>
void save_populations(output::Hdf5File& f, const lattice::FluidLattice<Real>& fluid) {
  f.create_group("/fluid");
  const std::vector<hsize_t> shape = {static_cast<hsize_t>(fluid.extent().cells())};
  std::vector<Real> slots;
  for (int i = 0; i < d3q19::kQ; ++i) {
    fluid.save_slots(i, slots);
    f.write("/fluid/population_deviation_" + std::to_string(i), shape, slots.data());
  }
}

// `file` names the checkpoint in errors.
template <class Real>
void restore_populations(output::Hdf5File& f, lattice::FluidLattice<Real>& fluid,
                         const std::filesystem::path& file) {
  for (int i = 0; i < d3q19::kQ; ++i) {
    const auto data = f.read<Real>("/fluid/population_deviation_" + std::to_string(i));
    if (static_cast<long>(data.size()) != fluid.extent().cells())
      throw std::runtime_error(file.string() + ": population array has the wrong size");
    fluid.restore_slots(i, data);
  }
}

// Density and velocity of every cell at the lattice's current step.
template <class Real>
void write_fields(const std::filesystem::path& dir, const lattice::FluidLattice<Real>& fluid) {
  std::vector<double> rho, ux, uy, uz;
  fluid.macroscopic_fields(rho, ux, uy, uz);
  const auto e = fluid.extent();
  output::write_field_snapshot(dir / "fields",
                               {fluid.time_step(), e.nx, e.ny, e.nz, &rho, &ux, &uy, &uz});
}

}  // namespace flocsim::run
