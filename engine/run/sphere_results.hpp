#pragma once
// What a sphere scene reports at the end, over the statistics window: the
// steady averages with their errors and drift (result.json's observables),
// the reference correlations at the measured state, the distributions p(n_a),
// g(r) and h(theta), and series.h5 (time series, phi(x, t), distributions).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string_view>
#include <vector>

#include "engine/case/suspension_case.hpp"
#include "engine/events/direct_interactions.hpp"
#include "engine/run/protocol.hpp"
#include "engine/run/run_log.hpp"
#include "engine/run/sphere_run_state.hpp"

namespace flocsim::run {

// Distributions over the statistics window.
struct Distributions {
  std::vector<double> p;            // p(n_a), index n_a
  std::vector<double> r_over_a, g;  // g(r)
  std::vector<double> theta, h;     // h(theta), pairs closer than 3a
};

struct StatisticsSummary {
  nlohmann::json observables;  // result.json's "observables"
  Distributions distributions;
};

StatisticsSummary summarise(const cases::SuspensionCase& c, const SphereRunState& s,
                            const Protocol& protocol, const events::DirectInteractions& contacts,
                            const RunExtremes& extremes);

// The steady averages among `observables` whose window still drifts: listed,
// and said in the log, so that nobody reads their means as steady-state
// values unawares.
nlohmann::json not_stationary(const nlohmann::json& observables, RunLog& log);

// series.h5: the time series, phi(x, t) (`slabs` per row) and the distributions.
void write_series(const std::filesystem::path& dir, const SphereRunState& s, int slabs,
                  const Distributions& d);

}  // namespace flocsim::run
