#pragma once
// No-slip on the sphere surfaces by the immersed-boundary method with
// multi-direct forcing (Uhlmann 2005; Breugem 2012), coupled to the
// lattice-Boltzmann liquid through its per-cell force field (the seam of
// engine/lattice/forced_liquid.hpp: rows of the velocity without that force,
// and a view of the force field; nothing else of the lattice).
//
// Options (engine/coupling/scheme.hpp): the marker spacing, the kernel (Roma's
// 3-point or the 2-point linear hat) and the forcing: direct (below, with the
// number of sweeps) or control (control_forcing.hpp: the marker force carried
// from step to step, corrected by the slip the last step left: one
// interpolation per step, of u* plus the sphere's force of the last step).
// The paper's markers are 0.7 dx apart, with Roma's kernel.
//
// Each sphere carries n markers on the sphere of *input* radius a_g (the
// geometric radius where the no-slip condition is imposed; the calibrated
// hydrodynamic radius a is a different number and lives in SphereSet::radius).
// Once per time step, before the fluid step, apply():
//   1. removes the immersed-boundary force of the previous step,
//   2. reads the liquid velocity u* that the next collision would see without
//      any immersed-boundary force: (sum_i c_i f_i + F_body/2) / rho. The
//      lattice's own macroscopic() adds half of the stored force field, which
//      would make direct forcing chase its own previous force;
//   3. for `sweeps` sweeps (Jacobi): interpolates u* + F/(2 rho) to every
//      marker with the kernel (kernel.hpp), and adds
//      dF_m = 2 rho (U_surface - U_m) to the marker force, U_surface =
//      u_p + omega x r. The factor 2: the lattice velocity carries half of the
//      force applied in a step (Guo forcing), so a force density F changes the
//      velocity the collision sees by F / (2 rho);
//   4. spreads the marker forces F_m dV_m onto the lattice force field.
// The force the liquid exerts on the sphere is the reaction, H = -sum F_m dV_m,
// and the torque T = -sum r_m x F_m dV_m (r_m from the centre to the marker).
// The kernel's partition of unity makes sum_cells(spread force) = sum F_m dV_m,
// so the liquid gains exactly the momentum the spheres lose.
//
// The liquid inside a sphere stays on the lattice. apply() also measures its
// momentum P_in = sum_cells w rho u and angular momentum L_in = sum w r x rho u
// (u the velocity the collision sees, w the fraction of the cell inside the
// sphere of radius a_g, linear in the distance so that P_in varies smoothly
// as the sphere moves) and returns their change since the previous apply().
// The sphere equations (sphere_dynamics.hpp) add these changes to the
// immersed-boundary force and torque (Kempe & Froehlich 2012; Breugem 2012):
// the liquid inside is then accounted for as it actually moves, not as a
// rigid body, which keeps the explicit coupling stable with multi-direct
// forcing (the rigid-body approximation made the rotation unstable here).
//
// Sweeps are done per sphere on a private box of cells around it: forces
// of a neighbouring sphere whose kernel cells overlap (gaps below about 3 dx)
// are added to the lattice but not seen during this sphere's sweeps. The
// lubrication model takes over at those gaps (s0 = 0.2 a).
//
// Parallel work: spheres are grouped in blocks of the box (blocks wider than a
// sphere's cell box) and the blocks coloured by the parity of their block
// coordinates; blocks of one colour never write to the same cell, so threads
// take whole blocks of one colour at a time and write the force field without
// atomics.
//
// The per-marker physics (kernel weights, the forcing increments, the surface
// velocity, the inside weight) are plain functions in kernel.hpp,
// direct_forcing.hpp and control_forcing.hpp; marker_stencil.hpp vectorises
// interpolation and spreading; immersed_boundary.cpp holds the steps of one
// apply() and their scheduling (cell boxes and colours from
// engine/coupling/sphere_cells.hpp, chunk masks, prefetching).
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "engine/coupling/scheme.hpp"
#include "engine/coupling/sphere_cells.hpp"
#include "engine/coupling/sphere_coupling.hpp"
#include "engine/lattice/forced_liquid.hpp"
#include "engine/spheres/sphere_set.hpp"

