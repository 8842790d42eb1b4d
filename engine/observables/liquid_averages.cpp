#include "engine/observables/liquid_averages.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>

namespace flocsim::observables {

void mark_solid_cells(const lattice::Extent& e, const std::vector<spheres::Vec3>& centres,
                      double radius, std::vector<std::uint8_t>& solid) {
  solid.resize(static_cast<std::size_t>(e.cells()));
  const int reach = static_cast<int>(std::ceil(radius));
  const double r2 = radius * radius;
  auto wrap = [](int i, int n) { return ((i % n) + n) % n; };
  const long plane_cells = static_cast<long>(e.nx) * e.ny;
  // A sphere covers the unwrapped planes floor(c_z) - reach .. floor(c_z) +
  // reach + 1; plane z of the box is each of those that is z + k nz. Threads
  // take whole planes (each clears and marks its own), so none writes
  // another's cells.
  const int images = reach / e.nz + 1;
#pragma omp parallel for schedule(static)
  for (int z = 0; z < e.nz; ++z) {
    std::uint8_t* plane = solid.data() + z * plane_cells;
    std::fill(plane, plane + plane_cells, std::uint8_t{0});
    for (const auto& c : centres) {
      const int x0 = static_cast<int>(std::floor(c.x())), y0 = static_cast<int>(std::floor(c.y())),
                z0 = static_cast<int>(std::floor(c.z()));
      for (int k = -images; k <= images; ++k) {
        const int zu = z + k * e.nz;  // this plane as the sphere's unwrapped plane
        if (zu < z0 - reach || zu > z0 + reach + 1) continue;
        const double dz = zu - c.z();
        for (int y = y0 - reach; y <= y0 + reach + 1; ++y) {
          const double dy = y - c.y();
          if (dy * dy + dz * dz > r2) continue;  // the whole row of x
          std::uint8_t* row = plane + static_cast<long>(wrap(y, e.ny)) * e.nx;
          for (int x = x0 - reach; x <= x0 + reach + 1; ++x) {
            const double dx = x - c.x();
            if (offset_within(dx, dy, dz, r2)) row[wrap(x, e.nx)] = 1;
          }
        }
      }
    }
  }
}

template <class Real>
LiquidAverages liquid_averages(const lattice::ForcedLiquid<Real>& fluid,
                               const spheres::SphereSet& spheres,
                               std::vector<std::uint8_t>& solid) {
  const lattice::Extent e = fluid.extent();
  mark_solid_cells(e, spheres.position, spheres.radius, solid);
  const double body_x = fluid.body_force().x;
  const lattice::ForceFieldView<const Real> field = fluid.force_field_if_set();
  const Real* field_x = field.component[0];
  double velocity_sum = 0, all_cells_sum = 0, momentum = 0, mass = 0;
  double max_speed2 = 0, max_liquid_speed2 = 0;
  long liquid = 0;
#pragma omp parallel reduction(+ : velocity_sum, all_cells_sum, momentum, mass, liquid) \
    reduction(max : max_speed2, max_liquid_speed2)
  {
    std::vector<double> rho(static_cast<std::size_t>(e.nx)), ux(rho.size()), uy(rho.size()),
        uz(rho.size()), fx(rho.size(), 0.0), fy(rho.size(), 0.0), fz(rho.size(), 0.0);
#pragma omp for schedule(static)
    for (long row = 0; row < static_cast<long>(e.ny) * e.nz; ++row) {
      const int y = static_cast<int>(row % e.ny), z = static_cast<int>(row / e.ny);
      // (sum c f + F_body / 2) / rho, without the per-cell field's half force
      fluid.macroscopic_row_without_force_field(0, e.nx, y, z, rho.data(), ux.data(), uy.data(),
                                                uz.data());
      if (field_x) {
        const Real* f[3] = {field.row(0, row), field.row(1, row), field.row(2, row)};
        for (int x = 0; x < e.nx; ++x) {
          fx[x] = static_cast<double>(f[0][x]);
          fy[x] = static_cast<double>(f[1][x]);
          fz[x] = static_cast<double>(f[2][x]);
        }
      }
      const std::uint8_t* row_solid = solid.data() + row * e.nx;
      // The row's cells, each liquid_cell() as on the GPU (add_liquid_cell),
      // summed with vector reductions: a NaN speed may or may not win a max
      // here, but it makes the mass NaN, which the run's health check reads.
      double row_velocity = 0, row_all = 0, row_momentum = 0, row_mass = 0;
      double row_max2 = 0, row_liquid_max2 = 0;
      long row_liquid = 0;
#pragma omp simd reduction(+ : row_velocity, row_all, row_momentum, row_mass, row_liquid) \
    reduction(max : row_max2, row_liquid_max2)
      for (int x = 0; x < e.nx; ++x) {
        const LiquidCell c = liquid_cell(rho[x], ux[x], uy[x], uz[x], fx[x], fy[x], fz[x], body_x);
        const bool in_liquid = row_solid[x] == 0;
        row_momentum += c.momentum_x;
        row_mass += rho[x];
        row_all += c.u;
        row_max2 = std::max(row_max2, c.speed2);
        row_velocity += in_liquid ? c.u : 0.0;
        row_liquid += in_liquid ? 1 : 0;
        row_liquid_max2 = std::max(row_liquid_max2, in_liquid ? c.speed2 : 0.0);
      }
      velocity_sum += row_velocity;
      all_cells_sum += row_all;
      momentum += row_momentum;
      mass += row_mass;
      liquid += row_liquid;
      max_speed2 = std::max(max_speed2, row_max2);
      max_liquid_speed2 = std::max(max_liquid_speed2, row_liquid_max2);
    }
  }
  LiquidSums sums;
  sums.velocity_x = velocity_sum;
  sums.velocity_x_all_cells = all_cells_sum;
  sums.momentum_x = momentum;
  sums.mass = mass;
  sums.max_speed2 = max_speed2;
  sums.max_liquid_speed2 = max_liquid_speed2;
  sums.liquid_cells = liquid;
  return averages_from_sums(sums, e.cells());
}

LiquidAverages averages_from_sums(const LiquidSums& s, long cells) {
  LiquidAverages out;
  out.liquid_cells = s.liquid_cells;
  out.mean_velocity_x =
      s.liquid_cells > 0 ? s.velocity_x / static_cast<double>(s.liquid_cells) : 0.0;
  out.mean_velocity_x_all_cells = s.velocity_x_all_cells / static_cast<double>(cells);
  out.lattice_momentum_x = s.momentum_x;
  out.mass = s.mass;
  out.max_speed = std::sqrt(s.max_speed2);
  out.max_speed_outside_spheres = std::sqrt(s.max_liquid_speed2);
  return out;
}

template LiquidAverages liquid_averages(const lattice::ForcedLiquid<float>&,
                                        const spheres::SphereSet&, std::vector<std::uint8_t>&);
template LiquidAverages liquid_averages(const lattice::ForcedLiquid<double>&,
                                        const spheres::SphereSet&, std::vector<std::uint8_t>&);

}  // namespace flocsim::observables
