#include "engine/run/protocol.hpp"

#include <algorithm>
#include <cmath>

#include "engine/observables/suspension_averages.hpp"
#include "engine/result_names/result_names.hpp"

namespace flocsim::run {

namespace {

// `p`'s durations are in a / U_inf; `T` is a / U_inf in time steps.
Protocol::Durations durations_of(const cases::Protocol& p, double T) {
  auto steps = [T](double in_convective_times) {
    return static_cast<long>(std::llround(in_convective_times * T));
  };
  Protocol::Durations d;
  d.sample = std::max(1L, steps(p.sample_every));
  d.stage1_min = steps(p.stage1_min);
  d.stage1_max = steps(p.stage1_max);
  d.settle = steps(p.stage2_settle);
  d.statistics = std::max(d.sample, steps(p.statistics));
  d.snapshot = p.snapshot_every > 0 ? std::max(1L, steps(p.snapshot_every)) : 0;
  d.window_samples =
      std::max(5L, static_cast<long>(std::llround(p.stationarity_window / p.sample_every)));
  return d;
}

}  // namespace

Protocol::Protocol(const cases::SuspensionCase& c, const cases::SceneModules& modules)
    : d_(durations_of(c.protocol, c.derived.convective_time)),
      signal_(modules.liquid ? result_names::column::U_over_Uinf
                             : result_names::column::granular_temperature),
      convective_time_(c.derived.convective_time),
      du_over_uinf_(c.physics.du_over_uinf),
      target_escape_velocity_(c.derived.escape_velocity),
      // stage 2 exists only where a square well acts
      has_stage2_(modules.contacts && c.derived.escape_velocity > 0) {}

bool Protocol::done(long step) const {
  return statistics_start_ >= 0 && step - statistics_start_ >= d_.statistics;
}

long Protocol::expected_total(long step) const {
  const long after_stage1 = has_stage2_ ? d_.settle + d_.statistics : d_.statistics;
  if (stage_ == 1 && statistics_start_ < 0) return std::max(step, d_.stage1_max) + after_stage1;
  if (statistics_start_ >= 0) return statistics_start_ + d_.statistics;
  return stage2_start_ + d_.settle + d_.statistics;
}

std::pair<long, long> Protocol::length_bounds() const {
  // The loop decides only on sample steps (multiples of d_.sample): the first
  // decision is at the first sample, stage 1 ends at the first sample at or
  // after its bound, stage 2 is checked from the sample after it began, and
  // the statistics end at the first sample that completes them.
  const long sample = d_.sample;
  auto on_sample = [sample](long steps) {
    return (std::max(steps, 0L) + sample - 1) / sample * sample;
  };
  auto length = [&](long stage1_end) {
    const long start =
        has_stage2_ ? stage1_end + std::max(sample, on_sample(d_.settle)) : stage1_end;
    return start + on_sample(d_.statistics);
  };
  const long earliest = std::max(sample, on_sample(d_.stage1_min));
  const long latest = std::max(sample, on_sample(std::max(d_.stage1_min, d_.stage1_max)));
  return {length(earliest), length(latest)};
}

std::string Protocol::phase() const {
  return statistics_start_ >= 0 ? "statistics" : stage_ == 2 ? "stage 2" : "stage 1";
}

bool Protocol::advance(long step, const std::vector<double>& signal,
                       events::DirectInteractions& contacts, const spheres::SphereSet& spheres,
                       const spheres::PeriodicBox& box, RunLog& log) {
  if (stage_ == 1 && statistics_start_ < 0 && step >= d_.stage1_min) {
    const bool stationary = observables::is_stationary(signal, d_.window_samples);
    if (!stationary && step < d_.stage1_max) return false;
    stage1_stationary_ = stationary;
    const std::string why =
        stationary ? " (stationary)" : " (stage1_max reached before the detector fired)";
    if (has_stage2_) {
      stage_ = 2;
      stage2_start_ = step;
      contacts.set_escape_velocity(target_escape_velocity_);
      contacts.attach_pairs_within_well(spheres, box);
      log.info("stage 2 at t U_inf/a = " + std::to_string(step / convective_time_) + why +
               ": du/U_inf = " + std::to_string(du_over_uinf_));
    } else {
      statistics_start_ = step;
      log.info("statistics from t U_inf/a = " + std::to_string(step / convective_time_) + why);
    }
    return true;
  }
  if (stage_ == 2 && statistics_start_ < 0 && step - stage2_start_ >= d_.settle) {
    statistics_start_ = step;
    log.info("statistics from t U_inf/a = " + std::to_string(step / convective_time_));
  }
  return false;
}

void Protocol::write(output::Hdf5File& f) const {
  f.set_attribute("/", "stage", static_cast<std::int64_t>(stage_));
  f.set_attribute("/", "stage2_start", static_cast<std::int64_t>(stage2_start_));
  f.set_attribute("/", "statistics_start", static_cast<std::int64_t>(statistics_start_));
  f.set_attribute("/", "stage1_stationary", static_cast<std::int64_t>(stage1_stationary_));
}

void Protocol::read(const output::Hdf5File& f) {
  stage_ = static_cast<int>(f.attribute_int("/", "stage"));
  stage2_start_ = f.attribute_int("/", "stage2_start");
  statistics_start_ = f.attribute_int("/", "statistics_start");
  stage1_stationary_ = f.attribute_int("/", "stage1_stationary") != 0;
}

void Protocol::restore_well(events::DirectInteractions& contacts) const {
  if (stage_ == 2) contacts.set_escape_velocity(target_escape_velocity_);
}

}  // namespace flocsim::run
