#pragma once
// How a calibration table entry names its immersed-boundary scheme: the fields
// marker_spacing, iterations (the number of forcing sweeps) and kernel. Entries
// written before the kernel was a choice have no kernel field: they used Roma's.
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "engine/immersed_boundary/scheme.hpp"

namespace flocsim::calibration {

inline immersed_boundary::Scheme scheme_from_entry(const nlohmann::json& entry,
                                                   const std::string& origin) {
  immersed_boundary::Scheme scheme;
  scheme.marker_spacing = entry.at("marker_spacing").get<double>();
  scheme.sweeps = entry.at("iterations").get<int>();
  const std::string kernel = entry.value("kernel", std::string("roma3"));
  const auto k = immersed_boundary::kernel_from_name(kernel);
  if (!k) throw std::runtime_error("calibration table " + origin + ": unknown kernel " + kernel);
  scheme.kernel = *k;
  return scheme;
}

inline void write_scheme(nlohmann::json& entry, const immersed_boundary::Scheme& scheme) {
  entry["marker_spacing"] = scheme.marker_spacing;
  entry["iterations"] = scheme.sweeps;
  entry["kernel"] = immersed_boundary::kernel_name(scheme.kernel);
}

}  // namespace flocsim::calibration