namespace flocsim::immersed_boundary {

using spheres::Vec3;

struct ImmersedBoundarySettings {
  double input_radius = 5.6;  // a_g: markers sit on this sphere (lattice units)
  coupling::Scheme scheme;    // marker spacing, forcing (sweeps or gains), kernel
  bool measure_slip = false;  // one more interpolation per step, for diagnostics
};

// Throws std::invalid_argument naming the setting and what is allowed where
// `settings` cannot run (on either device).
void check_settings(const ImmersedBoundarySettings& settings);
// Edge of the cube of cells around a sphere that holds every marker's
// kernel stencil and the liquid inside.
int sphere_box_edge(double input_radius);
// Throws unless every side of the lattice exceeds 2 a_g + 3: a sphere's
// kernel cells must not meet its own periodic image.
void check_box_fits(const lattice::Extent& extent, double input_radius);

// Control forcing's carried state as checkpoints hold it (x y z per marker)
// and as the couplings keep it ((0, x, y, z) per marker, in Real), both
// ways: the CPU and GPU couplings write and read the same checkpoint.
template <class Real>
std::vector<double> lanes_to_vectors(const std::vector<Real>& lanes) {
  std::vector<double> out;
  out.reserve(3 * lanes.size() / 4);
  for (std::size_t k = 0; k + 3 < lanes.size(); k += 4)
    for (int d = 1; d <= 3; ++d) out.push_back(static_cast<double>(lanes[k + d]));
  return out;
}
template <class Real>
std::vector<Real> vectors_to_lanes(const std::vector<double>& v) {
  std::vector<Real> out(4 * (v.size() / 3), Real(0));
  for (std::size_t k = 0; k < v.size() / 3; ++k)
    for (int d = 0; d < 3; ++d) out[4 * k + 1 + d] = static_cast<Real>(v[3 * k + d]);
  return out;
}

template <class Real>
class ImmersedBoundary final : public coupling::SphereCoupling<Real> {
 public:
  explicit ImmersedBoundary(ImmersedBoundarySettings settings);
  ~ImmersedBoundary() override;

  const ImmersedBoundarySettings& settings() const { return settings_; }
  int markers_per_sphere() const { return static_cast<int>(directions_.size()); }
  double marker_volume() const { return marker_volume_; }
  std::string_view stage_name() const override { return "immersed_boundary"; }

  // Sets the immersed-boundary part of the fluid's force field (enabling the
  // field on first use) for the spheres at their current positions and
  // velocities, and stores the hydrodynamic force and torque on each sphere.
  // Call once per time step, right before fluid.step(). The fluid extent must
  // equal the box length. Spheres must not move between apply() and the
  // fluid step that uses its force.
  void apply(lattice::ForcedLiquid<Real>& liquid, const spheres::SphereSet& spheres) override;

  // Removes every force this object has put into the field.
  void remove(lattice::ForcedLiquid<Real>& liquid) override;

  // Control forcing: every marker's force density and last slip.
  std::vector<coupling::NamedArray> memory() const override;
  void restore_memory(const std::vector<coupling::NamedArray>& memory) override;

  // With measure_slip: root-mean-square and maximum over all markers of
  // |u(X_m) - U_surface| after the last sweep of the last apply().
  double rms_slip() const { return rms_slip_; }
  double max_slip() const { return max_slip_; }

 private:
  struct Workspace;
  template <int W>
  struct SphereWork;  // the steps of one apply() for one sphere (immersed_boundary.cpp)
  template <int W>    // kernel width
  void apply_with_kernel(lattice::ForcedLiquid<Real>& liquid, const spheres::SphereSet& spheres);
  // Cell boxes of the spheres (origins_, rows_) and the chunks they read (need_).
  void locate(const spheres::SphereSet& spheres, const lattice::Extent& e, double half_width);
  // One pass over the lattice rows: u* on the chunks the spheres read, and
  // the last step's force cleared.
  void read_liquid_velocity(lattice::ForcedLiquid<Real>& liquid,
                            const lattice::ForceFieldView<Real>& field, bool clear_in_pass);
  void zero_boxes(const lattice::ForceFieldView<Real>& field);

  ImmersedBoundarySettings settings_;
  std::vector<Vec3> directions_;  // unit vectors of the markers
  std::vector<double> offsets_;   // a_g times the unit vectors, x y z per marker
  double marker_volume_ = 0;
  int box_ = 0;  // edge of the cell box around a sphere

  std::vector<std::array<int, 3>> origins_;  // lowest corner of each sphere's cell box (unwrapped)
  std::vector<std::array<int, 3>> written_;  // boxes holding force from the last apply()
  // Per sphere and box row (j + box k): first and last box cell of the row that
  // the sphere reads and writes (first > last: none); rows_ for this apply(),
  // written_rows_ for the boxes in written_.
  std::vector<std::int16_t> rows_, written_rows_;
  // u* = (rho, u without the immersed-boundary force) of the cells the
  // spheres need, four numbers per cell in lattice order, filled by one pass
  // over the lattice rows per apply(). need_ marks the chunks the spheres read (all zero between
  // calls), held_ the chunks holding force from the last apply() (that pass
  // zeroes them).
  std::vector<Real> velocity_;
  coupling::ChunkMask need_, held_;
  // Control forcing: per sphere and marker, (0, F_m) and (0, e_previous).
  std::vector<Real> marker_force_, marker_slip_;
  std::vector<std::unique_ptr<Workspace>> workspaces_;
  double rms_slip_ = 0, max_slip_ = 0;
};

extern template class ImmersedBoundary<float>;
extern template class ImmersedBoundary<double>;

}  // namespace flocsim::immersed_boundary
