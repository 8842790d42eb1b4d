// The lattice-Boltzmann fluid against references it did not produce itself:
//  - a plain two-array "push" D3Q19 TRT + Guo implementation written here from
//    the formulas, on full populations f_i (the engine stores f_i - w_i and
//    streams in place with the AA pattern), compared population by population;
//  - initialisation at an odd time step (the AA storage slot depends on parity);
//  - Kolmogorov flow, F_y = F0 sin(k x): steady Stokes balance and the exact
//    steady state of the discrete TRT scheme, derived below;
//  - a Taylor-Green vortex with different wave numbers along its two axes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "engine/lattice/d3q19.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "tests/lattice/lattice_probes.hpp"

namespace flocsim::lattice {
namespace {

using d3q19::cx;
using d3q19::cy;
using d3q19::cz;
using d3q19::kQ;

// ---------------------------------------------------------------------------
// Reference implementation. Two arrays, full populations, push streaming:
//   f_i(x + c_i, t + 1) = f_i(x, t) - omega+ (f+_i - feq+_i) - omega- (f-_i - feq-_i)
//                         + (1 - omega+/2) S+_i + (1 - omega-/2) S-_i
// with f+-_i = (f_i +- f_opp(i)) / 2, rho = sum f, rho u = sum c f + F/2,
// feq_i = w_i rho (1 + 3 c.u + 9/2 (c.u)^2 - 3/2 u.u),
// Guo source S_i = w_i [3 (c - u).F + 9 (c.u)(c.F)] split into
// S+_i = w_i [9 (c.u)(c.F) - 3 u.F] and S-_i = 3 w_i c.F,
// omega+ = 1/tau+, tau+ = 3 nu + 1/2, and tau- from
// Lambda = (tau+ - 1/2)(tau- - 1/2). Weights and opposites are derived here
// from the velocity vectors, only c_i is taken from d3q19.hpp.
class ReferenceLattice {
 public:
  ReferenceLattice(Extent extent, double nu, double lambda) : e_(extent) {
    const double tau_plus = 3.0 * nu + 0.5;
    const double tau_minus = 0.5 + lambda / (tau_plus - 0.5);
    omega_plus_ = 1.0 / tau_plus;
    omega_minus_ = 1.0 / tau_minus;
    for (int i = 0; i < kQ; ++i) {
      const int c2 = cx[i] * cx[i] + cy[i] * cy[i] + cz[i] * cz[i];
      weight_[i] = c2 == 0 ? 1.0 / 3.0 : c2 == 1 ? 1.0 / 18.0 : 1.0 / 36.0;
      for (int j = 0; j < kQ; ++j)
        if (cx[j] == -cx[i] && cy[j] == -cy[i] && cz[j] == -cz[i]) opposite_[i] = j;
    }
    const auto n = static_cast<std::size_t>(e_.cells());
    f_.assign(n * kQ, 0.0);
    for (auto& component : force_) component.assign(n, 0.0);
  }

  long index(int x, int y, int z) const {
    x = (x % e_.nx + e_.nx) % e_.nx;
    y = (y % e_.ny + e_.ny) % e_.ny;
    z = (z % e_.nz + e_.nz) % e_.nz;
    return x + static_cast<long>(e_.nx) * (y + static_cast<long>(e_.ny) * z);
  }
  std::array<std::vector<double>, 3>& force_field() { return force_; }
  void set_body_force(Vector3 b) { body_ = b; }

  double population(int i, int x, int y, int z) const { return f_[slot(i, index(x, y, z))]; }

  // Total force on cell c (body force plus, if with_field, the per-cell field).
  std::array<double, 3> force(long c, bool with_field = true) const {
    std::array<double, 3> F = {body_.x, body_.y, body_.z};
    if (with_field)
      for (int d = 0; d < 3; ++d) F[d] += force_[d][static_cast<std::size_t>(c)];
    return F;
  }

