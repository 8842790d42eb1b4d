#include "engine/partially_saturated/partially_saturated_cells.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "engine/partially_saturated/cell_coverage.hpp"
#include "engine/partially_saturated/covered_cell_body.hpp"

namespace flocsim::partially_saturated {

using spheres::Vec3;

namespace {
constexpr double kHalfDiagonal = kHalfCellDiagonal;
// Runs of cells are swept in blocks of kLanes (the row's buffers have the
// slack for a last whole block, lattice::CoveredRow::kPad): one vector of
// floats, two of doubles.
constexpr int kLanes = 16;
static_assert(lattice::CoveredRow<float>::kPad >= kLanes, "slack for a whole block");

// Sums of 16 rows of one chunk's lanes, q[i][0] + ... + q[i][kLanes - 1],
// accumulated over a run's chunks. One sum per row would end every run in
// 12 horizontal reductions (most of exchange()'s time); a tree of
// shuffles and adds sums eight rows at once instead.
class LaneSums {
 public:
  static_assert(kLanes == 16, "two groups of eight lanes per chunk");
  typedef double V8 __attribute__((vector_size(64)));
  typedef long long I8 __attribute__((vector_size(64)));

  void add(const double (&q)[16][kLanes]) {
    V8 v[16];
    for (int i = 0; i < 16; ++i) v[i] = load(q[i]) + load(q[i] + 8);
    // the tree's output lanes hold the totals of its inputs 0, 4, 2, 6, 1, 5, 3, 7
    for (int g = 0; g < 2; ++g) {
      const V8* p = v + 8 * g;
      total_[g] += tree(p[0], p[4], p[2], p[6], p[1], p[5], p[3], p[7]);
    }
  }
  // Adds the 16 sums, in order, to those of `out` (16 doubles, 64-byte aligned).
  template <class Sums>
  void add_to(Sums& out) const {
    static_assert(sizeof(Sums) == sizeof total_ && alignof(Sums) >= alignof(V8), "16 sums");
    V8* const to = reinterpret_cast<V8*>(&out);
    to[0] += total_[0];
    to[1] += total_[1];
  }

