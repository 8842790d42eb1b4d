#include "engine/run/sphere_results.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/observables/reference_correlations.hpp"
#include "engine/observables/suspension_averages.hpp"
#include "engine/output/atomic_file.hpp"
#include "engine/output/hdf5_file.hpp"
#include "engine/result_names/result_names.hpp"

namespace flocsim::run {

namespace fs = std::filesystem;
namespace column = result_names::column;
namespace observable = result_names::observable;

namespace {

// The samples of one column taken after the statistics started.
std::vector<double> statistics_window(const SphereRunState& s, long statistics_start,
                                      std::string_view column_name) {
  const auto& steps = s.series[column::step];
  const auto& values = s.series[column_name];
  std::vector<double> out;
  for (std::size_t k = 0; k < steps.size(); ++k)
    if (steps[k] > static_cast<double>(statistics_start)) out.push_back(values[k]);
  return out;
}

// Steady average with its batch-means error, batches of at least 5
// correlation times (observables::steady_average; at most 10 batches).
// The window is also tested for a slow drift (observables::window_drift): a
// drifting series is reported "stationary": false, with its change over the
// window, rather than as a bare mean.
nlohmann::json steady(const std::vector<double>& samples) {
  const auto a = observables::steady_average(samples);
  const auto drift = observables::window_drift(samples);
  return {{"mean", a.mean},
          {"error", a.error},
          {"batches", a.batches},
          {"samples", a.samples},
          {"correlation_samples", a.correlation_samples},
          {"error_reliable", a.error_reliable},
          {"stationary", drift.stationary},
          {"drift_over_window", drift.change},
          {"drift_z", std::isfinite(drift.z) ? drift.z : 1e300 * (drift.z > 0 ? 1 : -1)}};
}

}  // namespace

StatisticsSummary summarise(const cases::SuspensionCase& c, const SphereRunState& s,
                            const Protocol& protocol, const events::DirectInteractions& contacts,
                            const RunExtremes& extremes) {
  const double worst_momentum_drift = extremes.momentum_drift;
  const cases::SceneModules& modules = cases::modules_of(c.scene);
  const double a = c.numerics.radius_cells;
  const double mass = s.spheres.mass();
  auto window = [&](std::string_view name) {
    return statistics_window(s, protocol.statistics_start(), name);
  };
  auto key = [](std::string_view name) { return std::string(name); };
  nlohmann::json obs;
  // the steady averages the time series' columns declare
  for (const auto& col : kSphereColumns)
    if (!col.steady_average.empty()) obs[key(col.steady_average)] = steady(window(col.name));
  if (modules.liquid) {
    for (const auto& col : kLiquidColumns)
      if (!col.steady_average.empty()) obs[key(col.steady_average)] = steady(window(col.name));
    // F with <u> over every cell (docs/validation/paper-baseline.md, "Which <u>"); F is the
    // liquid-only reading flocsim reports
    const auto f_all = window(column::F_all_cells);
    if (std::none_of(f_all.begin(), f_all.end(), [](double v) { return std::isnan(v); }))
      obs[key(observable::F_all_cells)] = steady(f_all);
    const double phi = c.derived.phi_realised;
    const double re = obs[key(observable::Re)]["mean"].get<double>();
    nlohmann::json ref;
    ref["beetstra_F_at_measured_Re"] = observables::beetstra_drag(phi, re);
    ref["beetstra_normalisation"] =
        "F = F_h / (6 pi mu a U), F_h = f V_p (1/phi - 1), U superficial, Re = 2aU/nu";
    if (c.scene == cases::Scene::suspension) {
      ref["richardson_zaki_U_over_Uinf"] =
          observables::richardson_zaki_velocity_ratio(phi, c.physics.reynolds_inf);
      ref["richardson_zaki_exponent"] =
          observables::richardson_zaki_exponent(c.physics.reynolds_inf);
      ref["beetstra_U_over_Uinf"] =
          observables::beetstra_velocity_ratio(phi, c.physics.reynolds_inf);
    }
    if (c.scene == cases::Scene::single_sphere && c.derived.box.nx == c.derived.box.ny &&
        c.derived.box.ny == c.derived.box.nz) {
      // creeping-flow hindrance of the simple cubic array the periodic box makes
      ref["sangani_acrivos_K"] = calibration::sangani_acrivos_drag(2 * a / c.derived.box.nx);
    }
    obs["references"] = ref;
    // the lattice Mach number the run reached: |u| / c_s, c_s = 1 / sqrt(3)
    obs["max_liquid_speed"] = extremes.liquid_speed;
    obs["max_liquid_speed_outside_spheres"] = extremes.liquid_speed_outside_spheres;
    obs["max_liquid_Mach"] = extremes.liquid_speed * std::sqrt(3.0);
    obs["mass_balance"] = {
        {"worst_drift", extremes.mass_drift},
        {"relative_to_liquid_mass", extremes.mass_drift / std::max(1e-300, extremes.mass_first)},
        {"what",
         "largest |liquid mass (sum of rho over every cell) - its first sample| over the run"}};
    if (modules.spheres_move)
      obs["momentum_balance"] = {
          {"worst_drift", worst_momentum_drift},
          {"relative_to_sphere_momentum",
           worst_momentum_drift / std::max(1e-300, std::abs(mass * c.derived.sphere_count *
                                                            c.derived.settling_velocity))},
          {"what", c.numerics.inside_liquid == "rigid-body"
                       ? "lattice momentum + sum (m_p - rho V_p) u_p (rigid-body inside liquid), "
                         "x, minus its first sample"
                       : "lattice momentum + sum (m_p u_p - P_in), x, minus its first sample"}};
  } else {
    const auto samples = window(column::kinetic_energy);
    const auto wells = window(column::well_energy);
    const auto collisions = window(column::collisions);
    if (samples.size() >= 2) {
      // with e = 1 and no liquid, kinetic + well energy is conserved
      const double e0 = samples.front() + wells.front(), e1 = samples.back() + wells.back();
      obs["energy_relative_change"] = (e1 - e0) / e0;
      const auto times = window(column::time);
      const double span = times.back() - times.front();
      obs["collisions_per_sphere_per_convective_time"] =
          (collisions.back() - collisions.front()) / c.derived.sphere_count / span;
    }
  }
  if (modules.spheres_move) obs["max_sphere_speed"] = extremes.sphere_speed;
  obs["max_speeds_what"] =
      "largest speeds in lattice units at the samples (every protocol.sample_every) over the "
      "run: max_liquid_speed |u| over every cell, "
      "max_liquid_speed_outside_spheres over the cells outside every sphere, max_liquid_Mach = "
      "max_liquid_speed sqrt(3), max_sphere_speed |u_p|";
  Distributions dist;
  const double n_samples = static_cast<double>(window(column::step).size());
  dist.p.resize(s.size_distribution_sum.size());
  for (std::size_t n = 0; n < dist.p.size(); ++n)
    dist.p[n] = n_samples > 0 ? s.size_distribution_sum[n] / n_samples : 0.0;
  while (dist.p.size() > 2 && dist.p.back() == 0.0) dist.p.pop_back();
  dist.r_over_a = s.microstructure.radial_bin_centres();
  for (double& x : dist.r_over_a) x /= a;
  dist.g = s.microstructure.radial_distribution();
  dist.theta = s.microstructure.angular_bin_centres();
  dist.h = s.microstructure.angular_distribution();
  obs["size_distribution"] = dist.p;
  obs["g_r"] = {{"r_over_a", dist.r_over_a}, {"g", dist.g}};
  obs["h_theta"] = {{"theta", dist.theta}, {"h", dist.h}, {"pairs_closer_than", "3a"}};
  obs["microstructure_configurations"] = s.microstructure.configurations();
  obs["window"] = {{"start", protocol.statistics_start() / c.derived.convective_time},
                   {"end", s.step / c.derived.convective_time},
                   {"unit", "a/U_inf"},
                   {"samples", static_cast<long>(n_samples)}};
  obs["stage2_start"] = protocol.stage2_start() >= 0
                            ? nlohmann::json(protocol.stage2_start() / c.derived.convective_time)
                            : nullptr;
  obs["stage1_stationary"] = protocol.stage1_stationary();
  const auto& k = contacts.counters();
  obs["events"] = {{"collisions", k.collisions},
                   {"well_entries", k.well_entries},
                   {"escapes", k.escapes},
                   {"edge_bounces", k.edge_bounces},
                   {"attached_pairs_final", contacts.attached_count()},
                   {"worst_overlap", contacts.worst_overlap()}};
  return {std::move(obs), std::move(dist)};
}

nlohmann::json not_stationary(const nlohmann::json& obs, RunLog& log) {
  nlohmann::json drifting = nlohmann::json::array();
  for (auto it = obs.begin(); it != obs.end(); ++it)
    if (it.value().is_object() && it.value().contains("stationary") &&
        !it.value()["stationary"].get<bool>()) {
      drifting.push_back(it.key());
      char line[200];
      std::snprintf(line, sizeof line,
                    "%s is not stationary over the statistics window: it changes by %.4g "
                    "(z = %.1f); lengthen protocol.statistics or stage2_settle",
                    it.key().c_str(), it.value()["drift_over_window"].get<double>(),
                    it.value()["drift_z"].get<double>());
      log.warning(line);
    }
  return drifting;
}

// series.h5: the time series, phi(x, t) and the steady distributions.
void write_series(const fs::path& dir, const SphereRunState& s, int slabs, const Distributions& d) {
  output::TemporaryFile tmp(dir / "series.h5");
  {
    output::Hdf5File f(tmp.path(), output::Hdf5File::Mode::create);
    for (std::size_t col = 0; col < s.series.columns(); ++col)
      f.write("/" + s.series.names()[col], {s.series.column(col).size()},
              s.series.column(col).data());
    // phi(x, t): rows are samples (times in /time), columns slabs of width L / slabs
    const auto slab_count = static_cast<hsize_t>(slabs);
    f.write("/phi_x", {s.phi_x.size() / slab_count, slab_count}, s.phi_x.data());
    f.create_group("/distributions");
    f.write("/distributions/size_distribution", {d.p.size()}, d.p.data());
    f.write("/distributions/r_over_a", {d.r_over_a.size()}, d.r_over_a.data());
    f.write("/distributions/g", {d.g.size()}, d.g.data());
    f.write("/distributions/theta", {d.theta.size()}, d.theta.data());
    f.write("/distributions/h", {d.h.size()}, d.h.data());
    f.close();
  }
  tmp.commit();
}

}  // namespace flocsim::run
