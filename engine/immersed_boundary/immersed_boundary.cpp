#include "engine/immersed_boundary/immersed_boundary.hpp"

#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

#include "engine/coupling/vector_sqrt.hpp"
#include "engine/immersed_boundary/control_forcing.hpp"
#include "engine/immersed_boundary/direct_forcing.hpp"
#include "engine/immersed_boundary/kernel.hpp"
#include "engine/immersed_boundary/marker_stencil.hpp"
#include "engine/immersed_boundary/sphere_markers.hpp"

namespace flocsim::immersed_boundary {

using coupling::for_each_box_run;

// Per-thread scratch space: a box of cells around one sphere and its markers,
// in the lattice's precision (layout: see Stencil).
template <class Real>
struct ImmersedBoundary<Real>::Workspace {
  using V4 = typename Simd<Real>::V4;
  using V16 = typename Simd<Real>::V16;
  explicit Workspace(int box, int markers)
      : row_cells(box + 1),
        cells(static_cast<std::size_t>(row_cells) * box * box),
        velocity(4 * cells, Real(0)),
        state(4 * cells, Real(0)),
        half_inv(4 * cells, Real(0)),
        force(4 * cells, Real(0)),
        base(static_cast<std::size_t>(markers)),
        weights(static_cast<std::size_t>(markers)),
        target(static_cast<std::size_t>(markers)),
        marker_force(static_cast<std::size_t>(markers)),
        increment(static_cast<std::size_t>(markers) + 3),  // spread() reads 16 numbers
        first(3 * static_cast<std::size_t>(markers)),
        frac(3 * static_cast<std::size_t>(markers)),
        root(3 * static_cast<std::size_t>(markers)),
        packed(12 * static_cast<std::size_t>(markers)) {}
  int row_cells;  // box + 1: room for the spare cells of a stencil row at the far end
  std::size_t cells;
  // velocity = (rho, u) as the pass read it; state = (rho, v), v the velocity
  // the collision sees with this sphere's new force (from the second sweep
  // on); half_inv: 1 / (2 rho) four times; force = (0, F): 4 numbers per cell.
  std::vector<Real> velocity, state, half_inv, force;
  std::vector<std::size_t> base;                    // stencil corner of each marker (numbers)
  std::vector<V16> weights;                         // kernel weights of each marker
  std::vector<V4> target, marker_force, increment;  // (0, vector) per marker
  std::vector<int> first;  // per direction and marker: first stencil cell in the box
  std::vector<double> frac,
      root;                  // per direction and marker: offset from the kernel's node, Roma's root
  std::vector<Real> packed;  // per weight slot and marker, before packing
  std::vector<const Real*> lines;  // cache lines of the next sphere
  int fetched = -1;                // the sphere whose lines were fetched
};

// The steps of one apply() for one sphere, in order (process()):
//   stencils     kernel weights and cells of every marker, and its target
//                velocity U = u_p + omega x r;
//   load_cells   the liquid velocity of the sphere's cells into its box;
//   force        direct forcing: `sweeps` Jacobi sweeps of interpolation and
//                spreading of 2 rho (U - u); control forcing: one
//                interpolation, the PI update of each marker's force, one
//                spreading of the whole force;
//   measure_slip (diagnostics) the slip left, interpolated once more;
//   loads        force and torque on the sphere, the reaction of its markers';
//   inside       momentum and angular momentum of the liquid inside;
//   write_back   the sphere's force added to the lattice's force field.
template <class Real>
template <int W>
struct ImmersedBoundary<Real>::SphereWork {
  using V4 = typename Simd<Real>::V4;
  using V4d = typename Simd<double>::V4;
  ImmersedBoundary& ib;
  const spheres::SphereSet& spheres;
  const lattice::Extent e;
  const lattice::ForceFieldView<Real> field;
  const int B, markers;
  const double dV;
  const Stencil<Real, W> stencil;
  std::vector<Vec3>& momentum;
  std::vector<Vec3>& angular;
  std::vector<double>& slip_sq;
  std::vector<double>& slip_max;

  const std::int16_t* rows_of(int s) const {
    return &ib.rows_[2 * static_cast<std::size_t>(s) * B * B];
  }

