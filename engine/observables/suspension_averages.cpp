#include "engine/observables/suspension_averages.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace flocsim::observables {

double superficial_slip_velocity(double liquid_mean_velocity_x, double sphere_mean_velocity_x,
                                 double phi) {
  return (1.0 - phi) * (liquid_mean_velocity_x - sphere_mean_velocity_x);
}

double dimensionless_drag(double body_force_density, double radius, double phi, double viscosity,
                          double slip_velocity) {
  const double hydrodynamic_force =
      body_force_density * 4.0 / 3.0 * M_PI * radius * radius * radius * (1.0 / phi - 1.0);
  return hydrodynamic_force / (6.0 * M_PI * radius * viscosity * slip_velocity);
}

double granular_temperature(const std::vector<spheres::Vec3>& velocity) {
  if (velocity.empty()) return 0.0;
  spheres::Vec3 mean = spheres::Vec3::Zero();
  for (const auto& v : velocity) mean += v;
  mean /= static_cast<double>(velocity.size());
  double sum = 0;
  for (const auto& v : velocity) sum += (v - mean).squaredNorm();
  return sum / (3.0 * static_cast<double>(velocity.size()));
}

std::vector<double> slab_solids_fraction(const std::vector<spheres::Vec3>& position, double radius,
                                         const spheres::PeriodicBox& box, int slabs) {
  if (slabs < 1) throw std::invalid_argument("slab_solids_fraction: slabs must be >= 1");
  const double L = box.length.x(), width = L / slabs;
  std::vector<double> volume(static_cast<std::size_t>(slabs), 0.0);
  // Volume of a sphere between planes at offsets t0 < t1 from its centre
  // (clipped to [-a, a]): pi [a^2 t - t^3 / 3] from t0 to t1.
  auto cap = [radius](double t0, double t1) {
    t0 = std::max(t0, -radius);
    t1 = std::min(t1, radius);
    if (t1 <= t0) return 0.0;
    auto prim = [radius](double t) { return radius * radius * t - t * t * t / 3.0; };
    return M_PI * (prim(t1) - prim(t0));
  };
  for (const auto& p : position) {
    const double xc = p.x() - L * std::floor(p.x() / L);
    // the sphere spans [xc - a, xc + a]; its images at xc +- L cover the wrap
    for (double image : {xc - L, xc, xc + L}) {
      const int first = std::max(0, static_cast<int>(std::floor((image - radius) / width)));
      const int last = std::min(slabs - 1, static_cast<int>(std::floor((image + radius) / width)));
      for (int s = first; s <= last; ++s)
        volume[s] += cap(s * width - image, (s + 1) * width - image);
    }
  }
  const double slab_volume = width * box.length.y() * box.length.z();
  for (double& v : volume) v /= slab_volume;
  return volume;
}

namespace {
// Batch means with the series' integrated correlation time already measured.
SteadyAverage batch_means_with_tau(const std::vector<double>& series, int batches, double tau) {
  SteadyAverage out;
  out.samples = static_cast<long>(series.size());
  if (series.empty()) return out;
  if (batches < 2) throw std::invalid_argument("batch_means: at least 2 batches are needed");
  const long per = out.samples / batches;
  if (per < 1) throw std::invalid_argument("batch_means: fewer samples than batches");
  // use the last batches * per samples (the most recent, most stationary part)
  const long start = out.samples - per * batches;
  std::vector<double> means(static_cast<std::size_t>(batches), 0.0);
  for (int b = 0; b < batches; ++b) {
    double s = 0;
    for (long k = 0; k < per; ++k) s += series[start + b * per + k];
    means[b] = s / per;
  }
  double batch_mean = 0;
  for (double m : means) batch_mean += m;
  batch_mean /= batches;
  double var = 0;
  for (double m : means) var += (m - batch_mean) * (m - batch_mean);
  var /= (batches - 1);
  double all = 0;
  for (double x : series) all += x;
  out.mean = all / static_cast<double>(series.size());
  out.error = std::sqrt(var / batches);
  out.batches = batches;
  out.correlation_samples = tau;
  out.error_reliable = static_cast<double>(per) >= 5.0 * out.correlation_samples;
  return out;
}
}  // namespace

SteadyAverage batch_means(const std::vector<double>& series, int batches) {
  return batch_means_with_tau(series, batches,
                              series.empty() ? 0.0 : integrated_correlation_time(series));
}

