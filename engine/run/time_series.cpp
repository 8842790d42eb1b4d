#include "engine/run/time_series.hpp"

#include <algorithm>
#include <stdexcept>

namespace flocsim::run {

TimeSeries::TimeSeries(bool with_liquid) : with_liquid_(with_liquid) {
  for (const auto& c : kSphereColumns) names_.emplace_back(c.name);
  if (with_liquid)
    for (const auto& c : kLiquidColumns) names_.emplace_back(c.name);
  data_.resize(names_.size());
}

void TimeSeries::append(const SphereSample& sample, const LiquidSample* liquid) {
  if ((liquid != nullptr) != with_liquid_)
    throw std::logic_error(with_liquid_ ? "time series: a row without its liquid columns"
                                        : "time series: liquid columns in a scene without liquid");
  std::size_t k = 0;
  for (const auto& c : kSphereColumns) data_[k++].push_back(sample.*c.value);
  if (liquid)
    for (const auto& c : kLiquidColumns) data_[k++].push_back(liquid->*c.value);
}

const std::vector<double>& TimeSeries::operator[](std::string_view name) const {
  const auto it = std::find(names_.begin(), names_.end(), name);
  if (it == names_.end()) throw std::logic_error("no time-series column " + std::string(name));
  return data_[static_cast<std::size_t>(it - names_.begin())];
}

}  // namespace flocsim::run
