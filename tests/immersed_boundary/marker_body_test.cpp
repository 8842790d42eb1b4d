// The GPU's immersed boundary, run here on the CPU: a serial launcher that
// does, sphere after sphere, exactly the steps of the CUDA launcher
// (engine/coupling_gpu/marker_kernels.cu), its threads replaced by loops and
// its atomic additions by plain ones, calling the same kernel bodies
// (engine/immersed_boundary/marker_body.hpp) on the same marker setup
// (gpu::marker_setup). It must reproduce the CPU's ImmersedBoundary, the
// reference, which reaches the same method through 16-wide vectors over a
// padded box: force and torque on every sphere, the inside liquid's momenta
// and the force field cell by cell, to round-off, for direct forcing (one
// and three sweeps, both kernels) and control forcing (carried over steps),
// in float and double, with spheres whose boxes overlap and one across the
// periodic wrap.
//
// Round-off: the two sum the same terms in different orders (27 kernel
// weights per marker, ~600 markers per sphere, a few thousand inside cells),
// so they agree to a few hundred ulps of the largest magnitude compared:
// 1e-12 of it in double, 1e-4 in float (a float ulp is 6e-8; sums of ~10^3
// terms and differences of near-equal velocities U - u cost up to ~10^3).
#include "engine/immersed_boundary/marker_body.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/coupling_gpu/gpu_immersed_boundary.hpp"
#include "engine/coupling_gpu/marker_kernels.hpp"
#include "engine/immersed_boundary/immersed_boundary.hpp"
#include "engine/lattice/aa_cell.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "tests/immersed_boundary/coupling_scenes.hpp"
#include "tests/lattice/lattice_probes.hpp"

