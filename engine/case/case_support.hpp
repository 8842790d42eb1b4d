#pragma once
// Small helpers shared by the case readers (fluid_case, suspension_case).
#include <unistd.h>

#include <sstream>
#include <string>

#include "engine/input/field_table.hpp"

namespace flocsim::cases {

// A number as a user would type it (6 significant digits), for messages.
inline std::string format_value(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

// A number exactly as given (the shortest text that reads back as the same
// double): for refusals at a boundary, where 6 digits would print a refused
// value as an accepted one. The field table's own (input/field_table.hpp).
inline std::string exact_value(double v) {
  return input::exact_number(v);
}

// Physical memory of this machine in bytes (0 when the system does not say).
inline double physical_memory_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0.0;
}

}  // namespace flocsim::cases
