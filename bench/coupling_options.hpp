#pragma once
// The --options syntax of the coupling benchmarks (bench_coupling,
// bench_coupling_noise): a comma-separated list, each one of
//   direct:KERNEL:SPACING:SWEEPS   immersed boundary, direct forcing (also KERNEL:SPACING:SWEEPS)
//   control:KERNEL:SPACING[:G:P]   immersed boundary, control forcing
//   psm                            partially saturated cells
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "engine/coupling/scheme.hpp"

namespace flocsim::bench {

inline std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string p; std::getline(in, p, sep);) parts.push_back(p);
  return parts;
}

// One entry -> Scheme; nullopt when malformed or out of range (kernel roma3 or
// linear2, spacing in [0.3, 1.5] dx, sweeps in [1, 20]).
inline std::optional<coupling::Scheme> parse_option(const std::string& text) {
  if (text == "psm") return coupling::kPartiallySaturatedScheme;
  auto parts = split(text, ':');
  coupling::Scheme s;
  if (!parts.empty() && (parts[0] == "direct" || parts[0] == "control")) {
    s.forcing = *coupling::forcing_from_name(parts[0]);
    parts.erase(parts.begin());
  }
  const std::size_t wanted = s.control() ? 2 : 3;
  if (parts.size() != wanted && !(s.control() && parts.size() == 4)) return std::nullopt;
  const auto kernel = coupling::kernel_from_name(parts[0]);
  if (!kernel) return std::nullopt;
  s.kernel = *kernel;
  try {
    s.marker_spacing = std::stod(parts[1]);
    s.sweeps = s.control() ? 1 : std::stoi(parts[2]);
    if (s.control() && parts.size() == 4) s.gains = {std::stod(parts[2]), std::stod(parts[3])};
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (!(s.marker_spacing >= 0.3 && s.marker_spacing <= 1.5) || s.sweeps < 1 || s.sweeps > 20)
    return std::nullopt;
  return s;
}

inline const char* kOptionsSyntax =
    "psm, direct:KERNEL:SPACING:SWEEPS or control:KERNEL:SPACING[:G:P] with kernel roma3 or "
    "linear2, spacing in [0.3, 1.5] dx, sweeps in [1, 20]";

}  // namespace flocsim::bench
