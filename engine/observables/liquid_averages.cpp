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
        if (dy * dy + dz * dz > r2) continue;
        const long row = (static_cast<long>(wrap(z, e.nz)) * e.ny + wrap(y, e.ny)) * e.nx;
        for (int x = x0 - reach; x <= x0 + reach + 1; ++x) {
          const double dx = x - c.x();
          if (dx * dx + dy * dy + dz * dz <= r2)
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
#pragma omp for schedule(static)
    for (long row = 0; row < static_cast<long>(e.ny) * e.nz; ++row) {
      const int y = static_cast<int>(row % e.ny), z = static_cast<int>(row / e.ny);
      // (sum c f + F_body / 2) / rho, without the per-cell field's half force
      fluid.macroscopic_row_without_force_field(0, e.nx, y, z, rho.data(), ux.data(), uy.data(),
                                                uz.data());
      const Real* row_field_x = field_x ? field.row(0, row) : nullptr;
      const Real* row_field_y = field_x ? field.row(1, row) : nullptr;
      const Real* row_field_z = field_x ? field.row(2, row) : nullptr;
      for (int x = 0; x < e.nx; ++x) {
        momentum += rho[x] * ux[x] - 0.5 * body_x;
        mass += rho[x];
        const double force = row_field_x ? static_cast<double>(row_field_x[x]) : 0.0;
        const double u = ux[x] + 0.5 * force / rho[x];
        const double v =
            uy[x] + (row_field_y ? 0.5 * static_cast<double>(row_field_y[x]) / rho[x] : 0.0);
        const double w =
            uz[x] + (row_field_z ? 0.5 * static_cast<double>(row_field_z[x]) / rho[x] : 0.0);
        // not finite after a blow-up: NaN never wins a comparison, so the mass tells
        const double speed2 = u * u + v * v + w * w;
        if (speed2 > max_speed2) max_speed2 = speed2;
        all_cells_sum += u;
        if (solid[static_cast<std::size_t>(row * e.nx + x)]) continue;
        if (speed2 > max_liquid_speed2) max_liquid_speed2 = speed2;
        velocity_sum += u;
        ++liquid;
      }
    }
  }
  LiquidAverages out;
  out.liquid_cells = liquid;
  out.mean_velocity_x = liquid > 0 ? velocity_sum / static_cast<double>(liquid) : 0.0;
  out.mean_velocity_x_all_cells = all_cells_sum / static_cast<double>(e.cells());
  out.lattice_momentum_x = momentum;
  out.mass = mass;
  out.max_speed = std::sqrt(max_speed2);
  out.max_speed_outside_spheres = std::sqrt(max_liquid_speed2);
  return out;
}

template LiquidAverages liquid_averages(const lattice::ForcedLiquid<float>&,
                                        const spheres::SphereSet&, std::vector<std::uint8_t>&);
template LiquidAverages liquid_averages(const lattice::ForcedLiquid<double>&,
                                        const spheres::SphereSet&, std::vector<std::uint8_t>&);

}  // namespace flocsim::observables
