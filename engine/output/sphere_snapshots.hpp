#pragma once
// Snapshots of the spheres (positions, velocities, angular velocities,
// aggregate ids): one HDF5 file per snapshot, <directory>/step_NNNNNNNNNN.h5,
// written atomically, plus the XDMF index <directory>.xdmf so ParaView shows
// them as points (a Glyph filter with the "radius" attribute draws spheres).
// Each file records the sphere radius (attribute "radius") and the periodic
// box the spheres fill (dataset "/box", 3 cell counts), so that a case that
// reads the positions back (positions_from) can check they fit its own box.
#include <filesystem>
#include <vector>

#include "engine/spheres/sphere_set.hpp"

namespace flocsim::output {

void write_sphere_snapshot(const std::filesystem::path& directory, long step, double time,
                           const spheres::SphereSet& spheres, const spheres::PeriodicBox& box,
                           const std::vector<int>& aggregate_of);

}  // namespace flocsim::output
