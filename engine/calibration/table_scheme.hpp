#pragma once
// How a calibration table entry names its coupling scheme (engine/coupling/
// scheme.hpp): "method" ("immersed-boundary" or "partially-saturated"; entries
// written before there was a choice have none: immersed boundary); for the
// immersed boundary "forcing" ("direct" or "control"; none: direct),
// marker_spacing, iterations (the number of direct-forcing sweeps) and
// kernel (none: Roma's, from before the kernel was a choice). Control gains
// are not part of an entry's identity (they do not change the calibration);
// the entry records those it was made with.
#include <cstdio>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "engine/coupling/scheme.hpp"

namespace flocsim::calibration {

inline coupling::Scheme scheme_from_entry(const nlohmann::json& entry, const std::string& origin) {
  coupling::Scheme scheme;
  const std::string method = entry.value("method", std::string("immersed-boundary"));
  const auto m = coupling::method_from_name(method);
  if (!m) throw std::runtime_error("calibration table " + origin + ": unknown method " + method);
  scheme.method = *m;
  if (!scheme.immersed_boundary()) return scheme;
  scheme.marker_spacing = entry.at("marker_spacing").get<double>();
  scheme.sweeps = entry.at("iterations").get<int>();
  const std::string kernel = entry.value("kernel", std::string("roma3"));
  const auto k = coupling::kernel_from_name(kernel);
  if (!k) throw std::runtime_error("calibration table " + origin + ": unknown kernel " + kernel);
  scheme.kernel = *k;
  const std::string forcing = entry.value("forcing", std::string("direct"));
  const auto f = coupling::forcing_from_name(forcing);
  if (!f) throw std::runtime_error("calibration table " + origin + ": unknown forcing " + forcing);
  scheme.forcing = *f;
  if (scheme.control() && entry.contains("gains")) {
    scheme.gains.integral = entry.at("gains").at("integral").get<double>();
    scheme.gains.proportional = entry.at("gains").at("proportional").get<double>();
  }
  return scheme;
}

inline void write_scheme(nlohmann::json& entry, const coupling::Scheme& scheme) {
  if (!scheme.immersed_boundary()) {
    entry["method"] = coupling::method_name(scheme.method);
    return;
  }
  entry["marker_spacing"] = scheme.marker_spacing;
  entry["iterations"] = scheme.sweeps;
  entry["kernel"] = coupling::kernel_name(scheme.kernel);
  if (scheme.control()) {
    entry["forcing"] = coupling::forcing_name(scheme.forcing);
    entry["gains"] = {{"integral", scheme.gains.integral},
                      {"proportional", scheme.gains.proportional}};
  }
}

// The `flocsim calibrate` options that name this scheme: " --marker-spacing 1
// --sweeps 1 --kernel roma3", " --forcing control --marker-spacing 1
// --kernel roma3", " --coupling partially-saturated".
inline std::string calibrate_options(const coupling::Scheme& scheme) {
  if (!scheme.immersed_boundary()) return " --coupling " + coupling::method_name(scheme.method);
  char spacing[32];
  std::snprintf(spacing, sizeof spacing, "%g", scheme.marker_spacing);
  std::string o = scheme.control() ? " --forcing control" : "";
  o += std::string(" --marker-spacing ") + spacing;
  if (!scheme.control()) o += " --sweeps " + std::to_string(scheme.sweeps);
  return o + " --kernel " + coupling::kernel_name(scheme.kernel);
}

}  // namespace flocsim::calibration