  Macroscopic macroscopic(int x, int y, int z, bool with_field = true) const {
    const long c = index(x, y, z);
    double rho = 0, j[3] = {0, 0, 0};
    for (int i = 0; i < kQ; ++i) {
      const double fi = f_[slot(i, c)];
      rho += fi;
      j[0] += cx[i] * fi;
      j[1] += cy[i] * fi;
      j[2] += cz[i] * fi;
    }
    const auto F = force(c, with_field);
    return {rho, {(j[0] + 0.5 * F[0]) / rho, (j[1] + 0.5 * F[1]) / rho, (j[2] + 0.5 * F[2]) / rho}};
  }

  // Equilibrium of (rho, u - F/(2 rho)), so that u reads back with the half-force shift.
  template <class Field>
  void initialise(Field&& field) {
    for (int z = 0; z < e_.nz; ++z)
      for (int y = 0; y < e_.ny; ++y)
        for (int x = 0; x < e_.nx; ++x) {
          const Macroscopic m = field(x, y, z);
          const long c = index(x, y, z);
          const auto F = force(c);
          const double u[3] = {m.velocity.x - 0.5 * F[0] / m.density,
                               m.velocity.y - 0.5 * F[1] / m.density,
                               m.velocity.z - 0.5 * F[2] / m.density};
          for (int i = 0; i < kQ; ++i) f_[slot(i, c)] = equilibrium(i, m.density, u);
        }
  }

  void step() {
    std::vector<double> next(f_.size(), 0.0);
    for (int z = 0; z < e_.nz; ++z)
      for (int y = 0; y < e_.ny; ++y)
        for (int x = 0; x < e_.nx; ++x) {
          const long c = index(x, y, z);
          double f[kQ];
          for (int i = 0; i < kQ; ++i) f[i] = f_[slot(i, c)];
          double rho = 0, j[3] = {0, 0, 0};
          for (int i = 0; i < kQ; ++i) {
            rho += f[i];
            j[0] += cx[i] * f[i];
            j[1] += cy[i] * f[i];
            j[2] += cz[i] * f[i];
          }
          const auto F = force(c);
          const double u[3] = {(j[0] + 0.5 * F[0]) / rho, (j[1] + 0.5 * F[1]) / rho,
                               (j[2] + 0.5 * F[2]) / rho};
          double feq[kQ];
          for (int i = 0; i < kQ; ++i) feq[i] = equilibrium(i, rho, u);
          const double uF = u[0] * F[0] + u[1] * F[1] + u[2] * F[2];
          for (int i = 0; i < kQ; ++i) {
            const int o = opposite_[i];
            const double cu = cx[i] * u[0] + cy[i] * u[1] + cz[i] * u[2];
            const double cF = cx[i] * F[0] + cy[i] * F[1] + cz[i] * F[2];
            const double f_plus = 0.5 * (f[i] + f[o]), f_minus = 0.5 * (f[i] - f[o]);
            const double eq_plus = 0.5 * (feq[i] + feq[o]), eq_minus = 0.5 * (feq[i] - feq[o]);
            const double source_plus = weight_[i] * (9.0 * cu * cF - 3.0 * uF);
            const double source_minus = weight_[i] * 3.0 * cF;
            const double post =
                f[i] - omega_plus_ * (f_plus - eq_plus) - omega_minus_ * (f_minus - eq_minus) +
                (1.0 - 0.5 * omega_plus_) * source_plus + (1.0 - 0.5 * omega_minus_) * source_minus;
            next[slot(i, index(x + cx[i], y + cy[i], z + cz[i]))] = post;
          }
        }
    f_.swap(next);
  }

 private:
  std::size_t slot(int i, long c) const {
    return static_cast<std::size_t>(i) * static_cast<std::size_t>(e_.cells()) +
           static_cast<std::size_t>(c);
  }
  double equilibrium(int i, double rho, const double (&u)[3]) const {
    const double cu = cx[i] * u[0] + cy[i] * u[1] + cz[i] * u[2];
    const double usq = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    return weight_[i] * rho * (1.0 + 3.0 * cu + 4.5 * cu * cu - 1.5 * usq);
  }

