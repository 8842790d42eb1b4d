#pragma once
// Tables for a terminal: the columns a user reads first, as many as fit the
// terminal's width, in their given order, and a line naming those left out
// (`flocsim query` and `flocsim post`; their files keep every column).
#include <cstddef>
#include <ostream>
#include <string>
#include <vector>

#include "engine/text/printable.hpp"

namespace flocsim::orchestrator {

struct TerminalColumn {
  std::string header;
  std::vector<std::string> cells;  // one per row
};

// Writes the columns, two spaces apart, keeping them in order while they fit
// in `width` characters (0: no limit); the first column is always kept. Returns
// the headers of the columns left out.
std::vector<std::string> write_fitted(const std::vector<TerminalColumn>& columns, std::size_t width,
                                      std::ostream& out);

// The width to fit: the terminal's when `out_fd` is one, else $COLUMNS when
// set, else 0 (no limit: a pipe or file gets every column it asked for).
std::size_t terminal_width(int out_fd = 1);

// Every name and value printed for a terminal goes through text::printable
// (engine/text/printable.hpp): control and bidirectional characters escaped.
using text::printable;

// Characters a UTF-8 string takes on a terminal (one per code point).
std::size_t display_width(const std::string& s);

}  // namespace flocsim::orchestrator
