#pragma once
// The start-up protocol of the paper (end of section 3) around the coupled
// step: stage 1 with du = 0 until a dynamically stationary state (two-window
// detector on U/U_inf with a liquid, on the granular temperature without; at
// least stage1_min and at most stage1_max a/U_inf); the switch-on of the
// square well; stage 2 with du at its target, stage2_settle a/U_inf to reach
// the new state; then `statistics` a/U_inf of samples that enter the steady
// averages. Without a square well (du = 0, or a scene without contacts)
// there is no stage 2: statistics begin when stage 1 ends.
//
// The protocol alone owns the well strength: it derives the target du from
// the case, hands the contacts du = 0 in stage 1, switches the well on, and
// keeps its state (stage, switch-on step, start of the statistics) in the
// checkpoint, restoring the well of a resumed stage 2.
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "engine/case/suspension_case.hpp"
#include "engine/events/direct_interactions.hpp"
#include "engine/output/hdf5_file.hpp"
#include "engine/run/run_log.hpp"
#include "engine/spheres/sphere_set.hpp"

namespace flocsim::run {

class Protocol {
 public:
  // The protocol's durations, in time steps.
  struct Durations {
    long sample, stage1_min, stage1_max, settle, statistics, snapshot, window_samples;
  };

  Protocol(const cases::SuspensionCase& c, const cases::SceneModules& modules);

  const Durations& durations() const { return d_; }
  // The time-series column whose stationarity ends stage 1: the slip velocity
  // where there is a liquid, the granular temperature in a granular gas.
  std::string_view stationarity_signal() const { return signal_; }

  // The square well's escape velocity now: 0 in stage 1, du from stage 2 on.
  double escape_velocity() const { return stage_ == 2 ? target_escape_velocity_ : 0.0; }

  int stage() const { return stage_; }
  long stage2_start() const { return stage2_start_; }          // -1 before stage 2
  long statistics_start() const { return statistics_start_; }  // -1 before the statistics
  bool stage1_stationary() const { return stage1_stationary_; }
  bool in_statistics() const { return statistics_start_ >= 0; }
  // The statistics window is complete at `step`.
  bool done(long step) const;
  // The run's length in steps as far as it is known at `step`.
  long expected_total(long step) const;
  // The run's length in steps before it starts: the shortest (stage 1 ends at
  // stage1_min, stationary at once) and the longest (stage1_max reached), with
  // every stage boundary on a sample step as the loop decides it.
  std::pair<long, long> length_bounds() const;
  // "stage 1", "stage 2" or "statistics", for progress lines.
  std::string phase() const;

  // After the sample taken at `step` (`signal` the stationarity signal's
  // column): ends stage 1 when stationary or at stage1_max, switching the
  // well on in `contacts` with the pairs already within it attached; starts
  // the statistics after stage 2 has settled. True when the run's expected
  // length changed.
  bool advance(long step, const std::vector<double>& signal, events::DirectInteractions& contacts,
               const spheres::SphereSet& spheres, const spheres::PeriodicBox& box, RunLog& log);

  // The protocol's state as root attributes of a checkpoint.
  void write(output::Hdf5File& f) const;
  void read(const output::Hdf5File& f);
  // The well strength of the restored stage, given to the contacts.
  void restore_well(events::DirectInteractions& contacts) const;

 private:
  Durations d_;
  std::string_view signal_;
  double convective_time_;
  double du_over_uinf_;
  double target_escape_velocity_;  // du in lattice units
  bool has_stage2_;                // a square well acts in this scene
  int stage_ = 1;
  long stage2_start_ = -1;      // step at which du was switched on
  long statistics_start_ = -1;  // step after which samples enter the averages
  bool stage1_stationary_ = false;
};

}  // namespace flocsim::run