  // Calls fetch(address) for each cache line of the velocity that sphere s
  // reads and of the force field that it adds to.
  template <class Fetch>
  void sphere_lines(int s, Fetch&& fetch) const {
    constexpr int step = 64 / static_cast<int>(sizeof(Real));
    for_each_box_run(ib.origins_[static_cast<std::size_t>(s)], rows_of(s), B, e,
                     [&](int, int, int, int x, int count, long r) {
                       const Real* from =
                           &ib.velocity_[4 * (static_cast<std::size_t>(e.nx) * r + x)];
                       for (int q = 0; q < 4 * count; q += step) fetch(from + q);
                       fetch(from + 4 * count - 1);
                       for (int d = 0; d < 3; ++d) {
                         const Real* f = field.row(d, r) + x;
                         for (int q = 0; q < count; q += step) fetch(f + q);
                         fetch(f + count - 1);
                       }
                     });
  }

  // Kernel weights and stencil corners in vector loops over the markers
  // (arrays per direction), then packed; targets U = u_p + omega x r.
  void stencils(Workspace& ws, int s) const {
    const Vec3 centre = spheres.position[static_cast<std::size_t>(s)];
    const Vec3 up = spheres.velocity[static_cast<std::size_t>(s)];
    const Vec3 omega = spheres.angular_velocity[static_cast<std::size_t>(s)];
    const auto& lo = ib.origins_[static_cast<std::size_t>(s)];
    const int R = ws.row_cells;
    const int M = markers;
    const double* r = ib.offsets_.data();
    double* frac = ws.frac.data();
    double* q = ws.root.data();
    int* first = ws.first.data();
    const double c[3] = {centre[0], centre[1], centre[2]};
    for (int d = 0; d < 3; ++d) {
#pragma omp simd
      for (int m = 0; m < M; ++m) {
        const double X = c[d] + r[3 * m + d];
        if constexpr (W == 3) {  // cells round(X) - 1 .. round(X) + 1
          const double near = std::nearbyint(X);
          first[d * M + m] = static_cast<int>(near) - 1 - lo[d];
          const double f = X - near;
          frac[d * M + m] = f;
          q[d * M + m] = 1.0 - 3.0 * f * f;
        } else {  // cells floor(X), floor(X) + 1
          const double below = std::floor(X);
          first[d * M + m] = static_cast<int>(below) - lo[d];
          frac[d * M + m] = X - below;
        }
      }
    }
    if constexpr (W == 3) coupling::sqrt_in_place(q, 3 * M);
    Real* wt = ws.packed.data();  // W + W^2 weights per marker, in slot order
#pragma omp simd
    for (int m = 0; m < M; ++m) {
      double w[3][W];
      for (int d = 0; d < 3; ++d) {
        if constexpr (W == 3)
          roma_weights_from_root(frac[d * M + m], q[d * M + m], w[d]);
        else
          linear_weights(frac[d * M + m], w[d]);
      }
      for (int a = 0; a < W; ++a) wt[a * M + m] = static_cast<Real>(w[0][a]);
      for (int cc = 0; cc < W; ++cc)
        for (int b = 0; b < W; ++b)
          wt[(W + b + W * cc) * M + m] = static_cast<Real>(w[1][b] * w[2][cc]);
    }
    for (int m = 0; m < M; ++m) {
      const std::size_t k = static_cast<std::size_t>(m);
      Real* wm = reinterpret_cast<Real*>(&ws.weights[k]);  // the other slots stay zero
      for (int l = 0; l < W + W * W; ++l) wm[l] = wt[l * M + m];
      ws.base[k] =
          4 * static_cast<std::size_t>(first[m] + R * (first[M + m] + B * first[2 * M + m]));
      const Vec3 U = surface_velocity(up, omega, Vec3(r[3 * m], r[3 * m + 1], r[3 * m + 2]));
      ws.target[k] =
          V4{0, static_cast<Real>(U[0]), static_cast<Real>(U[1]), static_cast<Real>(U[2])};
      ws.marker_force[k] = V4{};
    }
  }

