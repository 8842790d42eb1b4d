#pragma once
// The liquid averages' kernel bodies (engine/lattice/kernel_body.hpp): what
// one cell adds to the sums behind LiquidAverages (liquid_averages.hpp), how
// two partial sums combine, which cells a sphere makes solid, and one GPU
// thread's share of the cells. The CPU's liquid_averages() calls
// add_liquid_cell over rows after its vectorised moments; the GPU's
// reduction (engine/observables_gpu) runs all of them, so the test suite
// holds the arithmetic the GPU executes to the CPU's
// (tests/observables/liquid_average_body_test.cpp). Plain numbers only: no
// Eigen, nothing nvcc cannot compile.
#include <cmath>
#include <cstdint>

#include "engine/lattice/aa_cell.hpp"
#include "engine/lattice/kernel_body.hpp"

namespace flocsim::observables {

// Sums over cells, in double. Which cells: every cell for the momentum, the
// mass, the all-cells velocity and max_speed2; the liquid cells (centre
// outside every sphere) for the rest.
struct LiquidSums {
  double velocity_x = 0;            // of the liquid cells' physical u_x
  double velocity_x_all_cells = 0;  // of every cell's
  double momentum_x = 0;            // sum c_ix f_i, no half-force shift
  double mass = 0;                  // sum rho
  double max_speed2 = 0;            // largest |u|^2, every cell
  double max_liquid_speed2 = 0;     // largest |u|^2, liquid cells
  long liquid_cells = 0;
};

// What one cell gives the sums: from its density rho and velocity (ux, uy,
// uz) = (sum c f + F_body/2) / rho, i.e. without its per-cell force, and its
// per-cell force density `field` (zero without a field): the physical velocity
// adds half the cell's field force; the raw momentum takes half the body force
// off rho u (the field's half is not in rho u to begin with).
struct LiquidCell {
  double u = 0, v = 0, w = 0;  // the physical velocity
  double speed2 = 0;           // u^2 + v^2 + w^2; not finite after a blow-up
  double momentum_x = 0;       // rho ux - body_x / 2
};
FLOCSIM_KERNEL_BODY LiquidCell liquid_cell(double rho, double ux, double uy, double uz,
                                           double field_x, double field_y, double field_z,
                                           double body_x) {
  LiquidCell c;
  c.momentum_x = rho * ux - 0.5 * body_x;
  c.u = ux + 0.5 * field_x / rho;
  c.v = uy + 0.5 * field_y / rho;
  c.w = uz + 0.5 * field_z / rho;
  c.speed2 = c.u * c.u + c.v * c.v + c.w * c.w;
  return c;
}

// One cell added to the sums (the GPU's threads, cell after cell); `solid`:
// its centre lies inside a sphere. The CPU adds whole rows of liquid_cell
// with vector reductions instead (liquid_averages.cpp): the same terms, summed
// in another order.
FLOCSIM_KERNEL_BODY void add_liquid_cell(LiquidSums& s, double rho, double ux, double uy, double uz,
                                         double field_x, double field_y, double field_z,
                                         double body_x, bool solid) {
  const LiquidCell c = liquid_cell(rho, ux, uy, uz, field_x, field_y, field_z, body_x);
  s.momentum_x += c.momentum_x;
  s.mass += rho;
  // not finite after a blow-up: NaN never wins a comparison, so the mass tells
  if (c.speed2 > s.max_speed2) s.max_speed2 = c.speed2;
  s.velocity_x_all_cells += c.u;
  if (solid) return;
  if (c.speed2 > s.max_liquid_speed2) s.max_liquid_speed2 = c.speed2;
  s.velocity_x += c.u;
  ++s.liquid_cells;
}

// a += b: sums add, maxima keep the larger (a NaN in b never wins, as above).
FLOCSIM_KERNEL_BODY void combine_liquid_sums(LiquidSums& a, const LiquidSums& b) {
  a.velocity_x += b.velocity_x;
  a.velocity_x_all_cells += b.velocity_x_all_cells;
  a.momentum_x += b.momentum_x;
  a.mass += b.mass;
  if (b.max_speed2 > a.max_speed2) a.max_speed2 = b.max_speed2;
  if (b.max_liquid_speed2 > a.max_liquid_speed2) a.max_liquid_speed2 = b.max_liquid_speed2;
  a.liquid_cells += b.liquid_cells;
}

// Whether the cell at offset (dx, dy, dz) from a sphere's centre lies within
// it (r2 = radius^2): mark_solid_cells on the CPU and the GPU's marking both
// ask this. A compiler may fuse a product into the sum (FMA) on one back-end
// and not the other; that can move only a cell whose |d|^2 is within an ulp
// of r2 and inexact, never an exact case (integer offsets and radius 3.5:
// |d|^2 = 12.25 either way).
FLOCSIM_KERNEL_BODY bool offset_within(double dx, double dy, double dz, double r2) {
  return dx * dx + dy * dy + dz * dz <= r2;
}

// The cube of cells a sphere may cover, as mark_solid_cells walks it: side
// 2 reach + 2 (reach = ceil(radius)) from floor(centre) - reach on each axis.
// Cube cell q (x fastest) is the lattice cell returned (periodic images
// wrapped) when its centre lies within the radius, else -1.
FLOCSIM_KERNEL_BODY int sphere_cube_side(int reach) {
  return 2 * reach + 2;
}
FLOCSIM_KERNEL_BODY long solid_cube_cell(const double (&centre)[3], double radius, int reach,
                                         int nx, int ny, int nz, long q) {
  const int side = sphere_cube_side(reach);
  const int i = static_cast<int>(q % side), j = static_cast<int>((q / side) % side),
            k = static_cast<int>(q / (static_cast<long>(side) * side));
  const int x = static_cast<int>(::floor(centre[0])) - reach + i;
  const int y = static_cast<int>(::floor(centre[1])) - reach + j;
  const int z = static_cast<int>(::floor(centre[2])) - reach + k;
  if (!offset_within(x - centre[0], y - centre[1], z - centre[2], radius * radius)) return -1;
  const int wx = ((x % nx) + nx) % nx, wy = ((y % ny) + ny) % ny, wz = ((z % nz) + nz) % nz;
  return static_cast<long>(wx) + static_cast<long>(nx) * (wy + static_cast<long>(ny) * wz);
}

// What one thread of the GPU's reduction reads (device memory there).
template <class Real>
struct LiquidSumInput {
  lattice::AaSlots<Real> slots;  // the populations, read with aa_load_cell
  bool even = true;              // the next step is even (the AA pattern's parity)
  double body[3] = {0, 0, 0};    // the body force
  const Real* field[3] = {nullptr, nullptr, nullptr};  // per-cell force; null: none
  const std::uint8_t* solid = nullptr;                 // 1 per cell inside a sphere
};

// The sums over cells first, first + stride, ... of the lattice: each cell's
// 19 populations where the AA pattern has them, in double before the moments
// (as the CPU's double row reader converts them), then add_liquid_cell.
template <class Real>
FLOCSIM_KERNEL_BODY LiquidSums liquid_thread_sums(const LiquidSumInput<Real>& in, long first,
                                                  long stride) {
  LiquidSums s;
  const lattice::AaSlots<Real>& a = in.slots;
  const long cells = static_cast<long>(a.nx) * a.ny * a.nz;
  for (long c = first; c < cells; c += stride) {
    const int x = static_cast<int>(c % a.nx);
    const int y = static_cast<int>((c / a.nx) % a.ny);
    const int z = static_cast<int>(c / (static_cast<long>(a.nx) * a.ny));
    Real f[d3q19::kQ];
    lattice::aa_load_cell(a, x, y, z, in.even, f);
    double d[d3q19::kQ];
    FLOCSIM_UNROLL
    for (int i = 0; i < d3q19::kQ; ++i) d[i] = static_cast<double>(f[i]);
    double rho, ux, uy, uz;
    lattice::cell_moments(d, in.body[0], in.body[1], in.body[2], rho, ux, uy, uz);
    double F[3] = {0, 0, 0};
    if (in.field[0])
      for (int q = 0; q < 3; ++q) F[q] = static_cast<double>(in.field[q][c]);
    add_liquid_cell(s, rho, ux, uy, uz, F[0], F[1], F[2], in.body[0], in.solid[c] != 0);
  }
  return s;
}

}  // namespace flocsim::observables
