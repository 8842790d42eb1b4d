#pragma once
// The time series of a sphere scene (series.h5, the checkpoint's /series),
// with its columns declared by name: a sample is a struct of named fields, and
// one table per struct gives each field its column name. The header (names())
// and every row come from the same table, so a column and its value cannot
// fall out of step. Scenes with a liquid add the settling observables of
// docs/model.md section 4.
//
// A column may name the result.json observable that is its steady average
// over the statistics window (sphere_results.cpp reports every such one).
//
// A new column: a field in SphereSample or LiquidSample, its row in the
// table beside it (names from engine/result_names), and its value where the
// sphere run samples (take_sample in sphere_run.cpp).
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "engine/result_names/result_names.hpp"

namespace flocsim::run {

// Every sphere scene's columns.
struct SphereSample {
  double step = 0;
  double time = 0;  // a / U_inf
  double stage = 0;
  double C_sph = 0;  // contacts per sphere
  double mean_aggregate_size = 0;
  double granular_temperature = 0;
  double Re_T = 0;
  double kinetic_energy = 0;
  double well_energy = 0;
  double collisions = 0;  // since the start
};

// The columns of scenes with a liquid.
struct LiquidSample {
  double U_over_Uinf = 0;
  double U = 0;  // superficial slip velocity
  double F = 0;  // dimensionless drag
  double Re = 0;
  double liquid_velocity = 0;  // <u>_x over the liquid cells
  double sphere_velocity = 0;  // <v>_x over the spheres
  double momentum_balance = 0;
  double liquid_velocity_all_cells = 0;
  double F_all_cells = 0;
};

template <class Sample>
struct Column {
  std::string_view name;
  double Sample::*value;
  std::string_view steady_average = {};  // its result.json observable; empty: none
};

namespace column_names = result_names::column;
namespace observable_names = result_names::observable;

inline constexpr Column<SphereSample> kSphereColumns[] = {
    {column_names::step, &SphereSample::step},
    {column_names::time, &SphereSample::time},
    {column_names::stage, &SphereSample::stage},
    {column_names::C_sph, &SphereSample::C_sph, observable_names::C_sph},
    {column_names::mean_aggregate_size, &SphereSample::mean_aggregate_size,
     observable_names::n_a_mean},
    {column_names::granular_temperature, &SphereSample::granular_temperature,
     observable_names::granular_temperature},
    {column_names::Re_T, &SphereSample::Re_T, observable_names::Re_T},
    {column_names::kinetic_energy, &SphereSample::kinetic_energy},
    {column_names::well_energy, &SphereSample::well_energy},
    {column_names::collisions, &SphereSample::collisions},
};

inline constexpr Column<LiquidSample> kLiquidColumns[] = {
    {column_names::U_over_Uinf, &LiquidSample::U_over_Uinf, observable_names::U_over_Uinf},
    {column_names::U, &LiquidSample::U, observable_names::U},
    {column_names::F, &LiquidSample::F, observable_names::F},
    {column_names::Re, &LiquidSample::Re, observable_names::Re},
    {column_names::liquid_velocity, &LiquidSample::liquid_velocity},
    {column_names::sphere_velocity, &LiquidSample::sphere_velocity},
    {column_names::momentum_balance, &LiquidSample::momentum_balance},
    {column_names::liquid_velocity_all_cells, &LiquidSample::liquid_velocity_all_cells},
    // averaged apart (sphere_results.cpp): unknown in runs resumed from older checkpoints
    {column_names::F_all_cells, &LiquidSample::F_all_cells},
};

class TimeSeries {
 public:
  explicit TimeSeries(bool with_liquid);

  // One row; `liquid` is required exactly when the series has a liquid's columns.
  void append(const SphereSample& sample, const LiquidSample* liquid = nullptr);

  const std::vector<std::string>& names() const { return names_; }
  std::size_t columns() const { return names_.size(); }
  std::size_t samples() const { return data_[0].size(); }
  bool with_liquid() const { return with_liquid_; }

  // A column's values by name (std::logic_error for a name it does not have).
  const std::vector<double>& operator[](std::string_view name) const;
  // By position, in names() order: for files that store every column.
  const std::vector<double>& column(std::size_t k) const { return data_[k]; }
  std::vector<double>& column(std::size_t k) { return data_[k]; }

 private:
  bool with_liquid_;
  std::vector<std::string> names_;
  std::vector<std::vector<double>> data_;
};

}  // namespace flocsim::run