  // The liquid velocity of the sphere's cells, from the pass, and 1/(2 rho).
  void load_cells(Workspace& ws, int s) const {
    const int R = ws.row_cells;
    for_each_box_run(ib.origins_[static_cast<std::size_t>(s)], rows_of(s), B, e,
                     [&](int j, int k, int i, int x, int count, long r) {
                       const std::size_t box = static_cast<std::size_t>(R) * (j + B * k) + i;
                       const Real* __restrict from =
                           &ib.velocity_[4 * (static_cast<std::size_t>(e.nx) * r + x)];
                       Real* __restrict to = &ws.velocity[4 * box];
                       Real* __restrict h = &ws.half_inv[4 * box];
                       for (int c = 0; c < 4 * count; ++c) to[c] = from[c];
#pragma omp simd
                       for (int c = 0; c < count; ++c) {
                         const Real v = Real(0.5) / to[4 * c];
                         h[4 * c] = h[4 * c + 1] = h[4 * c + 2] = h[4 * c + 3] = v;
                       }
                     });
  }

  // v = velocity + F / (2 rho) on the sphere's cells: what the next sweep (or
  // the slip measurement) interpolates.
  void update_state(Workspace& ws, const std::int16_t* rows) const {
    const int R = ws.row_cells;
    for (int row = 0; row < B * B; ++row) {
      const int i0 = rows[2 * row], i1 = rows[2 * row + 1];
      if (i0 > i1) continue;
      const std::size_t a = 4 * (static_cast<std::size_t>(R) * row + i0);
      const std::size_t b = 4 * (static_cast<std::size_t>(R) * row + i1 + 1);
      const Real* __restrict us = ws.velocity.data();
      const Real* __restrict h = ws.half_inv.data();
      const Real* __restrict f = ws.force.data();
      Real* __restrict v = ws.state.data();
#pragma omp simd
      for (std::size_t q = a; q < b; ++q) v[q] = us[q] + h[q] * f[q];
    }
  }

  // Prefetches this marker's share of the next sphere's cache lines.
  struct Prefetcher {
    Workspace& ws;
    std::size_t line = 0, per_marker = 1;
    void operator()() {
      for (std::size_t q = 0; q < per_marker && line < ws.lines.size(); ++q)
        __builtin_prefetch(ws.lines[line++]);
    }
  };

  // Multi-direct forcing: interpolate at all markers, then spread all
  // (Jacobi). The first sweep sees u* itself (no force yet). Returns the state
  // last interpolated (for the slip measurement).
  const Real* direct_forcing(Workspace& ws, const std::int16_t* rows, Prefetcher& fetch) const {
    const int sweeps = ib.settings_.scheme.sweeps;
    const bool measure = ib.settings_.measure_slip;
    const Real dVr = static_cast<Real>(dV);
    const Real* state = ws.velocity.data();
    for (int sweep = 0; sweep < sweeps; ++sweep) {
      for (int m = 0; m < markers; ++m) {
        fetch();
        const std::size_t k = static_cast<std::size_t>(m);
        const V4 dF =
            forcing_increment(stencil.interpolate(state, ws.base[k], ws.weights[k]), ws.target[k]);
        ws.marker_force[k] += dF;
        ws.increment[k] = dF * dVr;
      }
      spread_increments(ws);
      if (sweep + 1 < sweeps || measure) {
        update_state(ws, rows);
        state = ws.state.data();
      }
    }
    return state;
  }

  // Control forcing: each marker reads the slip its force of the last step
  // left, e = U - v(X_m) with v = u* + F_last / (2 rho) (this sphere's carried
  // forces spread again: like direct forcing, a sphere does not see its
  // neighbours' forces in its own sweep), corrects its force
  // (control_forcing.hpp) and the whole force is spread. Returns the state
  // for the slip measurement.
  const Real* control_forcing(Workspace& ws, int s, const std::int16_t* rows,
                              Prefetcher& fetch) const {
    const coupling::ControlGains& g = ib.settings_.scheme.gains;
    const Real dVr = static_cast<Real>(dV);
    // the carried forces and slips, (0, x, y, z) per marker (plain numbers in
    // memory, so loaded and stored as vectors without alignment assumptions)
    Real* carried = &ib.marker_force_[4 * static_cast<std::size_t>(s) * markers];
    Real* slips = &ib.marker_slip_[4 * static_cast<std::size_t>(s) * markers];
    // v = u* + F_last / (2 rho) on the sphere's cells
    for (int m = 0; m < markers; ++m)
      ws.increment[static_cast<std::size_t>(m)] =
          Simd<Real>::template load<V4>(carried + 4 * m) * dVr;
    spread_increments(ws);
    update_state(ws, rows);
    clear_force(ws, rows);
    for (int m = 0; m < markers; ++m) {
      fetch();
      const std::size_t k = static_cast<std::size_t>(m);
      V4 slip = Simd<Real>::template load<V4>(slips + 4 * m);
      const V4 force =
          Simd<Real>::template load<V4>(carried + 4 * m) +
          control_increment(stencil.interpolate(ws.state.data(), ws.base[k], ws.weights[k]),
                            ws.target[k], slip, g.integral, g.proportional);
      Simd<Real>::store(carried + 4 * m, force);
      Simd<Real>::store(slips + 4 * m, slip);
      ws.marker_force[k] = force;
      ws.increment[k] = force * dVr;
    }
    spread_increments(ws);
    if (ib.settings_.measure_slip) update_state(ws, rows);
    return ws.state.data();
  }

