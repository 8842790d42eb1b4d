#pragma once
// The names a run gives its quantities in series.h5 (time-series columns) and
// in result.json (steady observables): the contract between the solver
// (engine/run), the results database (db/) and post-processing. Spelled once
// here so that a writer and a reader cannot drift apart; header-only and
// dependency-free so that db/ can use it without the solver.
#include <array>
#include <string_view>

namespace flocsim::result_names {

// Columns of the time series (series.h5, one dataset per column, one value per
// sample; the checkpoint's /series group).
namespace column {
inline constexpr std::string_view step = "step";
inline constexpr std::string_view time = "time";  // in a / U_inf
inline constexpr std::string_view stage = "stage";
inline constexpr std::string_view C_sph = "C_sph";
inline constexpr std::string_view mean_aggregate_size = "mean_aggregate_size";
inline constexpr std::string_view granular_temperature = "granular_temperature";
inline constexpr std::string_view Re_T = "Re_T";
inline constexpr std::string_view kinetic_energy = "kinetic_energy";
inline constexpr std::string_view well_energy = "well_energy";
inline constexpr std::string_view collisions = "collisions";
// scenes with a liquid
inline constexpr std::string_view U_over_Uinf = "U_over_Uinf";
inline constexpr std::string_view U = "U";
inline constexpr std::string_view F = "F";
inline constexpr std::string_view Re = "Re";
inline constexpr std::string_view liquid_velocity = "liquid_velocity";
inline constexpr std::string_view sphere_velocity = "sphere_velocity";
inline constexpr std::string_view momentum_balance = "momentum_balance";
inline constexpr std::string_view liquid_velocity_all_cells = "liquid_velocity_all_cells";
inline constexpr std::string_view F_all_cells = "F_all_cells";
}  // namespace column

// Steady averages in result.json's "observables" (mean, error, drift).
namespace observable {
inline constexpr std::string_view C_sph = "C_sph";
inline constexpr std::string_view n_a_mean = "n_a_mean";  // mean of mean_aggregate_size
inline constexpr std::string_view granular_temperature = "granular_temperature";
inline constexpr std::string_view Re_T = "Re_T";
inline constexpr std::string_view U_over_Uinf = "U_over_Uinf";
inline constexpr std::string_view U = "U";
inline constexpr std::string_view F = "F";
inline constexpr std::string_view F_all_cells = "F_all_cells";
inline constexpr std::string_view Re = "Re";
}  // namespace observable

// The steady observables the results database's suspension_results view
// shows as columns (mean and error each), in its column order. The view is
// part of schema version 1 (db/results_db.cpp): a change here is a schema
// change and needs a migration there.
inline constexpr std::array<std::string_view, 6> kSummaryObservables = {
    observable::U_over_Uinf, observable::F,     observable::Re,
    observable::Re_T,        observable::C_sph, observable::n_a_mean};

}  // namespace flocsim::result_names
