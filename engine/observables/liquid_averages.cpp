#include "engine/observables/liquid_averages.hpp"

#include <omp.h>

#include <cmath>

namespace flocsim::observables {

void mark_solid_cells(const lattice::Extent& e, const std::vector<spheres::Vec3>& centres,
                      double radius, std::vector<std::uint8_t>& solid) {
  solid.assign(static_cast<std::size_t>(e.cells()), 0);
  const int reach = static_cast<int>(std::ceil(radius));
  const double r2 = radius * radius;
  auto wrap = [](int i, int n) { return ((i % n) + n) % n; };
  for (const auto& c : centres) {
    const int x0 = static_cast<int>(std::floor(c.x())), y0 = static_cast<int>(std::floor(c.y())),
              z0 = static_cast<int>(std::floor(c.z()));
    for (int z = z0 - reach; z <= z0 + reach + 1; ++z) {
      const double dz = z - c.z();
      for (int y = y0 - reach; y <= y0 + reach + 1; ++y) {
        const double dy = y - c.y();
        if (dy * dy + dz * dz > r2) continue;  // the whole row of x
        const long row = (static_cast<long>(wrap(z, e.nz)) * e.ny + wrap(y, e.ny)) * e.nx;
        for (int x = x0 - reach; x <= x0 + reach + 1; ++x) {
          const double dx = x - c.x();
          if (offset_within(dx, dy, dz, r2))
            solid[static_cast<std::size_t>(row + wrap(x, e.nx))] = 1;
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
        uz(rho.size());
    // This thread's sums, cell after cell in the order the reduction's
    // private copies took them before the per-cell work became a kernel body
    // (liquid_average_body.hpp): the same sums, bit for bit.
    LiquidSums t;
#pragma omp for schedule(static)
    for (long row = 0; row < static_cast<long>(e.ny) * e.nz; ++row) {
      const int y = static_cast<int>(row % e.ny), z = static_cast<int>(row / e.ny);
      // (sum c f + F_body / 2) / rho, without the per-cell field's half force
      fluid.macroscopic_row_without_force_field(0, e.nx, y, z, rho.data(), ux.data(), uy.data(),
                                                uz.data());
      const std::uint8_t* row_solid = solid.data() + row * e.nx;
      if (field_x) {
        const Real* fx = field.row(0, row);
        const Real* fy = field.row(1, row);
        const Real* fz = field.row(2, row);
        for (int x = 0; x < e.nx; ++x)
          add_liquid_cell(t, rho[x], ux[x], uy[x], uz[x], static_cast<double>(fx[x]),
                          static_cast<double>(fy[x]), static_cast<double>(fz[x]), body_x,
                          row_solid[x] != 0);
      } else {
        for (int x = 0; x < e.nx; ++x)
          add_liquid_cell(t, rho[x], ux[x], uy[x], uz[x], 0.0, 0.0, 0.0, body_x, row_solid[x] != 0);
      }
    }
    velocity_sum += t.velocity_x;
    all_cells_sum += t.velocity_x_all_cells;
    momentum += t.momentum_x;
    mass += t.mass;
    liquid += t.liquid_cells;
    if (t.max_speed2 > max_speed2) max_speed2 = t.max_speed2;
    if (t.max_liquid_speed2 > max_liquid_speed2) max_liquid_speed2 = t.max_liquid_speed2;
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