namespace flocsim::immersed_boundary {
namespace {

using spheres::Vec3;
using testing::control;
using testing::direct;
using testing::stir;
using testing::three_spheres;

struct PlainAdd {
  template <class Real>
  void operator()(Real* address, Real value) const {
    *address += value;
  }
};

// What the GPU keeps between steps (control forcing's carried state) and
// gives back each step.
template <class Real>
struct SerialState {
  std::vector<Real> marker_force, marker_slip;
  std::vector<double> loads;   // 12 per sphere, as MarkerKernels::apply
  std::vector<Real> field[3];  // the lattice's force field, x fastest
};

// One apply() of the GPU coupling, serially: marker_kernels.cu's
// sphere_kernel for each sphere in turn.
template <class Real, int W>
void serial_apply(const gpu::MarkerSetup& setup, const lattice::AaSlots<Real>& slots, bool even,
                  const lattice::Vector3& body, const spheres::SphereSet& spheres,
                  SerialState<Real>& state) {
  const long cells_total = static_cast<long>(slots.nx) * slots.ny * slots.nz;
  for (auto& f : state.field) f.assign(static_cast<std::size_t>(cells_total), Real(0));
  const std::size_t n = spheres.size();
  const int M = setup.markers, B = setup.box;
  const long cells = static_cast<long>(B) * B * B;
  if (state.marker_force.size() != 4 * n * M) {
    state.marker_force.assign(4 * n * M, Real(0));
    state.marker_slip.assign(4 * n * M, Real(0));
  }
  std::vector<Real> increment(4 * M), velocity(4 * cells), force(4 * cells);
  state.loads.assign(gpu::kLoadNumbers * n, 0.0);
  const Real dV = static_cast<Real>(setup.marker_volume);
  for (std::size_t s = 0; s < n; ++s) {
    const double centre[3] = {spheres.position[s][0], spheres.position[s][1],
                              spheres.position[s][2]};
    const double up[3] = {spheres.velocity[s][0], spheres.velocity[s][1], spheres.velocity[s][2]};
    const double omega[3] = {spheres.angular_velocity[s][0], spheres.angular_velocity[s][1],
                             spheres.angular_velocity[s][2]};
    SphereBox<Real> box;
    box.B = B;
    box.velocity = velocity.data();
    box.force = force.data();
    for (int d = 0; d < 3; ++d)
      box.lo[d] = static_cast<int>(std::floor(centre[d] - setup.input_radius)) - 2;
    for (long c = 0; c < cells; ++c) {  // load
      const int i = static_cast<int>(c % B), j = static_cast<int>((c / B) % B),
                k = static_cast<int>(c / (static_cast<long>(B) * B));
      Real f[d3q19::kQ];
      lattice::aa_load_cell(slots, wrap_coordinate(box.lo[0] + i, slots.nx),
                            wrap_coordinate(box.lo[1] + j, slots.ny),
                            wrap_coordinate(box.lo[2] + k, slots.nz), even, f);
      Real* u = box.velocity + 4 * c;
      lattice::cell_moments(f, static_cast<Real>(body.x), static_cast<Real>(body.y),
                            static_cast<Real>(body.z), u[0], u[1], u[2], u[3]);
      for (int q = 0; q < 4; ++q) box.force[4 * c + q] = 0;
    }
    Real* F_all = &state.marker_force[4 * s * M];
    Real* e_all = &state.marker_slip[4 * s * M];
    auto stencil = [&](int m) {
      return marker_stencil<Real, W>(centre, &setup.offsets[3 * m], box.lo);
    };
    auto spread_all = [&] {
      for (int m = 0; m < M; ++m) {
        const Real F_dV[3] = {increment[4 * m + 1], increment[4 * m + 2], increment[4 * m + 3]};
        spread_from_marker(box, stencil(m), F_dV, PlainAdd{});
      }
    };
    auto interpolate_and_force = [&](bool with_force) {
      for (int m = 0; m < M; ++m) {
        const double* r = &setup.offsets[3 * m];
        double Ud[3];
        surface_velocity_at(up, omega, r, Ud);
        const Real U[3] = {static_cast<Real>(Ud[0]), static_cast<Real>(Ud[1]),
                           static_cast<Real>(Ud[2])};
        Real rho_v[4];
        interpolate_at_marker(box, stencil(m), with_force, rho_v);
        Real* F = F_all + 4 * m;
        Real dF[3];
        if (setup.control) {
          Real slip[3] = {e_all[4 * m + 1], e_all[4 * m + 2], e_all[4 * m + 3]};
          control_forcing_increment(rho_v, U, slip, static_cast<Real>(setup.integral_gain),
                                    static_cast<Real>(setup.proportional_gain), dF);
          for (int d = 0; d < 3; ++d) {
            e_all[4 * m + 1 + d] = slip[d];
            F[1 + d] += dF[d];
            increment[4 * m + 1 + d] = F[1 + d] * dV;
          }
        } else {
          direct_forcing_increment(rho_v, U, dF);
          for (int d = 0; d < 3; ++d) {
            F[1 + d] += dF[d];
            increment[4 * m + 1 + d] = dF[d] * dV;
          }
        }
      }
    };
    if (setup.control) {
      for (int q = 0; q < 4 * M; ++q) increment[q] = F_all[q] * dV;
      spread_all();
      interpolate_and_force(true);
      std::fill(force.begin(), force.end(), Real(0));
      spread_all();
    } else {
      std::fill(F_all, F_all + 4 * M, Real(0));
      for (int sweep = 0; sweep < setup.sweeps; ++sweep) {
        interpolate_and_force(sweep > 0);
        spread_all();
      }
    }
    double* out = &state.loads[gpu::kLoadNumbers * s];
    for (int m = 0; m < M; ++m) {  // loads
      const double Fm[3] = {F_all[4 * m + 1] * setup.marker_volume,
                            F_all[4 * m + 2] * setup.marker_volume,
                            F_all[4 * m + 3] * setup.marker_volume};
      const double* r = &setup.offsets[3 * m];
      out[0] -= Fm[0];
      out[1] -= Fm[1];
      out[2] -= Fm[2];
      out[3] -= r[1] * Fm[2] - r[2] * Fm[1];
      out[4] -= r[2] * Fm[0] - r[0] * Fm[2];
      out[5] -= r[0] * Fm[1] - r[1] * Fm[0];
    }
    for (long c = 0; c < cells; ++c) {  // inside, and the write to the field
      const int i = static_cast<int>(c % B), j = static_cast<int>((c / B) % B),
                k = static_cast<int>(c / (static_cast<long>(B) * B));
      double P[3], L[3];
      if (inside_share(box, i, j, k, centre, setup.input_radius, P, L))
        for (int d = 0; d < 3; ++d) {
          out[6 + d] += P[d];
          out[9 + d] += L[d];
        }
      const long cell = lattice::aa_cell_index(slots, wrap_coordinate(box.lo[0] + i, slots.nx),
                                               wrap_coordinate(box.lo[1] + j, slots.ny),
                                               wrap_coordinate(box.lo[2] + k, slots.nz));
      for (int d = 0; d < 3; ++d) state.field[d][cell] += box.force[4 * c + 1 + d];
    }
  }
}

double largest(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

template <class Real>
constexpr double kRoundOff = sizeof(Real) == 8 ? 1e-12 : 1e-4;

// Compares the serial launcher's step against the CPU coupling's.
template <class Real>
void expect_same_step(ImmersedBoundary<Real>& cpu, lattice::FluidLattice<Real>& fluid,
                      const SerialState<Real>& gpu_state, std::size_t n) {
  std::vector<double> force, torque, momentum, angular;
  for (std::size_t s = 0; s < n; ++s)
    for (int d = 0; d < 3; ++d) {
      force.push_back(cpu.force()[s][d]);
      torque.push_back(cpu.torque()[s][d]);
      momentum.push_back(cpu.internal_momentum()[s][d]);
      angular.push_back(cpu.internal_angular_momentum()[s][d]);
    }
  const std::vector<double>* reference[4] = {&force, &torque, &momentum, &angular};
  const char* names[4] = {"force", "torque", "inside momentum", "inside angular momentum"};
  for (int q = 0; q < 4; ++q) {
    const double scale = largest(*reference[q]);
    ASSERT_GT(scale, 0) << names[q] << " is zero: the test would prove nothing";
    for (std::size_t s = 0; s < n; ++s)
      for (int d = 0; d < 3; ++d)
        EXPECT_NEAR(gpu_state.loads[gpu::kLoadNumbers * s + 3 * q + d], (*reference[q])[3 * s + d],
                    kRoundOff<Real> * scale)
            << names[q] << " of sphere " << s << ", component " << d;
  }
  const auto field = fluid.force_field();
  const long cells = fluid.extent().cells();
  double scale = 0, worst = 0;
  for (int d = 0; d < 3; ++d)
    for (long c = 0; c < cells; ++c) {
      scale = std::max(scale, std::abs(static_cast<double>(field.component[d][c])));
      worst = std::max(worst, std::abs(static_cast<double>(field.component[d][c]) -
                                       gpu_state.field[d][static_cast<std::size_t>(c)]));
    }
  ASSERT_GT(scale, 0);
  EXPECT_LE(worst, kRoundOff<Real> * scale) << "force field, largest difference";
}

template <class Real, int W>
void expect_serial_launcher_matches_cpu(coupling::Scheme scheme, int steps) {
  const lattice::Extent e{32, 30, 28};
  lattice::FluidLattice<Real> fluid(e, {0.02, 0.25});
  stir(fluid);
  fluid.step();  // one step old: the odd parity first
  const ImmersedBoundarySettings settings{.input_radius = 3.7, .scheme = scheme};
  ImmersedBoundary<Real> cpu(settings);
  const gpu::MarkerSetup setup = gpu::marker_setup(settings);
  ASSERT_EQ(setup.markers, cpu.markers_per_sphere());
  ASSERT_EQ(setup.kernel_width, W);
  const spheres::SphereSet spheres = three_spheres();
  SerialState<Real> state;
  for (int step = 0; step < steps; ++step) {
    // the serial launcher reads the populations as the CPU coupling does:
    // before its force is applied, at the lattice's current parity
    std::vector<Real> slots = testing::slots_of(fluid);
    const lattice::AaSlots<Real> s{slots.data(), e.cells(), e.nx, e.ny, e.nz};
    serial_apply<Real, W>(setup, s, fluid.time_step() % 2 == 0, fluid.body_force(), spheres, state);
    cpu.apply(fluid, spheres);
    SCOPED_TRACE("step " + std::to_string(step) + " (time step " +
                 std::to_string(fluid.time_step()) + ")");
    expect_same_step(cpu, fluid, state, spheres.size());
    fluid.step();  // with the CPU's force: both go on from the same liquid
  }
  if (scheme.control()) {  // the carried state, in the CPU's layout
    const auto memory = cpu.memory();
    ASSERT_EQ(memory.size(), 2u);
    const std::vector<Real>* carried[2] = {&state.marker_force, &state.marker_slip};
    for (int a = 0; a < 2; ++a) {
      const std::vector<double>& ref = memory[static_cast<std::size_t>(a)].values;
      ASSERT_EQ(ref.size() * 4, carried[a]->size() * 3);
      const double scale = largest(ref);
      for (std::size_t k = 0; k < ref.size() / 3; ++k)
        for (int d = 0; d < 3; ++d)
          EXPECT_NEAR((*carried[a])[4 * k + 1 + d], ref[3 * k + d], kRoundOff<Real> * scale)
              << memory[static_cast<std::size_t>(a)].name << " of marker " << k;
    }
  }
}

TEST(MarkerBody, OneSweepRomaMatchesTheCpuCouplingInDouble) {
  expect_serial_launcher_matches_cpu<double, 3>(direct(1, coupling::Kernel::roma3), 2);
}

TEST(MarkerBody, ThreeSweepsRomaMatchTheCpuCouplingInFloat) {
  expect_serial_launcher_matches_cpu<float, 3>(direct(3, coupling::Kernel::roma3), 2);
}

TEST(MarkerBody, TwoSweepsLinearHatMatchTheCpuCouplingInDouble) {
  expect_serial_launcher_matches_cpu<double, 2>(direct(2, coupling::Kernel::linear2), 2);
}

TEST(MarkerBody, ControlForcingCarriedOverStepsMatchesTheCpuCoupling) {
  expect_serial_launcher_matches_cpu<double, 3>(control(), 3);
  expect_serial_launcher_matches_cpu<float, 3>(control(), 3);
}

// The kernel body's stencil against the kernel's definition (kernel.hpp's
// roma_kernel, linear_kernel): the weight of every cell the stencil covers is
// the kernel at that cell's distance from the marker, and the cells just
// outside it have kernel weight zero (the stencil misses none).
TEST(MarkerBody, StencilWeightsAreTheKernelAtTheCellDistances) {
  const int lo[3] = {-3, 5, 10};
  const double centre[3] = {1.37, 9.02, 14.5};
  const double offset[3] = {0.21, -0.49, 0.0};  // Y = 8.53, Z = 14.5: a half-way node
  const double X[3] = {centre[0] + offset[0], centre[1] + offset[1], centre[2] + offset[2]};
  const auto roma = marker_stencil<double, 3>(centre, offset, lo);
  const auto hat = marker_stencil<double, 2>(centre, offset, lo);
  auto cell = [&](int d, int first, int a) { return static_cast<double>(lo[d] + first + a); };
  for (int d = 0; d < 3; ++d) {
    EXPECT_EQ(roma_kernel(cell(d, roma.first[d], -1) - X[d]), 0.0) << "direction " << d;
    EXPECT_EQ(roma_kernel(cell(d, roma.first[d], 3) - X[d]), 0.0) << "direction " << d;
    EXPECT_EQ(linear_kernel(cell(d, hat.first[d], -1) - X[d]), 0.0) << "direction " << d;
    EXPECT_EQ(linear_kernel(cell(d, hat.first[d], 2) - X[d]), 0.0) << "direction " << d;
  }
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR(roma.wx[a], roma_kernel(cell(0, roma.first[0], a) - X[0]), 1e-15);
  for (int a = 0; a < 2; ++a)
    EXPECT_NEAR(hat.wx[a], linear_kernel(cell(0, hat.first[0], a) - X[0]), 1e-15);
  for (int c = 0; c < 3; ++c)
    for (int b = 0; b < 3; ++b)
      EXPECT_NEAR(roma.wyz[b + 3 * c],
                  roma_kernel(cell(1, roma.first[1], b) - X[1]) *
                      roma_kernel(cell(2, roma.first[2], c) - X[2]),
                  1e-15);
  for (int c = 0; c < 2; ++c)
    for (int b = 0; b < 2; ++b)
      EXPECT_NEAR(hat.wyz[b + 2 * c],
                  linear_kernel(cell(1, hat.first[1], b) - X[1]) *
                      linear_kernel(cell(2, hat.first[2], c) - X[2]),
                  1e-15);
}

}  // namespace
}  // namespace flocsim::immersed_boundary
