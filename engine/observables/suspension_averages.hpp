#pragma once
// The settling observables of docs/model.md section 4 that are plain formulas of
// averages, the slab solids fraction phi(x), and the steady-state statistics
// (batch means) with which their time series are summarised.
#include <vector>

#include "engine/spheres/sphere_set.hpp"

namespace flocsim::observables {

// U = (1 - phi)(<u> - <u_p>) along x: <u> over the liquid volume, <u_p> over
// the solid volume.
double superficial_slip_velocity(double liquid_mean_velocity_x, double sphere_mean_velocity_x,
                                 double phi);

// F = F_h / (6 pi a nu rho U) with F_h = f (4/3) pi a^3 (1/phi - 1), f the body
// force density on the liquid (rho = 1 in lattice units).
double dimensionless_drag(double body_force_density, double radius, double phi, double viscosity,
                          double slip_velocity);

// T = (1/3) <|u_p - <u_p>|^2>: the granular temperature.
double granular_temperature(const std::vector<spheres::Vec3>& velocity);

// Solids volume fraction of `slabs` equal slabs normal to x, from the exact
// volume of each sphere (and its periodic images) inside each slab.
std::vector<double> slab_solids_fraction(const std::vector<spheres::Vec3>& position, double radius,
                                         const spheres::PeriodicBox& box, int slabs);

// Mean of a stationary time series with its standard error from batch means:
// the series is cut into `batches` consecutive batches whose means are close
// to independent when a batch is much longer than the correlation time; the
// error is their standard deviation over sqrt(batches).
struct SteadyAverage {
  double mean = 0;   // over every sample of the series
  double error = 0;  // batch-means standard error of the mean
  long samples = 0;
  int batches = 0;
  // Integrated autocorrelation time in samples, tau = 1 + 2 sum_k rho(k),
  // summed until the autocorrelation first drops below zero. The error is
  // trustworthy when a batch spans several tau (batch_length >= 5 tau).
  double correlation_samples = 0;
  bool error_reliable = false;
};
SteadyAverage batch_means(const std::vector<double>& series, int batches);

// The steady average a run reports: batch means whose batches each span at
// least `batch_over_tau` integrated correlation times (5: successive batch
// means then correlate by less than about 1/(2 * 5), so their scatter measures
// the error), as many as fit up to `most_batches`. Few batches give an honest
// but itself uncertain error (relative scatter ~ 1/sqrt(2 (B - 1)): 35 % at 5
// batches), so error_reliable is set only from `fewest_reliable_batches` on. A
// window shorter than two such batches has no batch-means error: the error is
// then sigma sqrt(tau / n) from the measured correlation time, batches = 0,
// and it is flagged unreliable (one sample: error 0, unreliable). A series
// holding a NaN or infinity gets NaN mean and error.
SteadyAverage steady_average(const std::vector<double>& series, int most_batches = 10,
                             double batch_over_tau = 5.0, int fewest_reliable_batches = 5);

// Integrated autocorrelation time of a series, in samples (see SteadyAverage).
double integrated_correlation_time(const std::vector<double>& series);

// A slow drift over a statistics window, which batch means alone do not see
// (a rising <n_a> gives a tidy mean and a small error). The least-squares
// slope b of the series against the sample index, with its standard error
// widened by the residuals' integrated correlation time tau (an AR(1) series
// has var(b) ~ tau sigma^2 / S_tt), gives z = b / se(b); |z| > 3 is a trend,
// unless the change over the window is below `relative_floor` of the mean:
// a deterministic flow still converging by 1e-7 (a fixed array's drag over
// its last 10 a/U_inf, float) has almost no noise, so any slope has a huge z,
// yet no reported figure resolves it (float carries ~1e-6, the paper's
// resolution tolerance is 1.5e-2).
struct Drift {
  double change = 0;  // b (n - 1): the trend's change over the window
  double z = 0;       // b / se(b)
  bool stationary = true;
};
Drift window_drift(const std::vector<double>& series, double z_limit = 3.0,
                   double relative_floor = 1e-4);

// Dynamically stationary: the means of the last two windows of `window`
// samples differ by less than `tolerance` standard errors of their difference
// (batch-means errors, 5 batches per window). False while fewer than
// 2 * window samples exist.
bool is_stationary(const std::vector<double>& series, long window, double tolerance = 2.0);

}  // namespace flocsim::observables