  void spread_increments(Workspace& ws) const {
    for (int m = 0; m < markers; ++m) {
      const std::size_t k = static_cast<std::size_t>(m);
      stencil.spread(ws.force.data(), ws.base[k], ws.weights[k],
                     reinterpret_cast<const Real*>(&ws.increment[k]));
    }
  }

  void clear_force(Workspace& ws, const std::int16_t* rows) const {
    const int R = ws.row_cells;
    for (int row = 0; row < B * B; ++row) {
      const int i0 = rows[2 * row], i1 = rows[2 * row + 1];
      if (i0 > i1) continue;
      std::fill(ws.force.begin() + 4 * (static_cast<std::size_t>(R) * row + i0),
                ws.force.begin() + 4 * (static_cast<std::size_t>(R) * row + i1 + 1), Real(0));
    }
  }

  void measure_slip(Workspace& ws, int s, const Real* state) const {
    const V4 vector_part = {0, 1, 1, 1};
    double sq = 0, mx = 0;
    for (int m = 0; m < markers; ++m) {
      const std::size_t k = static_cast<std::size_t>(m);
      const V4 diff =
          (stencil.interpolate(state, ws.base[k], ws.weights[k]) - ws.target[k]) * vector_part;
      const double err = std::sqrt(double(diff[1]) * diff[1] + double(diff[2]) * diff[2] +
                                   double(diff[3]) * diff[3]);
      sq += err * err;
      mx = std::max(mx, err);
    }
    slip_sq[static_cast<std::size_t>(s)] = sq;
    slip_max[static_cast<std::size_t>(s)] = mx;
  }

  // Force and torque on the sphere: the reaction of the marker forces.
  void loads(Workspace& ws, int s) const {
    Vec3 F = Vec3::Zero(), T = Vec3::Zero();
    const double ag = ib.settings_.input_radius;
    for (int m = 0; m < markers; ++m) {
      const V4 f = ws.marker_force[static_cast<std::size_t>(m)];
      const Vec3 Fm = Vec3(f[1], f[2], f[3]) * dV;
      F -= Fm;
      T -= (ag * ib.directions_[static_cast<std::size_t>(m)]).cross(Fm);
    }
    ib.force_[static_cast<std::size_t>(s)] = F;
    ib.torque_[static_cast<std::size_t>(s)] = T;
  }

