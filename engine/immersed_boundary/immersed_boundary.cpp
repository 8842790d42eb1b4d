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

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "engine/immersed_boundary/direct_forcing.hpp"
#include "engine/immersed_boundary/kernel.hpp"
#include "engine/immersed_boundary/sphere_markers.hpp"

namespace flocsim::immersed_boundary {

namespace {

int wrap(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}

// The cells a sphere reads and forces: a box of B^3 cells from its lowest
// corner `lo` (unwrapped lattice coordinates), of which box row (j, k) uses
// cells i0 .. i1 (i0 > i1: none), stored as rows[2 (j + B k)], rows[... + 1].
// The one walk over them: run(j, k, i, x, count, r) for every piece
// i .. i + count - 1 of box row (j, k) that lies at lattice x .. x + count - 1
// of lattice row r = y + ny z; pieces never cross the periodic edge in x.
template <class Run>
void for_each_box_run(const std::array<int, 3>& lo, const std::int16_t* rows, int B,
                      const lattice::Extent& e, Run&& run) {
  for (int k = 0; k < B; ++k) {
    const long plane = static_cast<long>(e.ny) * wrap(lo[2] + k, e.nz);
    for (int j = 0; j < B; ++j) {
      const int i0 = rows[2 * (j + B * k)], i1 = rows[2 * (j + B * k) + 1];
      if (i0 > i1) continue;
      const long r = wrap(lo[1] + j, e.ny) + plane;
      for (int i = i0; i <= i1;) {
        const int x = wrap(lo[0] + i, e.nx);
        const int count = std::min(i1 - i + 1, e.nx - x);
        run(j, k, i, x, count, r);
        i += count;
      }
    }
  }
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

// x[k] = sqrt(x[k]) for k < n, several at a time where the instruction set
// has it (std::sqrt does not vectorise while it may set errno). Square roots
// are correctly rounded: the values of std::sqrt.
void sqrt_in_place(double* x, int n) {
  int k = 0;
#if defined(__AVX512F__)
  for (; k + 8 <= n; k += 8)
    _mm512_storeu_pd(x + k, _mm512_maskz_sqrt_pd(0xFF, _mm512_loadu_pd(x + k)));
#endif
#if defined(__AVX__)
  for (; k + 4 <= n; k += 4) _mm256_storeu_pd(x + k, _mm256_sqrt_pd(_mm256_loadu_pd(x + k)));
#endif
#if defined(__SSE2__)
  for (; k + 2 <= n; k += 2) _mm_storeu_pd(x + k, _mm_sqrt_pd(_mm_loadu_pd(x + k)));
#endif
  for (; k < n; ++k) x[k] = std::sqrt(x[k]);
}

// Vectors of 4 and 16 numbers (GCC/Clang vector extensions: with AVX-512 a
// 16-float vector is one register, 16 doubles two).
template <class Real>
struct Simd {
  typedef Real V4 __attribute__((vector_size(4 * sizeof(Real))));
  typedef Real V16 __attribute__((vector_size(16 * sizeof(Real))));
  template <class V>
  static V load(const Real* p) {
    V v;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  template <class V>
  static void store(Real* p, V v) {
    std::memcpy(p, &v, sizeof v);
  }
};

// The W^3-cell stencil of one marker (W = 3: Roma, W = 2: linear) in a
// sphere's scratch box, shared by interpolation and spreading. Every box cell
// holds four numbers, so a row of four cells is one 16-number vector; a
// stencil row is W cells plus 4 - W with weight zero (the box rows have one
// spare cell for them), and each operation is W^2 whole-row vector steps.
//   state: (rho, v) per cell, v = u* + F / (2 rho): the velocity the collision sees;
//   force: (0, F) per cell, F this sphere's force density.
// w: the marker's 16 weight slots: x weights wx[a] in slots 0 .. W-1, the
// products wy[b] wz[c] in slot W + b + W c, the rest zero.
// base: the marker's stencil corner as an offset in numbers (4 per cell).
template <class Real, int W>
struct Stencil {
  static_assert(W == 2 || W == 3, "kernel width 2 or 3");
  static constexpr int kRows = W * W;
  using V4 = typename Simd<Real>::V4;
  using V16 = typename Simd<Real>::V16;
  std::size_t offset[kRows];  // numbers from the corner to stencil row (b, c), index b + W c

  Stencil(int row_cells, int box) {
    for (int c = 0; c < W; ++c)
      for (int b = 0; b < W; ++b)
        offset[b + W * c] = 4 * static_cast<std::size_t>(row_cells) * (b + box * c);
  }
  // x weight of each of the 16 numbers of a stencil row (slot 15 is zero).
  static V16 row_weights(const V16& w) {
    if constexpr (W == 3)
      return __builtin_shufflevector(w, w, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 15, 15, 15, 15);
    else
      return __builtin_shufflevector(w, w, 0, 0, 0, 0, 1, 1, 1, 1, 15, 15, 15, 15, 15, 15, 15, 15);
  }

  // Interpolated (rho, v) at the marker: the x weights multiply the sum of
  // the W^2 rows weighted by wy wz.
  V4 interpolate(const Real* state, std::size_t base, const V16& w) const {
    const Real* wyz = reinterpret_cast<const Real*>(&w) + W;
    std::size_t o[kRows];
    for (int l = 0; l < kRows; ++l) o[l] = offset[l];
    V16 acc[3] = {};  // three independent sums: a shorter dependency chain
#pragma GCC unroll 9
    for (int l = 0; l < kRows; ++l)
      acc[l % 3] += wyz[l] * Simd<Real>::template load<V16>(state + base + o[l]);
    V16 sum = (acc[0] + acc[1] + acc[2]) * row_weights(w);
    const V4 a = __builtin_shufflevector(sum, sum, 0, 1, 2, 3);
    const V4 b = __builtin_shufflevector(sum, sum, 4, 5, 6, 7);
    if constexpr (W == 3) {
      const V4 c = __builtin_shufflevector(sum, sum, 8, 9, 10, 11);
      return a + b + c;
    } else {
      return a + b;
    }
  }

  // Adds (0, F_m dV) spread with the kernel to force; s points to those 4
  // numbers (and 12 more, not used).
  void spread(Real* force, std::size_t base, const V16& w, const Real* s) const {
    const V16 s4 = Simd<Real>::template load<V16>(s);
    const V16 ws = row_weights(w) *
                   __builtin_shufflevector(s4, s4, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3);
    const Real* wyz = reinterpret_cast<const Real*>(&w) + W;
    std::size_t o[kRows];
    for (int l = 0; l < kRows; ++l) o[l] = offset[l];
    Real* f = force + base;
#pragma GCC unroll 9
    for (int l = 0; l < kRows; ++l)
      Simd<Real>::store(f + o[l], Simd<Real>::template load<V16>(f + o[l]) + ws * wyz[l]);
  }
};

}  // namespace

// Per-thread scratch space: a box of cells around one sphere and its markers,
// in the lattice's precision (layout: see Stencil).
template <class Real>
struct ImmersedBoundary<Real>::Workspace {
  using V4 = typename Simd<Real>::V4;
  using V16 = typename Simd<Real>::V16;
  explicit Workspace(int box, int markers)
      : row_cells(box + 1),
        cells(static_cast<std::size_t>(row_cells) * box * box),
        ustar(4 * cells, Real(0)),
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
  // u* = (rho, u*); state = (rho, v) (see Stencil), from the second sweep on;
  // half_inv: 1 / (2 rho) four times; force = (0, F): 4 numbers per cell.
  std::vector<Real> ustar, state, half_inv, force;
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

template <class Real>
ImmersedBoundary<Real>::ImmersedBoundary(ImmersedBoundarySettings settings) : settings_(settings) {
  const Scheme& scheme = settings.scheme;
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
  if (!(settings.input_radius <= 10000.0))
    throw std::invalid_argument("immersed boundary: input_radius = " +
                                std::to_string(settings.input_radius) + ": must be <= 10000 dx");
  const int n = marker_count(settings.input_radius, scheme.marker_spacing);
  directions_ = fibonacci_sphere(n);
  for (const Vec3& u : directions_)
    for (int d = 0; d < 3; ++d) offsets_.push_back(settings.input_radius * u[d]);
  marker_volume_ = immersed_boundary::marker_volume(settings.input_radius, n);
  box_ = static_cast<int>(std::ceil(2.0 * settings.input_radius)) + 5;
}

template <class Real>
ImmersedBoundary<Real>::~ImmersedBoundary() = default;

template <class Real>
void ImmersedBoundary<Real>::zero_boxes(const lattice::ForceFieldView<Real>& field) {
  if (written_.empty()) return;
  const lattice::Extent& e = field.extent;
  const auto colours = make_colours(written_, box_, e);
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
  if (kernel_width(settings_.scheme.kernel) == 3)
    apply_with_kernel<3>(liquid, spheres);
  else
    apply_with_kernel<2>(liquid, spheres);
}

template <class Real>
template <int W>
void ImmersedBoundary<Real>::apply_with_kernel(lattice::ForcedLiquid<Real>& liquid,
                                               const spheres::SphereSet& spheres) {
  using V4 = typename Simd<Real>::V4;
  using V4d = typename Simd<double>::V4;
  // A stencil cell lies within W/2 of its marker in each direction.
  constexpr double half_width = 0.5 * W;
  const lattice::Extent e = liquid.extent();
  const double ag = settings_.input_radius;
  const int length[3] = {e.nx, e.ny, e.nz};
  for (int d = 0; d < 3; ++d)
    if (length[d] <= 2.0 * ag + 3.0)
      throw std::invalid_argument(
          "immersed boundary: box length " + std::to_string(length[d]) +
          " must exceed 2 a_g + 3 = " + std::to_string(2.0 * ag + 3.0) +
          " (a sphere's kernel cells must not meet its own periodic image)");
  const lattice::ForceFieldView<Real> field = liquid.force_field();

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
  rows_.resize(2 * n * static_cast<std::size_t>(B) * B);
  auto rows_of = [&](std::size_t s) { return &rows_[2 * s * B * B]; };

  // The lattice rows are cut in 16-cell chunks; need_ marks the chunks with
  // cells that this apply() reads, held_ those holding force from the last one.
  const int chunks = (e.nx + 15) / 16;
  const int words = (chunks + 63) / 64;
  const std::size_t lattice_rows = static_cast<std::size_t>(e.rows());
  const bool zero_in_pass = !written_.empty() && held_.size() == lattice_rows * words;
  if (!zero_in_pass) zero_boxes(field);
  if (need_.size() != lattice_rows * words) need_.assign(lattice_rows * words, 0);
  ustar_.resize(4 * static_cast<std::size_t>(e.cells()));

  // The cells of every marker stencil: a stencil cell is within W/2 of its
  // marker in each direction, so it lies in the cube of that half-width
  // around some point of the sphere |X - centre| = a_g. Per box row: the cells
  // whose cube meets the ball of radius a_g (holes filled; this includes the
  // inside, |r| < a_g + 1/2, that the momentum sums need).
#pragma omp parallel for schedule(dynamic, 16)
  for (std::size_t s = 0; s < n; ++s) {
    const Vec3 centre = spheres.position[s];
    const auto& lo = origins_[s];
    std::int16_t* rows = rows_of(s);
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
    for_each_box_run(lo, rows, B, e, [&](int, int, int, int x, int count, long r) {
      std::uint64_t* word = &need_[static_cast<std::size_t>(r) * words];
      for (int c = x / 16; c <= (x + count - 1) / 16; ++c)
        std::atomic_ref<std::uint64_t>(word[c / 64])
            .fetch_or(std::uint64_t(1) << (c % 64), std::memory_order_relaxed);
    });
  }
  // The pass over the lattice rows, in memory order: zero the force field on
  // the chunks of the last apply() and compute u* on the chunks needed now
  // (runs of chunks at once), so that the streams are read nearly in order.
  auto pass_row = [&](std::size_t r) {
    const int y = static_cast<int>(r % e.ny), z = static_cast<int>(r / e.ny);
    if (zero_in_pass) {
      std::uint64_t* held = &held_[r * words];
      for (int c = 0; c < chunks; ++c)
        if (held[c / 64] >> (c % 64) & 1) {
          const int x0 = 16 * c, count = std::min(16, e.nx - x0);
          for (int d = 0; d < 3; ++d)
            std::fill_n(field.row(d, static_cast<long>(r)) + x0, count, Real(0));
        }
      std::fill_n(held, words, std::uint64_t(0));
    }
    const std::uint64_t* need = &need_[r * words];
    Real* out = &ustar_[4 * static_cast<std::size_t>(e.nx) * r];
    for (int c = 0; c < chunks;) {
      if (!(need[c / 64] >> (c % 64) & 1)) {
        ++c;
        continue;
      }
      int c1 = c + 1;
      while (c1 < chunks && (need[c1 / 64] >> (c1 % 64) & 1)) ++c1;
      const int x0 = 16 * c, x1 = std::min(e.nx, 16 * c1);
      liquid.macroscopic_row_without_force_field(x0, x1 - x0, y, z, out + 4 * x0);
      c = c1;
    }
  };
  const auto colours = make_colours(origins_, B, e);

  const int threads = omp_get_max_threads();
  if (static_cast<int>(workspaces_.size()) < threads)
    workspaces_.resize(static_cast<std::size_t>(threads));
  for (auto& w : workspaces_)
    if (!w) w = std::make_unique<Workspace>(B, markers);

  std::vector<double> slip_sq(settings_.measure_slip ? n : 0),
      slip_max(settings_.measure_slip ? n : 0);
  const int sweeps = settings_.scheme.sweeps;
  const bool measure = settings_.measure_slip;
  const Stencil<Real, W> stencil(B + 1, B);
  const Real dVr = static_cast<Real>(dV);

  // Calls fetch(address) for each cache line of ustar_ that sphere s reads
  // and of the force field that it adds to.
  auto sphere_lines = [&](int s, auto&& fetch) {
    constexpr int step = 64 / static_cast<int>(sizeof(Real));
    for_each_box_run(origins_[static_cast<std::size_t>(s)], rows_of(static_cast<std::size_t>(s)), B,
                     e, [&](int, int, int, int x, int count, long r) {
                       const Real* from = &ustar_[4 * (static_cast<std::size_t>(e.nx) * r + x)];
                       for (int q = 0; q < 4 * count; q += step) fetch(from + q);
                       fetch(from + 4 * count - 1);
                       for (int d = 0; d < 3; ++d) {
                         const Real* f = field.row(d, r) + x;
                         for (int q = 0; q < count; q += step) fetch(f + q);
                         fetch(f + count - 1);
                       }
                     });
  };

  auto process = [&](Workspace& ws, int s, int next) {
    const Vec3 centre = spheres.position[static_cast<std::size_t>(s)];
    const Vec3 up = spheres.velocity[static_cast<std::size_t>(s)];
    const Vec3 omega = spheres.angular_velocity[static_cast<std::size_t>(s)];
    const auto& lo = origins_[static_cast<std::size_t>(s)];
    const std::int16_t* rows = rows_of(static_cast<std::size_t>(s));
    const int R = ws.row_cells;
    // The lines of this sphere were fetched during the previous sphere's
    // sweeps, or are fetched now while the stencils are computed; the next
    // sphere's are fetched during this one's sweeps.
    if (ws.fetched != s) sphere_lines(s, [](const Real* p) { __builtin_prefetch(p); });
    ws.lines.clear();
    if (next >= 0) sphere_lines(next, [&](const Real* p) { ws.lines.push_back(p); });
    ws.fetched = next;
    std::size_t line = 0;
    const std::size_t lines_per_marker =
        ws.lines.size() / static_cast<std::size_t>(markers * sweeps) + 1;
    // Stencils (kernel weights) and targets, in vector loops over the markers
    // (arrays per direction), then packed.
    {
      const int M = markers;
      const double* r = offsets_.data();
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
      if constexpr (W == 3) sqrt_in_place(q, 3 * M);
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
    // u* and 1/(2 rho) of the sphere's cells, from the pass.
    for_each_box_run(lo, rows, B, e, [&](int j, int k, int i, int x, int count, long r) {
      const std::size_t box = static_cast<std::size_t>(R) * (j + B * k) + i;
      const Real* __restrict from = &ustar_[4 * (static_cast<std::size_t>(e.nx) * r + x)];
      Real* __restrict to = &ws.ustar[4 * box];
      Real* __restrict h = &ws.half_inv[4 * box];
      for (int c = 0; c < 4 * count; ++c) to[c] = from[c];
#pragma omp simd
      for (int c = 0; c < count; ++c) {
        const Real v = Real(0.5) / to[4 * c];
        h[4 * c] = h[4 * c + 1] = h[4 * c + 2] = h[4 * c + 3] = v;
      }
    });
    // v = u* + F / (2 rho) on the sphere's cells: what the next sweep (or
    // the slip measurement) interpolates.
    auto update_state = [&] {
      for (int row = 0; row < B * B; ++row) {
        const int i0 = rows[2 * row], i1 = rows[2 * row + 1];
        if (i0 > i1) continue;
        const std::size_t a = 4 * (static_cast<std::size_t>(R) * row + i0);
        const std::size_t b = 4 * (static_cast<std::size_t>(R) * row + i1 + 1);
        const Real* __restrict us = ws.ustar.data();
        const Real* __restrict h = ws.half_inv.data();
        const Real* __restrict f = ws.force.data();
        Real* __restrict v = ws.state.data();
#pragma omp simd
        for (std::size_t q = a; q < b; ++q) v[q] = us[q] + h[q] * f[q];
      }
    };
    // Multi-direct forcing: interpolate at all markers, then spread all
    // (Jacobi). The first sweep sees u* itself (no force yet).
    const Real* state = ws.ustar.data();
    for (int sweep = 0; sweep < sweeps; ++sweep) {
      for (int m = 0; m < markers; ++m) {
        for (std::size_t q = 0; q < lines_per_marker && line < ws.lines.size(); ++q)
          __builtin_prefetch(ws.lines[line++]);
        const std::size_t k = static_cast<std::size_t>(m);
        const V4 dF =
            forcing_increment(stencil.interpolate(state, ws.base[k], ws.weights[k]), ws.target[k]);
        ws.marker_force[k] += dF;
        ws.increment[k] = dF * dVr;
      }
      for (int m = 0; m < markers; ++m) {
        const std::size_t k = static_cast<std::size_t>(m);
        stencil.spread(ws.force.data(), ws.base[k], ws.weights[k],
                       reinterpret_cast<const Real*>(&ws.increment[k]));
      }
      if (sweep + 1 < sweeps || measure) {
        update_state();
        state = ws.state.data();
      }
    }
    if (measure) {
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
    Vec3 F = Vec3::Zero(), T = Vec3::Zero();
    for (int m = 0; m < markers; ++m) {
      const V4 f = ws.marker_force[static_cast<std::size_t>(m)];
      const Vec3 Fm = Vec3(f[1], f[2], f[3]) * dV;
      F -= Fm;
      T -= (ag * directions_[static_cast<std::size_t>(m)]).cross(Fm);
    }
    force_[static_cast<std::size_t>(s)] = F;
    torque_[static_cast<std::size_t>(s)] = T;
    // Momentum of the liquid inside, rho v = rho (u* + F/(2 rho)) (the
    // collision's), weighted by inside_weight().
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
        const Real* us = &ws.ustar[row];
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
    // Add this sphere's force to the lattice field, row by row, and clear the
    // scratch force (nonzero only on the rows' cells).
    for_each_box_run(lo, rows, B, e, [&](int j, int k, int i, int x, int count, long r) {
      Real* __restrict f = &ws.force[4 * (static_cast<std::size_t>(R) * (j + B * k) + i)];
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
  };

  // Blocks of one colour in parallel, handed out one at a time; a thread
  // takes its next block before working on the current one, so that it knows
  // the next sphere and can fetch its lines early.
  std::vector<std::atomic<std::size_t>> taken(colours.size());
#pragma omp parallel
  {
    Workspace& ws = *workspaces_[static_cast<std::size_t>(omp_get_thread_num())];
    ws.fetched = -1;
#pragma omp for schedule(dynamic, 64)
    for (std::size_t r = 0; r < lattice_rows; ++r) pass_row(r);
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
          process(ws, members[i], next);
        }
        block = following;
      }
#pragma omp barrier
    }
  }
  if (!zero_in_pass) held_.assign(lattice_rows * words, 0);
  need_.swap(held_);  // need_ is all zero again
  written_ = origins_;
  written_rows_.swap(rows_);
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