  Extent e_;
  double omega_plus_ = 1, omega_minus_ = 1;
  std::array<double, kQ> weight_{};
  std::array<int, kQ> opposite_{};
  std::vector<double> f_;
  std::array<std::vector<double>, 3> force_;
  Vector3 body_;
};

// Largest |engine - reference| over every population of every cell, and over
// every macroscopic read-out (density, velocity with and without the per-cell
// field; the latter also through the row accessor).
struct Difference {
  double population = 0, macroscopic = 0;
};

Difference compare(const FluidLattice<double>& fluid, const ReferenceLattice& ref) {
  const Extent e = fluid.extent();
  Difference d;
  std::vector<double> rho(static_cast<std::size_t>(e.nx)), ux(rho.size()), uy(rho.size()),
      uz(rho.size());
  auto worst = [&d](const Macroscopic& a, const Macroscopic& b) {
    d.macroscopic = std::max(
        {d.macroscopic, std::abs(a.density - b.density), std::abs(a.velocity.x - b.velocity.x),
         std::abs(a.velocity.y - b.velocity.y), std::abs(a.velocity.z - b.velocity.z)});
  };
  for (int z = 0; z < e.nz; ++z)
    for (int y = 0; y < e.ny; ++y) {
      fluid.macroscopic_row_without_force_field(0, e.nx, y, z, rho.data(), ux.data(), uy.data(),
                                                uz.data());
      for (int x = 0; x < e.nx; ++x) {
        for (int i = 0; i < kQ; ++i)
          d.population = std::max(
              d.population, std::abs(fluid.population(i, x, y, z) - ref.population(i, x, y, z)));
        worst(fluid.macroscopic(x, y, z), ref.macroscopic(x, y, z));
        const Macroscopic no_field = ref.macroscopic(x, y, z, false);
        worst(testing::macroscopic_without_force_field(fluid, x, y, z), no_field);
        const auto k = static_cast<std::size_t>(x);
        worst(Macroscopic{rho[k], {ux[k], uy[k], uz[k]}}, no_field);
      }
    }
  return d;
}

// Same random state in the engine and in the reference: per-cell density
// 1 +- 0.05 and velocity components +- 0.05 (through initialise_equilibrium,
// the only public way in), per-cell force components +- 2e-3 when with_field,
// and a uniform body force.
void randomise(FluidLattice<double>& fluid, ReferenceLattice& ref, bool with_field, unsigned seed) {
  const Extent e = fluid.extent();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Vector3 body{3e-4, -5e-4, 2e-4};
  fluid.set_body_force(body);
  ref.set_body_force(body);
  if (with_field) {
    fluid.enable_force_field();
    for (int z = 0; z < e.nz; ++z)
      for (int y = 0; y < e.ny; ++y)
        for (int x = 0; x < e.nx; ++x)
          for (int d = 0; d < 3; ++d) {
            const double F = 2e-3 * unit(rng);
            fluid.force_field().component[d][fluid.cell_index(x, y, z)] = F;
            ref.force_field()[static_cast<std::size_t>(d)]
                             [static_cast<std::size_t>(ref.index(x, y, z))] = F;
          }
  }
  std::vector<Macroscopic> state(static_cast<std::size_t>(e.cells()));
  for (auto& m : state)
    m = {1.0 + 0.05 * unit(rng), {0.05 * unit(rng), 0.05 * unit(rng), 0.05 * unit(rng)}};
  auto field = [&](int x, int y, int z) {
    return state[static_cast<std::size_t>(fluid.cell_index(x, y, z))];
  };
  fluid.initialise_equilibrium(field);
  ref.initialise(field);
}

// Engine and reference differ only by rounding: the engine works on the
// deviations f_i - w_i (O(1e-2)), the reference on f_i (O(0.3)), both in
// double, so a population differs by a few ulp of 0.3 (~1e-16) per operation
// and step; 1e-13 leaves a factor ~100 over a 4-step run and is still 1e-8 of
// the smallest force term, (1 - omega-/2) 3 w_i c.F >~ 1e-5 for the body force.
constexpr double kRoundOff = 1e-13;

struct StepCase {
  Extent extent;
  double nu, lambda;
  bool force_field;
};

class ReferenceStep : public ::testing::TestWithParam<StepCase> {};

TEST_P(ReferenceStep, EveryPopulationMatchesThePushReferenceForFourSteps) {
  // Extents of 1, 2, 3 and 5 cells along each axis: a row of one cell streams
  // onto itself, two cells wrap both ways onto the same neighbour, and the
  // odd (neighbour-addressed) AA step takes its explicit wrap path at both ends
  // of every row. Four steps cover both parities twice.
  const StepCase p = GetParam();
  FluidLattice<double> fluid(p.extent, {p.nu, p.lambda});
  ReferenceLattice ref(p.extent, p.nu, p.lambda);
  randomise(fluid, ref, p.force_field, 17u + static_cast<unsigned>(p.extent.cells()));

  const Difference d0 = compare(fluid, ref);
  EXPECT_LE(d0.population, kRoundOff) << "initial state";
  EXPECT_LE(d0.macroscopic, kRoundOff) << "initial state";
  const ReferenceLattice initial = ref;
  for (int t = 1; t <= 4; ++t) {
    fluid.step();
    ref.step();
    const Difference d = compare(fluid, ref);
    std::printf(
        "%d x %d x %d, nu %.3f, Lambda %.4f, field %d, step %d: max |df| = %.2e, "
        "max |d macro| = %.2e\n",
        p.extent.nx, p.extent.ny, p.extent.nz, p.nu, p.lambda, p.force_field, t, d.population,
        d.macroscopic);
    EXPECT_LE(d.population, kRoundOff) << "after step " << t;
    EXPECT_LE(d.macroscopic, kRoundOff) << "after step " << t;
  }
  // the comparison is not vacuous: the populations moved by far more than the tolerance
  const double moved = compare(fluid, initial).population;
  std::printf("largest population change over the four steps: %.2e\n", moved);
  EXPECT_GT(moved, 1e6 * kRoundOff);
}

INSTANTIATE_TEST_SUITE_P(
    Extents, ReferenceStep,
    ::testing::Values(StepCase{{1, 3, 5}, 0.05, 0.25, true}, StepCase{{2, 5, 3}, 0.005, 0.25, true},
                      StepCase{{5, 2, 1}, 0.1, 1.0 / 12.0, true},
                      StepCase{{3, 1, 2}, 1.0 / 6.0, 3.0 / 16.0, true},
                      StepCase{{5, 5, 5}, 0.02, 0.4, true},
                      // the kernel without a per-cell force field is a separate instantiation
                      StepCase{{5, 2, 3}, 0.05, 0.25, false},
                      StepCase{{1, 1, 2}, 0.3, 0.25, false}),
    [](const ::testing::TestParamInfo<StepCase>& case_info) {
      const StepCase& c = case_info.param;
      return std::to_string(c.extent.nx) + "x" + std::to_string(c.extent.ny) + "x" +
             std::to_string(c.extent.nz) + (c.force_field ? "_force_field" : "_body_force_only");
    });

// ---------------------------------------------------------------------------
// Initialisation at an odd time step: the AA layout then keeps population i of
// cell x in the opposite slot of cell x - c_i.

void expect_reads_back(const FluidLattice<double>& fluid, const std::vector<Macroscopic>& state) {
  // The stored equilibrium is of u - F/(2 rho); reading back adds F/2 again.
  // Exact up to the rounding of 19-term sums of O(1e-2) deviations: 1e-14.
  const Extent e = fluid.extent();
  double worst = 0;
  for (int z = 0; z < e.nz; ++z)
    for (int y = 0; y < e.ny; ++y)
      for (int x = 0; x < e.nx; ++x) {
        const Macroscopic m = fluid.macroscopic(x, y, z);
        const Macroscopic& g = state[static_cast<std::size_t>(fluid.cell_index(x, y, z))];
        worst = std::max(
            {worst, std::abs(m.density - g.density), std::abs(m.velocity.x - g.velocity.x),
             std::abs(m.velocity.y - g.velocity.y), std::abs(m.velocity.z - g.velocity.z)});
      }
  std::printf("odd-step initialisation: max |read back - given| = %.2e\n", worst);
  EXPECT_LE(worst, 1e-14);
}

std::vector<Macroscopic> random_state(Extent e, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Macroscopic> state(static_cast<std::size_t>(e.cells()));
  for (auto& m : state)
    m = {1.0 + 0.04 * unit(rng), {0.04 * unit(rng), 0.04 * unit(rng), 0.04 * unit(rng)}};
  return state;
}

void set_random_force(FluidLattice<double>& fluid, ReferenceLattice& ref, unsigned seed) {
  const Extent e = fluid.extent();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Vector3 body{-2e-4, 1e-4, 4e-4};
  fluid.set_body_force(body);
  ref.set_body_force(body);
  fluid.enable_force_field();
  for (int z = 0; z < e.nz; ++z)
    for (int y = 0; y < e.ny; ++y)
      for (int x = 0; x < e.nx; ++x)
        for (int d = 0; d < 3; ++d) {
          const double F = 1e-3 * unit(rng);
          fluid.force_field().component[d][fluid.cell_index(x, y, z)] = F;
          ref.force_field()[static_cast<std::size_t>(d)]
                           [static_cast<std::size_t>(ref.index(x, y, z))] = F;
        }
}

TEST(OddTimeStepInitialisation, SetTimeStepOneThenInitialise) {
  const Extent e{3, 2, 5};
  const double nu = 0.03, lambda = 0.25;
  FluidLattice<double> fluid(e, {nu, lambda});
  ReferenceLattice ref(e, nu, lambda);
  set_random_force(fluid, ref, 3);
  const auto state = random_state(e, 4);
  auto field = [&](int x, int y, int z) {
    return state[static_cast<std::size_t>(fluid.cell_index(x, y, z))];
  };
  fluid.set_time_step(1);
  fluid.initialise_equilibrium(field);
  ref.initialise(field);
  expect_reads_back(fluid, state);
  EXPECT_LE(compare(fluid, ref).population, kRoundOff) << "initial state";
  for (int t = 1; t <= 2; ++t) {  // an odd, then an even step
    fluid.step();
    ref.step();
    const Difference d = compare(fluid, ref);
    std::printf("initialised at t = 1, step %d: max |df| = %.2e\n", t, d.population);
    EXPECT_LE(d.population, kRoundOff) << "after step " << t;
    EXPECT_LE(d.macroscopic, kRoundOff) << "after step " << t;
  }
  EXPECT_EQ(fluid.time_step(), 3);
}

TEST(OddTimeStepInitialisation, StepOnceThenReinitialise) {
  // A state already evolved by one step (odd layout) is overwritten: nothing of
  // the old state may survive in any slot that is read later.
  const Extent e{2, 1, 3};
  const double nu = 0.1, lambda = 1.0 / 6.0;
  FluidLattice<double> fluid(e, {nu, lambda});
  ReferenceLattice ref(e, nu, lambda);
  set_random_force(fluid, ref, 5);
  const auto old_state = random_state(e, 6);
  fluid.initialise_equilibrium([&](int x, int y, int z) {
    return old_state[static_cast<std::size_t>(fluid.cell_index(x, y, z))];
  });
  fluid.step();
  ASSERT_EQ(fluid.time_step(), 1);
  const auto state = random_state(e, 7);
  auto field = [&](int x, int y, int z) {
    return state[static_cast<std::size_t>(fluid.cell_index(x, y, z))];
  };
  fluid.initialise_equilibrium(field);
  ref.initialise(field);
  expect_reads_back(fluid, state);
  for (int t = 1; t <= 3; ++t) {
    fluid.step();
    ref.step();
    const Difference d = compare(fluid, ref);
    std::printf("re-initialised at t = 1, step %d: max |df| = %.2e\n", t, d.population);
    EXPECT_LE(d.population, kRoundOff) << "after step " << t;
    EXPECT_LE(d.macroscopic, kRoundOff) << "after step " << t;
  }
}

// ---------------------------------------------------------------------------
// Kolmogorov flow: F_y = F0 sin(k x), rho = 1, in a periodic box. The steady
// Stokes balance nu u'' + F = 0 gives u_y = F0 / (nu k^2) sin(k x).
//
// Exact steady state of the discrete scheme (linear in F0). With all fields
// proportional to exp(i k x) and only u_y, F_y nonzero, the pairs with c_x = 0
// and c_y != 0 (weights 1/18 + 2/36 = 1/9) reach f-_i - feq-_i = Lambda- S-_i,
// Lambda- = 1/omega- - 1/2; for the two diagonal pairs with c_x = +-1, c_y != 0
// (weight 1/36 each) steady streaming f_i(x + c) = post-collision f_i(x) gives
// f-_i (D) = omega- feq-_i + (1 - omega-/2) S-_i,
// D = omega- + (cos k - 1) + sin^2 k / (cos k - 1 + omega+).
// Momentum, sum_i c_y (f_i - feq_i) = -F/2, then yields
//   nu u / F = 1 / (2 (1 - cos k)) - 1/4 + 2 Lambda / 3
//            = [1 + (2 Lambda / 3 - 1/6) k^2 + O(k^4)] / k^2,
// which depends on nu only through 1/nu: the relative error is a function of
// Lambda and k dx alone. The O((k dx)^2) coefficient is 2 Lambda/3 - 1/6: zero
// at Lambda = 1/4 (error k^4/240 = 6e-6 at 32 cells per wavelength), -0.43 %
// at Lambda = 1/12 and +0.64 % at Lambda = 1/2. Had the velocity lacked the
// half-force shift, the amplitude would be lower by F0/2, a relative nu k^2/2
// that grows with nu (1.9 % at nu = 1, 32 cells).
double kolmogorov_discrete_ratio(double k, double lambda) {
  // (discrete amplitude) / (Stokes amplitude F0 / (nu k^2))
  return k * k * (0.5 / (1.0 - std::cos(k)) - 0.25 + 2.0 * lambda / 3.0);
}

struct KolmogorovResult {
  double ratio;         // measured amplitude / (F0 / (nu k^2))
  double out_of_phase;  // cos-projection of u_y and largest |u_x|, |u_z|, relative to the amplitude
};

KolmogorovResult kolmogorov(double nu, double lambda, int n) {
  const double k = 2 * M_PI / n;
  const double U = 1e-3;  // Stokes amplitude; nonlinear terms enter at relative O(U^2)
  const double F0 = U * nu * k * k;
  FluidLattice<double> fluid({n, 2, 1}, {nu, lambda});
  fluid.enable_force_field();
  for (int z = 0; z < 1; ++z)
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < n; ++x)
        fluid.force_field().component[1][fluid.cell_index(x, y, z)] = F0 * std::sin(k * x);
  fluid.initialise_equilibrium([](int, int, int) { return Macroscopic{1.0, {0, 0, 0}}; });
  // The slowest mode relaxes at nu k^2: 18 e-foldings leave 1.5e-8 of the transient.
  const int steps = static_cast<int>(std::ceil(18.0 / (nu * k * k)));
  for (int s = 0; s < steps; ++s) fluid.step();
  double s = 0, c = 0, cross = 0;
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < n; ++x) {
      const Macroscopic m = fluid.macroscopic(x, y, 0);
      s += m.velocity.y * std::sin(k * x);
      c += m.velocity.y * std::cos(k * x);
      cross = std::max({cross, std::abs(m.velocity.x), std::abs(m.velocity.z)});
    }
  const double amplitude = 2.0 * s / (2 * n), phase = 2.0 * c / (2 * n);
  return {amplitude / U, std::max(std::abs(phase), cross) / amplitude};
}