 private:
  static V8 load(const double* p) {
    V8 v;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  static V8 tree(V8 p0, V8 p1, V8 p2, V8 p3, V8 p4, V8 p5, V8 p6, V8 p7) {
    // halves: lanes 0-3 of a and b, 4-7 of a and b, added
    const auto halves = [](V8 a, V8 b) {
      return __builtin_shuffle(a, b, I8{0, 1, 2, 3, 8, 9, 10, 11}) +
             __builtin_shuffle(a, b, I8{4, 5, 6, 7, 12, 13, 14, 15});
    };
    const auto quarters = [](V8 a, V8 b) {
      return __builtin_shuffle(a, b, I8{0, 1, 8, 9, 4, 5, 12, 13}) +
             __builtin_shuffle(a, b, I8{2, 3, 10, 11, 6, 7, 14, 15});
    };
    const auto eighths = [](V8 a, V8 b) {
      return __builtin_shuffle(a, b, I8{0, 8, 2, 10, 4, 12, 6, 14}) +
             __builtin_shuffle(a, b, I8{1, 9, 3, 11, 5, 13, 7, 15});
    };
    return eighths(quarters(halves(p0, p1), halves(p2, p3)),
                   quarters(halves(p4, p5), halves(p6, p7)));
  }
  V8 total_[2] = {};
};
}  // namespace

template <class Real>
PartiallySaturatedCells<Real>::PartiallySaturatedCells(double input_radius)
    : coupling::SphereCoupling<Real>(coupling::kPartiallySaturatedScheme),
      input_radius_(input_radius) {
  if (!(input_radius >= 1.0 && input_radius <= 2000.0))
    throw std::invalid_argument("partially saturated cells: input_radius = " +
                                std::to_string(input_radius) + ": must be in [1, 2000] dx");
  box_ = covering_box_edge(input_radius);
}

template <class Real>
void PartiallySaturatedCells<Real>::apply(lattice::ForcedLiquid<Real>& liquid,
                                          const spheres::SphereSet& spheres) {
  const lattice::Extent e = liquid.extent();
  const double reach = input_radius_ + kHalfDiagonal;
  check_box_length(e, input_radius_);
  extent_ = e;
  const std::size_t n = spheres.size();
  const int B = box_;
  motion_.resize(n);
  for (std::size_t s = 0; s < n; ++s) {
    const Vec3 u = spheres.velocity[s], w = spheres.angular_velocity[s];
    motion_[s] = {u[0], u[1], u[2], w[0], w[1], w[2]};
  }
  // Bands at least max(8, a_g + sqrt(3)/2) rows wide: a slice's rows (at most
  // 2 (a_g + sqrt(3)/2) + 1 of them) meet at most three bands.
  bands_ = std::max(1, static_cast<int>(e.ny / std::max(8.0, reach)));
  band_of_row_.resize(static_cast<std::size_t>(e.ny));
  for (int y = 0; y < e.ny; ++y)
    band_of_row_[static_cast<std::size_t>(y)] =
        static_cast<std::int32_t>(static_cast<long>(y) * bands_ / e.ny);
  // Each sphere's slices with the bands they meet, counted per band; then
  // placed band by band (in sphere order within a band).
  band_first_.assign(static_cast<std::size_t>(bands_) * e.nz + 1, 0);
  listed_.clear();
  for (std::size_t s = 0; s < n; ++s) {
    // the centre in the box, its box's lowest corner from there (unwrapped)
    const double p[3] = {spheres.position[s][0], spheres.position[s][1], spheres.position[s][2]};
    const double none[3] = {0, 0, 0};
    const CoveringSphere placed = covering_sphere(p, none, none, e, input_radius_);
    const double(&c)[3] = placed.centre;
    const int(&lo)[3] = placed.lo;
    for (int k = 0; k < B; ++k) {
      const double rz = lo[2] + k - c[2];
      const double left = reach * reach - rz * rz;
      if (left <= 0) continue;
      const double half = std::sqrt(left);
      const int j0 = std::max(0, static_cast<int>(std::ceil(c[1] - half)) - lo[1]);
      const int j1 = std::min(B - 1, static_cast<int>(std::floor(c[1] + half)) - lo[1]);
      if (j0 > j1) continue;
      Listed l;
      l.slice = {static_cast<std::int32_t>(s), 0, lo[0], lo[1], j0, j1, c[0], c[1], rz};
      l.z = wrap_once(lo[2] + k, e.nz);
      // the bands its rows y0 .. y1 meet, each once (the rows wrap into at
      // most two stretches)
      const int y0 = wrap_once(lo[1] + j0, e.ny), y1 = wrap_once(lo[1] + j1, e.ny);
      const auto add_bands = [&](int from, int to) {
        for (int b = band_of_row_[static_cast<std::size_t>(from)];
             b <= band_of_row_[static_cast<std::size_t>(to)]; ++b) {
          if (std::find(l.bands, l.bands + l.count, b) != l.bands + l.count) continue;
          if (l.count == 3)
            throw std::logic_error("partially saturated cells: a slice meets more than 3 bands");
          l.bands[l.count++] = b;
        }
      };
      if (y0 <= y1) {
        add_bands(y0, y1);
      } else {
        add_bands(y0, e.ny - 1);
        add_bands(0, y1);
      }
      for (int q = 0; q < l.count; ++q)
        ++band_first_[static_cast<std::size_t>(l.bands[q] + bands_ * l.z) + 1];
      listed_.push_back(l);
    }
  }
  // Each slice's sums get a slot, plane by plane (in sphere order within a
  // plane): the thread stepping a plane writes a few KiB of them, together.
  next_.assign(static_cast<std::size_t>(e.nz) + 1, 0);
  for (const Listed& l : listed_) ++next_[static_cast<std::size_t>(l.z) + 1];
  for (int z = 0; z < e.nz; ++z)
    next_[static_cast<std::size_t>(z) + 1] += next_[static_cast<std::size_t>(z)];
  for (Listed& l : listed_) l.slice.sums = next_[static_cast<std::size_t>(l.z)]++;
  sums_.assign(listed_.size(), Sums{});
  for (std::size_t b = 0; b + 1 < band_first_.size(); ++b) band_first_[b + 1] += band_first_[b];
  next_.assign(band_first_.begin(), band_first_.end() - 1);
  slices_.resize(static_cast<std::size_t>(band_first_.back()));
  for (const Listed& l : listed_)
    for (int q = 0; q < l.count; ++q)
      slices_[static_cast<std::size_t>(
          next_[static_cast<std::size_t>(l.bands[q] + bands_ * l.z)]++)] = l.slice;
  body_force_ = liquid.body_force();
  liquid.set_solid_coverage(this);
}

template <class Real>
void PartiallySaturatedCells<Real>::remove(lattice::ForcedLiquid<Real>& liquid) {
  if (liquid.pending_solid_coverage() == this) liquid.set_solid_coverage(nullptr);
}

template <class Real>
void PartiallySaturatedCells<Real>::begin_step(int threads) {
  if (static_cast<int>(scratch_.size()) < threads)
    scratch_.resize(static_cast<std::size_t>(threads));
}

template <class Real>
void PartiallySaturatedCells<Real>::find_runs(int y, int z, Scratch& t) const {
  const lattice::Extent& e = extent_;
  const int B = box_;
  const double reach = input_radius_ + kHalfDiagonal, inner = input_radius_ - kHalfDiagonal;
  t.runs.clear();
  std::int32_t first = 0;  // in t.eps
  int cuts = 0;            // cells packed for the plane cut
  const std::size_t band =
      static_cast<std::size_t>(band_of_row_[static_cast<std::size_t>(y)] + bands_ * z);
  for (std::int32_t q = band_first_[band]; q < band_first_[band + 1]; ++q) {
    const Slice& slice = slices_[static_cast<std::size_t>(q)];
    // row y is row j of the sphere's box; the cells of it within
    // a_g + sqrt(3)/2 of the centre are i0 .. i1
    const int j = wrap_once(y - slice.corner_y, e.ny);
    if (j < slice.j0 || j > slice.j1) continue;
    const double ry = slice.corner_y + j - slice.centre_y, rz = slice.rz;
    const double left = reach * reach - ry * ry - rz * rz;
    if (left <= 0) continue;
    const double cx = slice.centre_x;
    const int lo_x = slice.corner_x;
    const double half = std::sqrt(left);
    const int i0 = std::max(0, static_cast<int>(std::ceil(cx - half)) - lo_x);
    const int i1 = std::min(B - 1, static_cast<int>(std::floor(cx + half)) - lo_x);
    if (i0 > i1) continue;
    const int cells = i1 - i0 + 1;
    if (t.eps.size() < static_cast<std::size_t>(first + cells + kLanes)) {
      t.eps.resize(2 * static_cast<std::size_t>(first + cells + kLanes));
      for (auto* v : {&t.rx, &t.ry, &t.rz}) v->resize(t.eps.size());
      t.at.resize(t.eps.size());
    }
    // cells a .. b lie within a_g - sqrt(3)/2 of the centre, wholly
    // inside; the others are cut below, all at once
    const double left_in = inner * inner - ry * ry - rz * rz;
    int a = i1 + 1, b_in = i1;
    if (left_in > 0) {
      const double half_in = std::sqrt(left_in);
      a = std::max(i0, static_cast<int>(std::ceil(cx - half_in)) - lo_x);
      b_in = std::min(i1, static_cast<int>(std::floor(cx + half_in)) - lo_x);
      if (a > b_in) a = i1 + 1, b_in = i1;
    }
    float* const eps = &t.eps[static_cast<std::size_t>(first)];
    std::fill_n(eps, cells, 1.0f);
    const float ry_f = static_cast<float>(ry), rz_f = static_cast<float>(rz);
    const auto pack = [&](int i) {
      t.rx[static_cast<std::size_t>(cuts)] = static_cast<float>(lo_x + i - cx);
      t.ry[static_cast<std::size_t>(cuts)] = ry_f;
      t.rz[static_cast<std::size_t>(cuts)] = rz_f;
      t.at[static_cast<std::size_t>(cuts++)] = first + (i - i0);
    };
    for (int i = i0; i < a; ++i) pack(i);
    for (int i = b_in + 1; i <= i1; ++i) pack(i);
    const std::size_t s = static_cast<std::size_t>(slice.sphere);
    Run run;
    run.sphere = static_cast<std::int32_t>(s);
    run.sums = static_cast<std::size_t>(slice.sums);
    run.ry = ry_f;
    run.rz = rz_f;
    for (int i = i0; i <= i1;) {  // pieces that do not cross the edge in x
      const int x = wrap_once(lo_x + i, e.nx);
      run.x = x;
      run.count = std::min(i1 - i + 1, e.nx - x);
      run.first = first + (i - i0);
      run.rx0 = lo_x + i - cx;
      t.runs.push_back(run);
      i += run.count;
    }
    first += cells;
  }
  if (t.cut.size() < t.rx.size()) t.cut.resize(t.rx.size());
  // whole blocks of lanes (the arrays have the slack; the cells beyond the
  // last are the sphere's centre, computed and dropped): a scalar remainder
  // loop of a few cells per row would take as long as the vector loop
  const int blocks = (cuts + kLanes - 1) / kLanes * kLanes;
  for (int q = cuts; q < blocks; ++q) {
    const std::size_t u = static_cast<std::size_t>(q);
    t.rx[u] = t.ry[u] = t.rz[u] = 0.0f;
  }
  const SphereCoverage coverage(input_radius_);
  const float *px = t.rx.data(), *py = t.ry.data(), *pz = t.rz.data();
  float* const cut = t.cut.data();
#pragma omp simd
  for (int q = 0; q < blocks; ++q) cut[q] = coverage(px[q], py[q], pz[q]);
  for (int q = 0; q < cuts; ++q) t.eps[static_cast<std::size_t>(t.at[q])] = cut[q];
}

template <class Real>
bool PartiallySaturatedCells<Real>::cover(lattice::CoveredRow<Real>& row) {
  Scratch& t = scratch_[static_cast<std::size_t>(row.thread)];
  find_runs(row.y, row.z, t);
  if (t.runs.empty()) return false;
  Real* const eps = row.coverage;
  Real* const V0 = row.solid_velocity[0];
  Real* const V1 = row.solid_velocity[1];
  Real* const V2 = row.solid_velocity[2];
  for (const Run& run : t.runs) {
    const std::array<double, 6>& m = motion_[static_cast<std::size_t>(run.sphere)];
    const float* const eps_k = &t.eps[static_cast<std::size_t>(run.first)];
    // whole chunks of the run at a time (the row's buffers have the slack):
    // the cells beyond its end add zero
    for (int w = 0; w < run.count; w += kLanes) {
      const int x0 = run.x + w, left = run.count - w;
#pragma omp simd
      for (int c = 0; c < kLanes; ++c) {
        const double ep = c < left ? eps_k[w + c] : 0.0f;
        const double rx = static_cast<float>(run.rx0 + (w + c));
        // u = u_p + omega x r at the cell centre
        eps[x0 + c] += static_cast<Real>(ep);
        V0[x0 + c] += static_cast<Real>(ep * (m[0] + m[4] * run.rz - m[5] * run.ry));
        V1[x0 + c] += static_cast<Real>(ep * (m[1] + m[5] * rx - m[3] * run.rz));
        V2[x0 + c] += static_cast<Real>(ep * (m[2] + m[3] * run.ry - m[4] * rx));
      }
    }
  }
  return true;
}

template <class Real>
void PartiallySaturatedCells<Real>::exchange(const lattice::CoveredRow<Real>& row) {
  if (row.force[0])
    exchange_runs<true>(row);
  else
    exchange_runs<false>(row);
}

template <class Real>
template <bool kForceField>
void PartiallySaturatedCells<Real>::exchange_runs(const lattice::CoveredRow<Real>& row) {
  const Scratch& t = scratch_[static_cast<std::size_t>(row.thread)];
  const Real* const eps = row.coverage;
  const Real* const V0 = row.solid_velocity[0];
  const Real* const V1 = row.solid_velocity[1];
  const Real* const V2 = row.solid_velocity[2];
  const Real* const rho = row.density;
  const Real* const J0 = row.momentum[0];
  const Real* const J1 = row.momentum[1];
  const Real* const J2 = row.momentum[2];
  const Real* const F0 = row.force[0];
  const Real* const F1 = row.force[1];
  const Real* const F2 = row.force[2];
  const lattice::Vector3 body = body_force_;
  // per cell of a chunk of the run: what it adds to the run's sums (rows of
  // Sums' order; four rows of zeros make two whole groups of eight)
  alignas(64) double q[16][kLanes] = {};
  for (const Run& run : t.runs) {
    const double y = run.ry, z = run.rz;
    const float* const eps_k = &t.eps[static_cast<std::size_t>(run.first)];
    LaneSums sums;
    for (int w = 0; w < run.count; w += kLanes) {
      const int x0 = run.x + w, left = run.count - w;
#pragma omp simd
      for (int c = 0; c < kLanes; ++c) {
        const int x = x0 + c;
        const bool inside = c < left;  // the cells beyond the run count nothing
        const double ep = inside ? eps_k[w + c] : 0.0f;
        double f0 = body.x, f1 = body.y, f2 = body.z;
        if constexpr (kForceField) {
          f0 += F0[x];
          f1 += F1[x];
          f2 += F2[x];
        }
        double d0, d1, d2;
        exchange_share(ep, eps[x], rho[x], V0[x], V1[x], V2[x], J0[x], J1[x], J2[x], f0, f1, f2, d0,
                       d1, d2);
        const double j0 = inside ? J0[x] : 0.0, j1 = inside ? J1[x] : 0.0,
                     j2 = inside ? J2[x] : 0.0;
        d0 = inside ? d0 : 0.0;
        d1 = inside ? d1 : 0.0;
        d2 = inside ? d2 : 0.0;
        const double rx = static_cast<float>(run.rx0 + (w + c));
        q[0][c] = d0, q[1][c] = d1, q[2][c] = d2;
        q[3][c] = y * d2 - z * d1, q[4][c] = z * d0 - rx * d2, q[5][c] = rx * d1 - y * d0;
        q[6][c] = ep * j0, q[7][c] = ep * j1, q[8][c] = ep * j2;
        q[9][c] = ep * (y * j2 - z * j1), q[10][c] = ep * (z * j0 - rx * j2);
        q[11][c] = ep * (rx * j1 - y * j0);
      }
      sums.add(q);
    }
    sums.add_to(sums_[run.sums]);
  }
}

template <class Real>
void PartiallySaturatedCells<Real>::after_liquid_step(const lattice::ForcedLiquid<Real>& liquid,
                                                      const spheres::SphereSet& spheres) {
  const std::size_t n = spheres.size();
  if (motion_.size() != n || sums_.size() != listed_.size())
    throw std::logic_error("partially saturated cells: after_liquid_step() without apply()");
  if (liquid.pending_solid_coverage() == this)
    throw std::logic_error(
        "partially saturated cells: after_liquid_step() before the liquid's step");
  std::vector<Vec3> dP(n, Vec3::Zero()), r_dP(n, Vec3::Zero()), momentum(n, Vec3::Zero()),
      angular(n, Vec3::Zero());
  // each sphere's slices, in the order of its planes (listed_ is in sphere
  // order, then plane order)
  for (const Listed& l : listed_) {
    const Sums& m = sums_[static_cast<std::size_t>(l.slice.sums)];
    const std::size_t s = static_cast<std::size_t>(l.slice.sphere);
    dP[s] += Vec3(m.dP[0], m.dP[1], m.dP[2]);
    r_dP[s] += Vec3(m.r_dP[0], m.r_dP[1], m.r_dP[2]);
    momentum[s] += Vec3(m.P[0], m.P[1], m.P[2]);
    angular[s] += Vec3(m.r_P[0], m.r_P[1], m.r_P[2]);
  }
  // the spheres give up what their solid operator gave the liquid
  this->force_.resize(n);
  this->torque_.resize(n);
  for (std::size_t s = 0; s < n; ++s) {
    this->force_[s] = -dP[s];
    this->torque_[s] = -r_dP[s];
  }
  this->record_internal_momenta(std::move(momentum), std::move(angular));
}

template class PartiallySaturatedCells<float>;
template class PartiallySaturatedCells<double>;

}  // namespace flocsim::partially_saturated
