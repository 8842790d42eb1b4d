#include "engine/immersed_boundary/immersed_boundary.hpp"

#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "engine/immersed_boundary/kernel.hpp"
#include "engine/immersed_boundary/sphere_markers.hpp"

namespace flocsim::immersed_boundary {

namespace {

int wrap(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}

// Spheres grouped into blocks, blocks grouped by colour: two blocks of one
// colour are at least one block apart in every split direction, and blocks are
// at least one sphere box wide, so their spheres' boxes never share a cell.
std::vector<std::vector<std::vector<int>>> make_colours(
    const std::vector<std::array<int, 3>>& origins, int box, const lattice::Extent& extent) {
  const int length[3] = {extent.nx, extent.ny, extent.nz};
  int blocks[3];
  double width[3];
  for (int d = 0; d < 3; ++d) {
    int n = length[d] / box;
    n = n >= 2 ? n - n % 2 : 1;
    blocks[d] = n;
    width[d] = static_cast<double>(length[d]) / n;
  }
  const int total_blocks = blocks[0] * blocks[1] * blocks[2];
  std::vector<std::vector<int>> members(static_cast<std::size_t>(total_blocks));
  for (std::size_t s = 0; s < origins.size(); ++s) {
    int coord[3];
    for (int d = 0; d < 3; ++d) {
      const double centre = wrap(origins[s][d], length[d]) + 0.5 * box;
      double c = std::fmod(centre, static_cast<double>(length[d]));
      coord[d] = std::min(blocks[d] - 1, static_cast<int>(c / width[d]));
    }
    members[static_cast<std::size_t>(coord[0] + blocks[0] * (coord[1] + blocks[1] * coord[2]))]
        .push_back(static_cast<int>(s));
  }
  std::vector<std::vector<std::vector<int>>> colours(8);
  for (int bz = 0; bz < blocks[2]; ++bz)
    for (int by = 0; by < blocks[1]; ++by)
      for (int bx = 0; bx < blocks[0]; ++bx) {
        auto& m = members[static_cast<std::size_t>(bx + blocks[0] * (by + blocks[1] * bz))];
        if (m.empty()) continue;
        colours[static_cast<std::size_t>((bx % 2) | (by % 2) << 1 | (bz % 2) << 2)].push_back(
            std::move(m));
      }
  std::erase_if(colours, [](const auto& c) { return c.empty(); });
  return colours;
}

}  // namespace

// Per-thread scratch space: a box of cells around one sphere and its markers.
template <class Real>
struct ImmersedBoundary<Real>::Workspace {
  explicit Workspace(int box, int markers)
      : cells(static_cast<std::size_t>(box) * box * box),
        rho(cells),
        ux(cells),
        uy(cells),
        uz(cells),
        fx(cells, 0.0),
        fy(cells, 0.0),
        fz(cells, 0.0),
        base(static_cast<std::size_t>(markers)),
        weights(static_cast<std::size_t>(markers) * 9),
        target(static_cast<std::size_t>(markers)),
        marker_force(static_cast<std::size_t>(markers)),
        increment(static_cast<std::size_t>(markers)) {
    touched.reserve(cells);
  }
  std::size_t cells;
  std::vector<double> rho, ux, uy, uz;  // u*: velocity without immersed-boundary force
  std::vector<double> fx, fy, fz;       // this sphere's force density on the box
  std::vector<int> touched;             // box cells read and written for this sphere
  std::vector<int> global[3];           // wrapped lattice coordinate of each box row
  std::vector<int> base;                // box index of each marker's stencil corner
  std::vector<double> weights;          // 3 x 3 kernel weights of each marker
  std::vector<Vec3> target, marker_force, increment;
};

template <class Real>
ImmersedBoundary<Real>::ImmersedBoundary(ImmersedBoundarySettings settings) : settings_(settings) {
  if (!(settings.input_radius >= 1.0))
    throw std::invalid_argument(
        "immersed boundary: input_radius = " + std::to_string(settings.input_radius) +
        ": must be at least 1 dx (the kernel is 3 dx wide)");
  if (!(settings.marker_spacing > 0.2 && settings.marker_spacing <= 1.0))
    throw std::invalid_argument(
        "immersed boundary: marker_spacing = " + std::to_string(settings.marker_spacing) +
        ": must be in (0.2, 1] dx");
  if (settings.iterations < 1 || settings.iterations > 20)
    throw std::invalid_argument("immersed boundary: iterations = " +
                                std::to_string(settings.iterations) + ": must be in [1, 20]");
  const int n = marker_count(settings.input_radius, settings.marker_spacing);
  directions_ = fibonacci_sphere(n);
  marker_volume_ = immersed_boundary::marker_volume(settings.input_radius, n);
  box_ = static_cast<int>(std::ceil(2.0 * settings.input_radius)) + 5;
}

template <class Real>
ImmersedBoundary<Real>::~ImmersedBoundary() = default;

template <class Real>
void ImmersedBoundary<Real>::zero_boxes(lattice::FluidLattice<Real>& fluid) {
  if (written_.empty()) return;
  const lattice::Extent e = fluid.extent();
  const auto colours = make_colours(written_, box_, e);
  const int B = box_;
  Real* field[3] = {fluid.force_field(0), fluid.force_field(1), fluid.force_field(2)};
#pragma omp parallel
  for (const auto& blocks : colours) {
#pragma omp for schedule(dynamic, 1)
    for (std::size_t b = 0; b < blocks.size(); ++b)
      for (int s : blocks[b]) {
        const auto& o = written_[static_cast<std::size_t>(s)];
        for (int k = 0; k < B; ++k)
          for (int j = 0; j < B; ++j) {
            const long row = fluid.cell_index(0, wrap(o[1] + j, e.ny), wrap(o[2] + k, e.nz));
            for (int i = 0; i < B; ++i) {
              const long c = row + wrap(o[0] + i, e.nx);
              field[0][c] = field[1][c] = field[2][c] = Real(0);
            }
          }
      }
  }
  written_.clear();
}

template <class Real>
void ImmersedBoundary<Real>::remove(lattice::FluidLattice<Real>& fluid) {
  if (fluid.has_force_field()) zero_boxes(fluid);
}

template <class Real>
void ImmersedBoundary<Real>::apply(lattice::FluidLattice<Real>& fluid,
                                   const spheres::SphereSet& spheres) {
  const lattice::Extent e = fluid.extent();
  const double ag = settings_.input_radius;
  const int length[3] = {e.nx, e.ny, e.nz};
  for (int d = 0; d < 3; ++d)
    if (length[d] <= 2.0 * ag + 3.0)
      throw std::invalid_argument(
          "immersed boundary: box length " + std::to_string(length[d]) +
          " must exceed 2 a_g + 3 = " + std::to_string(2.0 * ag + 3.0) +
          " (a sphere's kernel cells must not meet its own periodic image)");
  if (!fluid.has_force_field()) fluid.enable_force_field();
  zero_boxes(fluid);

  const std::size_t n = spheres.size();
  const int B = box_;
  const int markers = markers_per_sphere();
  const double dV = marker_volume_;
  force_.assign(n, Vec3::Zero());
  torque_.assign(n, Vec3::Zero());
  const bool have_previous = internal_momentum_.size() == n;
  std::vector<Vec3> momentum(n, Vec3::Zero()), angular(n, Vec3::Zero());
  origins_.resize(n);
  for (std::size_t s = 0; s < n; ++s)
    for (int d = 0; d < 3; ++d)
      origins_[s][d] = static_cast<int>(std::floor(spheres.position[s][d] - ag)) - 2;
  const auto colours = make_colours(origins_, B, e);

  const int threads = omp_get_max_threads();
  if (static_cast<int>(workspaces_.size()) < threads)
    workspaces_.resize(static_cast<std::size_t>(threads));
  for (auto& w : workspaces_)
    if (!w) w = std::make_unique<Workspace>(B, markers);

  const double ball = 4.0 / 3.0 * M_PI * std::pow(ag + 2.6, 3);
  const bool use_field = static_cast<double>(n) * ball > 0.25 * static_cast<double>(e.cells());
  if (use_field) {
    const std::size_t cells = static_cast<std::size_t>(e.cells());
    field_rho_.resize(cells);
    field_ux_.resize(cells);
    field_uy_.resize(cells);
    field_uz_.resize(cells);
    fluid.macroscopic_field_without_force_field(field_rho_.data(), field_ux_.data(),
                                                field_uy_.data(), field_uz_.data());
  }
  std::vector<double> slip_sq(settings_.measure_slip ? n : 0),
      slip_max(settings_.measure_slip ? n : 0);
  Real* field[3] = {fluid.force_field(0), fluid.force_field(1), fluid.force_field(2)};
  const int iterations = settings_.iterations;
  const bool measure = settings_.measure_slip;

  auto process = [&](Workspace& ws, int s) {
    const Vec3 centre = spheres.position[static_cast<std::size_t>(s)];
    const Vec3 up = spheres.velocity[static_cast<std::size_t>(s)];
    const Vec3 omega = spheres.angular_velocity[static_cast<std::size_t>(s)];
    const auto& lo = origins_[static_cast<std::size_t>(s)];
    for (int d = 0; d < 3; ++d) {
      ws.global[d].resize(static_cast<std::size_t>(B));
      for (int i = 0; i < B; ++i)
        ws.global[d][static_cast<std::size_t>(i)] = wrap(lo[d] + i, length[d]);
    }
    // u* on every cell within a_g + 2.6 of the centre (all marker stencils,
    // sqrt(3) * 1.5 < 2.6, and the inside of the sphere), row by row so that
    // the 19 population streams are read in order.
    const double reach_sq = (ag + 2.6) * (ag + 2.6);
    for (int k = 0; k < B; ++k) {
      const double rz = lo[2] + k - centre[2];
      for (int j = 0; j < B; ++j) {
        const double ry = lo[1] + j - centre[1];
        const double left = reach_sq - ry * ry - rz * rz;
        if (left <= 0) continue;
        const double half = std::sqrt(left);
        const int i0 = std::max(0, static_cast<int>(std::ceil(centre[0] - half)) - lo[0]);
        const int i1 = std::min(B - 1, static_cast<int>(std::floor(centre[0] + half)) - lo[0]);
        const int gy = ws.global[1][static_cast<std::size_t>(j)];
        const int gz = ws.global[2][static_cast<std::size_t>(k)];
        const int row = B * (j + B * k);
        for (int i = i0; i <= i1; ++i) ws.touched.push_back(row + i);
        if (use_field) {
          const long grow = fluid.cell_index(0, gy, gz);
          for (int i = i0; i <= i1; ++i) {
            const long g = grow + ws.global[0][static_cast<std::size_t>(i)];
            const std::size_t lc = static_cast<std::size_t>(row + i);
            ws.rho[lc] = field_rho_[static_cast<std::size_t>(g)];
            ws.ux[lc] = field_ux_[static_cast<std::size_t>(g)];
            ws.uy[lc] = field_uy_[static_cast<std::size_t>(g)];
            ws.uz[lc] = field_uz_[static_cast<std::size_t>(g)];
          }
          continue;
        }
        // Read the row in pieces that do not cross the periodic edge in x.
        for (int i = i0; i <= i1;) {
          const int gx = ws.global[0][static_cast<std::size_t>(i)];
          const int count = std::min(i1 - i + 1, length[0] - gx);
          const std::size_t lc = static_cast<std::size_t>(row + i);
          fluid.macroscopic_row_without_force_field(gx, count, gy, gz, &ws.rho[lc], &ws.ux[lc],
                                                    &ws.uy[lc], &ws.uz[lc]);
          i += count;
        }
      }
    }
    // Stencils and targets of the markers.
    for (int m = 0; m < markers; ++m) {
      const Vec3 r = ag * directions_[static_cast<std::size_t>(m)];
      const Vec3 X = centre + r;
      const KernelWeights kx = kernel_weights(X[0]), ky = kernel_weights(X[1]),
                          kz = kernel_weights(X[2]);
      const int b = (kx.first - lo[0]) + B * ((ky.first - lo[1]) + B * (kz.first - lo[2]));
      ws.base[static_cast<std::size_t>(m)] = b;
      double* w = &ws.weights[static_cast<std::size_t>(m) * 9];
      for (int a = 0; a < 3; ++a) {
        w[a] = kx.w[a];
        w[3 + a] = ky.w[a];
        w[6 + a] = kz.w[a];
      }
      ws.target[static_cast<std::size_t>(m)] = up + omega.cross(r);
      ws.marker_force[static_cast<std::size_t>(m)].setZero();
    }
    // Interpolated density and velocity (with the force so far) at marker m.
    auto interpolate = [&](int m, double& rho, Vec3& u) {
      const int b = ws.base[static_cast<std::size_t>(m)];
      const double* w = &ws.weights[static_cast<std::size_t>(m) * 9];
      double r = 0, vx = 0, vy = 0, vz = 0;
      for (int c = 0; c < 3; ++c)
        for (int bb = 0; bb < 3; ++bb) {
          const double wyz = w[3 + bb] * w[6 + c];
          const std::size_t row = static_cast<std::size_t>(b + B * (bb + B * c));
          for (int a = 0; a < 3; ++a) {
            const std::size_t cell = row + static_cast<std::size_t>(a);
            const double wt = w[a] * wyz;
            const double h = 0.5 / ws.rho[cell];
            r += wt * ws.rho[cell];
            vx += wt * (ws.ux[cell] + h * ws.fx[cell]);
            vy += wt * (ws.uy[cell] + h * ws.fy[cell]);
            vz += wt * (ws.uz[cell] + h * ws.fz[cell]);
          }
        }
      rho = r;
      u = {vx, vy, vz};
    };
    for (int it = 0; it < iterations; ++it) {
      for (int m = 0; m < markers; ++m) {
        double rho;
        Vec3 u;
        interpolate(m, rho, u);
        ws.increment[static_cast<std::size_t>(m)] =
            2.0 * rho * (ws.target[static_cast<std::size_t>(m)] - u);
      }
      for (int m = 0; m < markers; ++m) {
        const Vec3 dF = ws.increment[static_cast<std::size_t>(m)];
        ws.marker_force[static_cast<std::size_t>(m)] += dF;
        const Vec3 spread = dF * dV;
        const int b = ws.base[static_cast<std::size_t>(m)];
        const double* w = &ws.weights[static_cast<std::size_t>(m) * 9];
        for (int c = 0; c < 3; ++c)
          for (int bb = 0; bb < 3; ++bb) {
            const double wyz = w[3 + bb] * w[6 + c];
            const std::size_t row = static_cast<std::size_t>(b + B * (bb + B * c));
            for (int a = 0; a < 3; ++a) {
              const std::size_t cell = row + static_cast<std::size_t>(a);
              const double wt = w[a] * wyz;
              ws.fx[cell] += wt * spread[0];
              ws.fy[cell] += wt * spread[1];
              ws.fz[cell] += wt * spread[2];
            }
          }
      }
    }
    if (measure) {
      double sq = 0, mx = 0;
      for (int m = 0; m < markers; ++m) {
        double rho;
        Vec3 u;
        interpolate(m, rho, u);
        const double err = (u - ws.target[static_cast<std::size_t>(m)]).norm();
        sq += err * err;
        mx = std::max(mx, err);
      }
      slip_sq[static_cast<std::size_t>(s)] = sq;
      slip_max[static_cast<std::size_t>(s)] = mx;
    }
    // Force and torque on the sphere: the reaction of the marker forces.
    Vec3 F = Vec3::Zero(), T = Vec3::Zero();
    for (int m = 0; m < markers; ++m) {
      const Vec3 Fm = ws.marker_force[static_cast<std::size_t>(m)] * dV;
      F -= Fm;
      T -= (ag * directions_[static_cast<std::size_t>(m)]).cross(Fm);
    }
    force_[static_cast<std::size_t>(s)] = F;
    torque_[static_cast<std::size_t>(s)] = T;
    // Momentum of the liquid inside, with the velocity the collision will see.
    Vec3 P = Vec3::Zero(), Lin = Vec3::Zero();
    const double reach = ag + 0.5;
    for (int k = 0; k < B; ++k) {
      const double rz = lo[2] + k - centre[2];
      if (std::abs(rz) >= reach) continue;
      for (int j = 0; j < B; ++j) {
        const double ry = lo[1] + j - centre[1];
        if (rz * rz + ry * ry >= reach * reach) continue;
        for (int i = 0; i < B; ++i) {
          const double rx = lo[0] + i - centre[0];
          const double dist = std::sqrt(rx * rx + ry * ry + rz * rz);
          const double w = std::min(1.0, reach - dist);
          if (w <= 0) continue;
          const std::size_t lc = static_cast<std::size_t>(i + B * (j + B * k));
          const Vec3 j_cell(ws.rho[lc] * ws.ux[lc] + 0.5 * ws.fx[lc],
                            ws.rho[lc] * ws.uy[lc] + 0.5 * ws.fy[lc],
                            ws.rho[lc] * ws.uz[lc] + 0.5 * ws.fz[lc]);
          P += w * j_cell;
          Lin += w * Vec3(rx, ry, rz).cross(j_cell);
        }
      }
    }
    momentum[static_cast<std::size_t>(s)] = P;
    angular[static_cast<std::size_t>(s)] = Lin;
    // Add this sphere's force to the lattice field and reset the scratch box.
    for (int cell : ws.touched) {
      const std::size_t lc = static_cast<std::size_t>(cell);
      const int i = cell % B, j = (cell / B) % B, k = cell / (B * B);
      const long g = fluid.cell_index(ws.global[0][static_cast<std::size_t>(i)],
                                      ws.global[1][static_cast<std::size_t>(j)],
                                      ws.global[2][static_cast<std::size_t>(k)]);
      field[0][g] += static_cast<Real>(ws.fx[lc]);
      field[1][g] += static_cast<Real>(ws.fy[lc]);
      field[2][g] += static_cast<Real>(ws.fz[lc]);
      ws.fx[lc] = ws.fy[lc] = ws.fz[lc] = 0.0;
    }
    ws.touched.clear();
  };

#pragma omp parallel
  {
    Workspace& ws = *workspaces_[static_cast<std::size_t>(omp_get_thread_num())];
    for (const auto& blocks : colours) {
#pragma omp for schedule(dynamic, 1)
      for (std::size_t b = 0; b < blocks.size(); ++b)
        for (int s : blocks[b]) process(ws, s);
    }
  }
  written_ = origins_;
  internal_momentum_change_.assign(n, Vec3::Zero());
  internal_angular_change_.assign(n, Vec3::Zero());
  if (have_previous)
    for (std::size_t s = 0; s < n; ++s) {
      internal_momentum_change_[s] = momentum[s] - internal_momentum_[s];
      internal_angular_change_[s] = angular[s] - internal_angular_[s];
    }
  internal_momentum_ = std::move(momentum);
  internal_angular_ = std::move(angular);

  if (measure) {
    double sq = 0, mx = 0;
    for (std::size_t s = 0; s < n; ++s) {
      sq += slip_sq[s];
      mx = std::max(mx, slip_max[s]);
    }
    rms_slip_ = n ? std::sqrt(sq / (static_cast<double>(n) * markers)) : 0.0;
    max_slip_ = mx;
  }
}

template <class Real>
void ImmersedBoundary<Real>::set_internal_momenta(std::vector<Vec3> momentum,
                                                  std::vector<Vec3> angular_momentum) {
  if (momentum.size() != angular_momentum.size())
    throw std::invalid_argument(
        "immersed boundary: internal momenta need one entry per sphere in both lists");
  internal_momentum_ = std::move(momentum);
  internal_angular_ = std::move(angular_momentum);
}

template class ImmersedBoundary<float>;
template class ImmersedBoundary<double>;

}  // namespace flocsim::immersed_boundary