  // Momentum of the liquid inside, rho v = rho (u* + F/(2 rho)) (the
  // collision's, F this sphere's new force), weighted by inside_weight().
  void inside(Workspace& ws, int s) const {
    const Vec3 centre = spheres.position[static_cast<std::size_t>(s)];
    const auto& lo = ib.origins_[static_cast<std::size_t>(s)];
    const int R = ws.row_cells;
    const double ag = ib.settings_.input_radius;
    double P[3] = {0, 0, 0}, L[3] = {0, 0, 0};
    const double reach = ag + 0.5;
    const double inner2 = (ag - 0.5) * (ag - 0.5) * (1.0 - 1e-12);
    for (int k = 0; k < B; ++k) {
      const double rz = lo[2] + k - centre[2];
      if (std::abs(rz) >= reach) continue;
      for (int j = 0; j < B; ++j) {
        const double ry = lo[1] + j - centre[1];
        const double left = reach * reach - ry * ry - rz * rz;
        if (left <= 0) continue;
        const double half = std::sqrt(left);
        const int i0 = std::max(0, static_cast<int>(std::ceil(centre[0] - half)) - lo[0]);
        const int i1 = std::min(B - 1, static_cast<int>(std::floor(centre[0] + half)) - lo[0]);
        if (i0 > i1) continue;
        // Per cell j = w rho v (lane 0 unused); over the row sum j and rx j.
        V4d sum = {}, moment = {};
        const std::size_t row = 4 * static_cast<std::size_t>(R) * (j + B * k);
        const Real* us = &ws.velocity[row];
        const Real* h = &ws.half_inv[row];
        const Real* f = &ws.force[row];
        for (int i = i0; i <= i1; ++i) {
          const double rx = lo[0] + i - centre[0];
          const double w = inside_weight(rx * rx + ry * ry + rz * rz, reach, inner2);
          if (w <= 0) continue;
          const V4 v =
              Simd<Real>::template load<V4>(us + 4 * i) +
              Simd<Real>::template load<V4>(h + 4 * i) * Simd<Real>::template load<V4>(f + 4 * i);
          const V4d c = __builtin_convertvector(v, V4d);
          const V4d jc = (w * c[0]) * c;
          sum += jc;
          moment += rx * jc;
        }
        // L = sum r x j with ry, rz fixed on the row.
        P[0] += sum[1], P[1] += sum[2], P[2] += sum[3];
        L[0] += ry * sum[3] - rz * sum[2];
        L[1] += rz * sum[1] - moment[3];
        L[2] += moment[2] - ry * sum[1];
      }
    }
    momentum[static_cast<std::size_t>(s)] = Vec3(P[0], P[1], P[2]);
    angular[static_cast<std::size_t>(s)] = Vec3(L[0], L[1], L[2]);
  }

  // Adds this sphere's force to the lattice field, row by row, and clears the
  // scratch force (nonzero only on the rows' cells).
  void write_back(Workspace& ws, int s) const {
    const int R = ws.row_cells;
    for_each_box_run(ib.origins_[static_cast<std::size_t>(s)], rows_of(s), B, e,
                     [&](int j, int k, int i, int x, int count, long r) {
                       Real* __restrict f =
                           &ws.force[4 * (static_cast<std::size_t>(R) * (j + B * k) + i)];
                       Real* __restrict gx = field.row(0, r) + x;
                       Real* __restrict gy = field.row(1, r) + x;
                       Real* __restrict gz = field.row(2, r) + x;
#pragma omp simd
                       for (int c = 0; c < count; ++c) {
                         gx[c] += f[4 * c + 1];
                         gy[c] += f[4 * c + 2];
                         gz[c] += f[4 * c + 3];
                       }
                       for (int q = 0; q < 4 * count; ++q) f[q] = Real(0);
                     });
  }