SteadyAverage steady_average(const std::vector<double>& series, int most_batches,
                             double batch_over_tau, int fewest_reliable_batches) {
  if (most_batches < 2) throw std::invalid_argument("steady_average: most_batches must be >= 2");
  SteadyAverage out;
  out.samples = static_cast<long>(series.size());
  if (series.empty()) return out;
  if (std::any_of(series.begin(), series.end(), [](double x) { return !std::isfinite(x); })) {
    // no average to speak of: say so rather than estimate a correlation time
    out.mean = out.error = out.correlation_samples = std::numeric_limits<double>::quiet_NaN();
    return out;
  }
  const double tau = integrated_correlation_time(series);
  const long batch_length = std::max(1L, static_cast<long>(std::ceil(batch_over_tau * tau)));
  const long fit = out.samples / batch_length;
  if (fit >= 2) {
    out = batch_means_with_tau(series, static_cast<int>(std::min<long>(most_batches, fit)), tau);
    // batch_means' own test (a batch >= 5 tau) and enough batches
    out.error_reliable = out.error_reliable && out.batches >= fewest_reliable_batches;
    return out;
  }
  // too short for two batches of batch_over_tau correlation times
  double mean = 0;
  for (double x : series) mean += x;
  mean /= static_cast<double>(out.samples);
  double var = 0;
  for (double x : series) var += (x - mean) * (x - mean);
  var /= std::max(1L, out.samples - 1);
  out.mean = mean;
  out.error = std::sqrt(var * tau / static_cast<double>(out.samples));
  out.batches = 0;
  out.correlation_samples = tau;
  out.error_reliable = false;
  return out;
}

double integrated_correlation_time(const std::vector<double>& series) {
  const std::size_t n = series.size();
  if (n < 3) return 1.0;
  double mean = 0;
  for (double x : series) mean += x;
  mean /= static_cast<double>(n);
  double c0 = 0;
  for (double x : series) c0 += (x - mean) * (x - mean);
  if (c0 <= 0) return 1.0;  // a constant series: no correlation to speak of
  double tau = 1.0;
  for (std::size_t lag = 1; lag < n / 2; ++lag) {
    double c = 0;
    for (std::size_t i = 0; i + lag < n; ++i) c += (series[i] - mean) * (series[i + lag] - mean);
    const double rho = c / c0;
    if (rho <= 0) break;
    tau += 2.0 * rho;
  }
  return tau;
}

Drift window_drift(const std::vector<double>& series, double z_limit, double relative_floor) {
  Drift out;
  const std::size_t n = series.size();
  if (n < 3) return out;
  const double t_mean = 0.5 * static_cast<double>(n - 1);
  double x_mean = 0;
  for (double x : series) x_mean += x;
  x_mean /= static_cast<double>(n);
  double s_tt = 0, s_tx = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) - t_mean;
    s_tt += t * t;
    s_tx += t * (series[k] - x_mean);
  }
  const double slope = s_tx / s_tt;
  std::vector<double> residual(n);
  double ss = 0;
  for (std::size_t k = 0; k < n; ++k) {
    residual[k] = series[k] - x_mean - slope * (static_cast<double>(k) - t_mean);
    ss += residual[k] * residual[k];
  }
  out.change = slope * static_cast<double>(n - 1);
  const double variance = ss / static_cast<double>(n - 2);
  if (variance <= 0) {  // an exact line: any slope is a trend
    out.z = slope == 0 ? 0 : std::copysign(INFINITY, slope);
  } else {
    const double se = std::sqrt(variance * integrated_correlation_time(residual) / s_tt);
    out.z = slope / se;
  }
  out.stationary =
      std::abs(out.z) <= z_limit || std::abs(out.change) <= relative_floor * std::abs(x_mean);
  return out;
}

bool is_stationary(const std::vector<double>& series, long window, double tolerance) {
  const long n = static_cast<long>(series.size());
  if (window < 5 || n < 2 * window) return false;
  const std::vector<double> older(series.end() - 2 * window, series.end() - window);
  const std::vector<double> newer(series.end() - window, series.end());
  const SteadyAverage a = batch_means(older, 5), b = batch_means(newer, 5);
  const double spread = std::hypot(a.error, b.error);
  return std::abs(a.mean - b.mean) <= tolerance * spread;
}

}  // namespace flocsim::observables
