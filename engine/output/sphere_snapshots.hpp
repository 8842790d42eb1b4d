#pragma once
// Snapshots of the spheres (positions, velocities, aggregate ids) in one HDF5
// file, group /step_NNNNNNNNNN per snapshot, with an XDMF index next to it so
// ParaView shows them as points (apply a Glyph filter with the radius stored
// in the file's "radius" attribute to see spheres).
#include <filesystem>
#include <vector>

#include "engine/spheres/sphere_set.hpp"

namespace flocsim::output {

// Appends (replacing a snapshot of the same step) and rewrites the .xdmf.
void append_sphere_snapshot(const std::filesystem::path& h5, long step, double time,
                            const spheres::SphereSet& spheres, const std::vector<int>& aggregate_of);

}  // namespace flocsim::output