struct KolmogorovCase {
  double nu, lambda;
};

class KolmogorovFlow : public ::testing::TestWithParam<KolmogorovCase> {};

TEST_P(KolmogorovFlow, SteadyAmplitudeIsTheStokesBalance) {
  // 32 cells per wavelength. Against Stokes: 1 %, the brief's resolution
  // tolerance (largest expected error here 0.64 % at Lambda = 1/2). Against the
  // exact discrete steady state: 2e-5, covering the O(U^2) = 1e-6 nonlinear
  // terms of the equilibrium and the Guo source and the 1.5e-8 transient left.
  const auto p = GetParam();
  const int n = 32;
  const double k = 2 * M_PI / n;
  const KolmogorovResult r = kolmogorov(p.nu, p.lambda, n);
  const double discrete = kolmogorov_discrete_ratio(k, p.lambda);
  std::printf(
      "Kolmogorov nu %.3f Lambda %.4f: amplitude / Stokes = %.7f (discrete theory "
      "%.7f, measured - theory %.1e), out of phase %.1e\n",
      p.nu, p.lambda, r.ratio, discrete, r.ratio - discrete, r.out_of_phase);
  EXPECT_NEAR(r.ratio, 1.0, 0.01);
  EXPECT_NEAR(r.ratio / discrete, 1.0, 2e-5);
  EXPECT_LT(r.out_of_phase, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(VALIDATION, KolmogorovFlow,
                         ::testing::Values(KolmogorovCase{1.0 / 6.0, 0.25},
                                           KolmogorovCase{1.0, 0.25},
                                           KolmogorovCase{1.0 / 6.0, 1.0 / 12.0},
                                           KolmogorovCase{0.05, 0.5}));

TEST(KolmogorovFlowConvergence, ErrorIsSecondOrderAwayFromLambdaQuarter) {
  // At Lambda = 1/12 the relative error is -k^2/9 + O(k^4): doubling the cells
  // per wavelength divides it by 4 (3.8 to 4.2 allowed; the O(k^4) term shifts
  // the ratio by ~1 % at 16 cells).
  const double nu = 1.0 / 6.0, lambda = 1.0 / 12.0;
  std::vector<double> errors;
  for (int n : {16, 32, 64}) {
    const double k = 2 * M_PI / n;
    errors.push_back(kolmogorov(nu, lambda, n).ratio - 1.0);
    std::printf(
        "Kolmogorov %2d cells/wavelength: amplitude / Stokes - 1 = %.4e "
        "(-k^2/9 = %.4e)\n",
        n, errors.back(), -k * k / 9.0);
  }
  for (std::size_t i = 0; i + 1 < errors.size(); ++i) {
    EXPECT_LT(errors[i], 0.0);
    EXPECT_NEAR(errors[i] / errors[i + 1], 4.0, 0.2) << "refinement " << i;
  }
}

// ---------------------------------------------------------------------------
// Taylor-Green vortex with wave numbers k1 along axis a and k2 along axis b:
//   u_a = -U cos(k1 a) sin(k2 b),  u_b = U (k1/k2) sin(k1 a) cos(k2 b),
//   p = -U^2/4 [cos(2 k1 a) + (k1/k2)^2 cos(2 k2 b)],  rho = 1 + 3 p,
// divergence-free, with u.grad u = -grad p, so it decays as a whole at
// exp(-nu (k1^2 + k2^2) t).
struct TaylorGreenCase {
  int a, b;  // the axes of the vortex plane; the third axis has one cell
};

class AnisotropicTaylorGreen : public ::testing::TestWithParam<TaylorGreenCase> {};

TEST_P(AnisotropicTaylorGreen, DecaysAtNuTimesK1SquaredPlusK2Squared) {
  // 48 cells per wavelength along a, 32 along b. The 1 % tolerance is the
  // resolution tolerance of docs/model.md section 5 for shear-wave decay at 32 cells per
  // wavelength; U = 0.02 keeps compressibility errors at O(U^2 / cs^2) ~ 1e-3.
  const auto p = GetParam();
  const int la = 48, lb = 32;
  const double nu = 0.02, U = 0.02;
  const double k1 = 2 * M_PI / la, k2 = 2 * M_PI / lb;
  int n[3] = {1, 1, 1};
  n[p.a] = la;
  n[p.b] = lb;
  FluidLattice<double> fluid({n[0], n[1], n[2]}, {nu, 0.25});
  fluid.initialise_equilibrium([&](int x, int y, int z) {
    const int r[3] = {x, y, z};
    const double a = r[p.a], b = r[p.b];
    const double pressure =
        -0.25 * U * U * (std::cos(2 * k1 * a) + (k1 / k2) * (k1 / k2) * std::cos(2 * k2 * b));
    double u[3] = {0, 0, 0};
    u[p.a] = -U * std::cos(k1 * a) * std::sin(k2 * b);
    u[p.b] = U * (k1 / k2) * std::sin(k1 * a) * std::cos(k2 * b);
    return Macroscopic{1.0 + 3.0 * pressure, {u[0], u[1], u[2]}};
  });
  // Amplitudes of u_a and u_b by projection on their own modes (each equals U
  // times the decay factor).
  auto amplitudes = [&] {
    double sa = 0, sb = 0;
    for (int b = 0; b < lb; ++b)
      for (int a = 0; a < la; ++a) {
        int r[3] = {0, 0, 0};
        r[p.a] = a;
        r[p.b] = b;
        const Macroscopic m = fluid.macroscopic(r[0], r[1], r[2]);
        const double u[3] = {m.velocity.x, m.velocity.y, m.velocity.z};
        sa += u[p.a] * -std::cos(k1 * a) * std::sin(k2 * b);
        sb += u[p.b] * std::sin(k1 * a) * std::cos(k2 * b);
      }
    const double norm = 4.0 / (la * lb);
    return std::pair{norm * sa, norm * sb * k2 / k1};
  };
  const auto [start_a, start_b] = amplitudes();
  EXPECT_NEAR(start_a, U, 1e-12);
  EXPECT_NEAR(start_b, U, 1e-12);
  // The first steps build the non-equilibrium part missing from the
  // equilibrium initial state; then a decay by e^1 is measured.
  for (int s = 0; s < 50; ++s) fluid.step();
  const auto [a0, b0] = amplitudes();
  const double expected_rate = nu * (k1 * k1 + k2 * k2);
  const int steps = static_cast<int>(std::ceil(1.0 / expected_rate));
  for (int s = 0; s < steps; ++s) fluid.step();
  const auto [a1, b1] = amplitudes();
  const double rate_a = std::log(a0 / a1) / steps, rate_b = std::log(b0 / b1) / steps;
  std::printf("Taylor-Green %d x %d x %d: rate / (nu (k1^2 + k2^2)) = %.5f (u_a), %.5f (u_b)\n",
              n[0], n[1], n[2], rate_a / expected_rate, rate_b / expected_rate);
  EXPECT_NEAR(rate_a / expected_rate, 1.0, 0.01);
  EXPECT_NEAR(rate_b / expected_rate, 1.0, 0.01);
}

INSTANTIATE_TEST_SUITE_P(VALIDATION, AnisotropicTaylorGreen,
                         ::testing::Values(TaylorGreenCase{0, 1}, TaylorGreenCase{1, 2},
                                           TaylorGreenCase{2, 0}),
                         [](const ::testing::TestParamInfo<TaylorGreenCase>& case_info) {
                           const char* axis = "xyz";
                           return std::string(1, axis[case_info.param.a]) +
                                  axis[case_info.param.b] + "_plane";
                         });

}  // namespace
}  // namespace flocsim::lattice