  void process(Workspace& ws, int s, int next) const {
    const std::int16_t* rows = rows_of(s);
    // The lines of this sphere were fetched during the previous sphere's
    // sweeps, or are fetched now while the stencils are computed; the next
    // sphere's are fetched during this one's sweeps.
    if (ws.fetched != s) sphere_lines(s, [](const Real* p) { __builtin_prefetch(p); });
    ws.lines.clear();
    if (next >= 0) sphere_lines(next, [&](const Real* p) { ws.lines.push_back(p); });
    ws.fetched = next;
    const bool control = ib.settings_.scheme.control();
    const int passes = control ? 1 : ib.settings_.scheme.sweeps;
    Prefetcher fetch{ws, 0, ws.lines.size() / static_cast<std::size_t>(markers * passes) + 1};
    stencils(ws, s);
    load_cells(ws, s);
    const Real* state =
        control ? control_forcing(ws, s, rows, fetch) : direct_forcing(ws, rows, fetch);
    if (ib.settings_.measure_slip) measure_slip(ws, s, state);
    loads(ws, s);
    inside(ws, s);
    write_back(ws, s);
  }
};

void check_settings(const ImmersedBoundarySettings& settings) {
  const coupling::Scheme& scheme = settings.scheme;
  if (!scheme.immersed_boundary())
    throw std::invalid_argument("immersed boundary: the scheme is " + scheme.describe() +
                                ", not an immersed boundary");
  if (!(settings.input_radius >= 1.0))
    throw std::invalid_argument(
        "immersed boundary: input_radius = " + std::to_string(settings.input_radius) +
        ": must be at least 1 dx (the kernel is up to 3 dx wide)");
  if (!(scheme.marker_spacing > 0.2 && scheme.marker_spacing <= 1.5))
    throw std::invalid_argument(
        "immersed boundary: marker_spacing = " + std::to_string(scheme.marker_spacing) +
        ": must be in (0.2, 1.5] dx");
  if (scheme.sweeps < 1 || scheme.sweeps > 20)
    throw std::invalid_argument("immersed boundary: sweeps = " + std::to_string(scheme.sweeps) +
                                ": must be in [1, 20]");
  if (scheme.control() && scheme.sweeps != 1)
    throw std::invalid_argument("immersed boundary: sweeps = " + std::to_string(scheme.sweeps) +
                                " with control forcing: it makes one correction per step (1)");
  if (!(settings.input_radius <= 10000.0))
    throw std::invalid_argument("immersed boundary: input_radius = " +
                                std::to_string(settings.input_radius) + ": must be <= 10000 dx");
}

int sphere_box_edge(double input_radius) {
  // The box's lowest cell is floor(x - a_g) - 2, the highest stencil cell at
  // most floor(x + a_g) + 2 <= floor(x - a_g) + ceil(2 a_g) + 3 (Roma's kernel
  // reaches round(X) + 1, the hat floor(X) + 1).
  return static_cast<int>(std::ceil(2.0 * input_radius)) + 5;
}

void check_box_fits(const lattice::Extent& e, double input_radius) {
  const int length[3] = {e.nx, e.ny, e.nz};
  for (int d = 0; d < 3; ++d)
    if (length[d] <= 2.0 * input_radius + 3.0)
      throw std::invalid_argument(
          "immersed boundary: box length " + std::to_string(length[d]) +
          " must exceed 2 a_g + 3 = " + std::to_string(2.0 * input_radius + 3.0) +
          " (a sphere's kernel cells must not meet its own periodic image)");
}

template <class Real>
ImmersedBoundary<Real>::ImmersedBoundary(ImmersedBoundarySettings settings)
    : coupling::SphereCoupling<Real>(settings.scheme), settings_(settings) {
  check_settings(settings);
  const int n = marker_count(settings.input_radius, settings.scheme.marker_spacing);
  directions_ = fibonacci_sphere(n);
  for (const Vec3& u : directions_)
    for (int d = 0; d < 3; ++d) offsets_.push_back(settings.input_radius * u[d]);
  marker_volume_ = immersed_boundary::marker_volume(settings.input_radius, n);
  box_ = sphere_box_edge(settings.input_radius);
}

template <class Real>
ImmersedBoundary<Real>::~ImmersedBoundary() = default;

template <class Real>
void ImmersedBoundary<Real>::zero_boxes(const lattice::ForceFieldView<Real>& field) {
  if (written_.empty()) return;
  const lattice::Extent& e = field.extent;
  const auto colours = coupling::make_colours(written_, box_, e);
  const int B = box_;
#pragma omp parallel
  for (const auto& blocks : colours) {
#pragma omp for schedule(dynamic, 1)
    for (std::size_t b = 0; b < blocks.size(); ++b)
      for (int s : blocks[b])
        for_each_box_run(written_[static_cast<std::size_t>(s)],
                         &written_rows_[2 * static_cast<std::size_t>(s) * B * B], B, e,
                         [&](int, int, int, int x, int count, long r) {
                           for (int d = 0; d < 3; ++d)
                             std::fill_n(field.row(d, r) + x, count, Real(0));
                         });
  }
  written_.clear();
}

template <class Real>
void ImmersedBoundary<Real>::remove(lattice::ForcedLiquid<Real>& liquid) {
  const auto set = liquid.force_field_if_set();
  if (!set.empty()) zero_boxes(liquid.force_field());
}

template <class Real>
void ImmersedBoundary<Real>::apply(lattice::ForcedLiquid<Real>& liquid,
                                   const spheres::SphereSet& spheres) {
  if (coupling::kernel_width(settings_.scheme.kernel) == 3)
    apply_with_kernel<3>(liquid, spheres);
  else
    apply_with_kernel<2>(liquid, spheres);
}

template <class Real>
void ImmersedBoundary<Real>::locate(const spheres::SphereSet& spheres, const lattice::Extent& e,
                                    double half_width) {
  const std::size_t n = spheres.size();
  const int B = box_;
  const double ag = settings_.input_radius;
  origins_.resize(n);
  for (std::size_t s = 0; s < n; ++s)
    for (int d = 0; d < 3; ++d)
      origins_[s][d] = static_cast<int>(std::floor(spheres.position[s][d] - ag)) - 2;
  rows_.resize(2 * n * static_cast<std::size_t>(B) * B);
  // The cells of every marker stencil: a stencil cell is within W/2 of its
  // marker in each direction, so it lies in the cube of that half-width
  // around some point of the sphere |X - centre| = a_g. Per box row: the cells
  // whose cube meets the ball of radius a_g (holes filled; this includes the
  // inside, |r| < a_g + 1/2, that the momentum sums need).
#pragma omp parallel for schedule(dynamic, 16)
  for (std::size_t s = 0; s < n; ++s) {
    const Vec3 centre = spheres.position[s];
    const auto& lo = origins_[s];
    std::int16_t* rows = &rows_[2 * s * B * B];
    for (int k = 0; k < B; ++k) {
      const double ez = std::max(0.0, std::abs(lo[2] + k - centre[2]) - half_width);
      for (int j = 0; j < B; ++j) {
        const double ey = std::max(0.0, std::abs(lo[1] + j - centre[1]) - half_width);
        const double left = ag * ag - ey * ey - ez * ez;
        int i0 = 1, i1 = 0;
        if (left >= 0) {
          const double half = half_width + std::sqrt(left) + 1e-9;
          i0 = std::max(0, static_cast<int>(std::ceil(centre[0] - half)) - lo[0]);
          i1 = std::min(B - 1, static_cast<int>(std::floor(centre[0] + half)) - lo[0]);
        }
        rows[2 * (j + B * k)] = static_cast<std::int16_t>(i0);
        rows[2 * (j + B * k) + 1] = static_cast<std::int16_t>(i1);
      }
    }
    for_each_box_run(lo, rows, B, e,
                     [&](int, int, int, int x, int count, long r) { need_.mark(r, x, count); });
  }
}

template <class Real>
void ImmersedBoundary<Real>::read_liquid_velocity(lattice::ForcedLiquid<Real>& liquid,
                                                  const lattice::ForceFieldView<Real>& field,
                                                  bool clear_in_pass) {
  const lattice::Extent e = liquid.extent();
  const int chunks = need_.chunks();
  // In memory order: zero the force field on the chunks of the last apply()
  // and read the velocity on the chunks needed now (runs of chunks at once),
  // so that the streams are read nearly in order.
  auto pass_row = [&](std::size_t r) {
    const int y = static_cast<int>(r % e.ny), z = static_cast<int>(r / e.ny);
    const std::uint64_t* need = need_.row(r);
    Real* out = &velocity_[4 * static_cast<std::size_t>(e.nx) * r];
    for (int c = 0; c < chunks;) {
      if (!coupling::ChunkMask::has(need, c)) {
        ++c;
        continue;
      }
      int c1 = c + 1;
      while (c1 < chunks && coupling::ChunkMask::has(need, c1)) ++c1;
      const int x0 = coupling::ChunkMask::kChunk * c,
                x1 = std::min(e.nx, coupling::ChunkMask::kChunk * c1);
      liquid.macroscopic_row_without_force_field(x0, x1 - x0, y, z, out + 4 * x0);
      c = c1;
    }
    if (clear_in_pass) {
      std::uint64_t* held = held_.row(r);
      for (int c = 0; c < chunks; ++c)
        if (coupling::ChunkMask::has(held, c)) {
          const int x0 = coupling::ChunkMask::kChunk * c,
                    count = std::min(coupling::ChunkMask::kChunk, e.nx - x0);
          for (int d = 0; d < 3; ++d)
            std::fill_n(field.row(d, static_cast<long>(r)) + x0, count, Real(0));
        }
      std::fill_n(held, held_.words(), std::uint64_t(0));
    }
  };
#pragma omp for schedule(dynamic, 64)
  for (std::size_t r = 0; r < static_cast<std::size_t>(e.rows()); ++r) pass_row(r);
}

template <class Real>
template <int W>
void ImmersedBoundary<Real>::apply_with_kernel(lattice::ForcedLiquid<Real>& liquid,
                                               const spheres::SphereSet& spheres) {
  // A stencil cell lies within W/2 of its marker in each direction.
  constexpr double half_width = 0.5 * W;
  const lattice::Extent e = liquid.extent();
  check_box_fits(e, settings_.input_radius);
  const lattice::ForceFieldView<Real> field = liquid.force_field();

  const std::size_t n = spheres.size();
  const int B = box_;
  const int markers = markers_per_sphere();
  this->force_.assign(n, Vec3::Zero());
  this->torque_.assign(n, Vec3::Zero());
  std::vector<Vec3> momentum(n, Vec3::Zero()), angular(n, Vec3::Zero());
  if (settings_.scheme.control() &&
      marker_force_.size() != 4 * n * static_cast<std::size_t>(markers)) {
    marker_force_.assign(4 * n * static_cast<std::size_t>(markers), Real(0));
    marker_slip_.assign(4 * n * static_cast<std::size_t>(markers), Real(0));
  }

  // The force of the last apply() is cleared during the velocity pass, on the
  // chunks it was held in, except on the first call (or after remove()).
  const bool clear_in_pass = !written_.empty() && !held_.empty();
  if (!clear_in_pass) zero_boxes(field);
  need_.resize(e);
  velocity_.resize(4 * static_cast<std::size_t>(e.cells()));
  locate(spheres, e, half_width);
  const auto colours = coupling::make_colours(origins_, B, e);

  const int threads = omp_get_max_threads();
  if (static_cast<int>(workspaces_.size()) < threads)
    workspaces_.resize(static_cast<std::size_t>(threads));
  for (auto& w : workspaces_)
    if (!w) w = std::make_unique<Workspace>(B, markers);

  std::vector<double> slip_sq(settings_.measure_slip ? n : 0),
      slip_max(settings_.measure_slip ? n : 0);
  const SphereWork<W> work{
      *this,    spheres, e,       field,   B, markers, marker_volume_, Stencil<Real, W>(B + 1, B),
      momentum, angular, slip_sq, slip_max};

  // Blocks of one colour in parallel, handed out one at a time; a thread
  // takes its next block before working on the current one, so that it knows
  // the next sphere and can fetch its lines early.
  std::vector<std::atomic<std::size_t>> taken(colours.size());
#pragma omp parallel
  {
    Workspace& ws = *workspaces_[static_cast<std::size_t>(omp_get_thread_num())];
    ws.fetched = -1;
    read_liquid_velocity(liquid, field, clear_in_pass);
    for (std::size_t c = 0; c < colours.size(); ++c) {
      const auto& blocks = colours[c];
      std::size_t block = taken[c]++;
      while (block < blocks.size()) {
        const std::size_t following = taken[c]++;
        const auto& members = blocks[block];
        for (std::size_t i = 0; i < members.size(); ++i) {
          int next = -1;
          if (i + 1 < members.size())
            next = members[i + 1];
          else if (following < blocks.size())
            next = blocks[following].front();
          work.process(ws, members[i], next);
        }
        block = following;
      }
#pragma omp barrier
    }
  }
  if (!clear_in_pass) {
    held_.resize(e);
    held_.clear();
  }
  need_.swap(held_);  // need_ is all zero again
  written_ = origins_;
  written_rows_.swap(rows_);
  this->record_internal_momenta(std::move(momentum), std::move(angular));

  if (settings_.measure_slip) {
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
std::vector<coupling::NamedArray> ImmersedBoundary<Real>::memory() const {
  if (!settings_.scheme.control()) return {};
  return {{"marker_force", lanes_to_vectors(marker_force_)},
          {"marker_slip", lanes_to_vectors(marker_slip_)}};
}

template <class Real>
void ImmersedBoundary<Real>::restore_memory(const std::vector<coupling::NamedArray>& memory) {
  if (!settings_.scheme.control()) return;
  for (const auto& a : memory) {
    if (a.values.size() % (3 * static_cast<std::size_t>(markers_per_sphere())) != 0)
      throw std::invalid_argument("immersed boundary: checkpointed " + a.name + " holds " +
                                  std::to_string(a.values.size()) +
                                  " numbers, not 3 per marker of whole spheres (" +
                                  std::to_string(markers_per_sphere()) + " markers each)");
    if (a.name == "marker_force")
      marker_force_ = vectors_to_lanes<Real>(a.values);
    else if (a.name == "marker_slip")
      marker_slip_ = vectors_to_lanes<Real>(a.values);
  }
}

template class ImmersedBoundary<float>;
template class ImmersedBoundary<double>;

}  // namespace flocsim::immersed_boundary
