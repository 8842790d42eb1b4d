#pragma once
// Tables for a terminal: the columns a user reads first, as many as fit the
// terminal's width, in their given order, and a line naming those left out
// (`flocsim query` and `flocsim post`; their files keep every column).
#include <cstddef>
#include <ostream>
#include <string>
#include <vector>

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

// `text` safe to print on a terminal: control characters (C0, DEL, C1: ESC
// sequences recolour, move or retitle the terminal) and the bidirectional
// controls (U+202E and its kin reorder what follows) are written as \x1b or
// \u202e, so that a name or value from a sweep file or database shows as what
// it is. Everything else, other UTF-8 included, is kept.
std::string terminal_text(const std::string& text);

// Characters a UTF-8 string takes on a terminal (one per code point).
std::size_t display_width(const std::string& s);

}  // namespace flocsim::orchestrator
