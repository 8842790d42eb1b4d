#include "orchestrator/terminal_table.hpp"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "engine/text/printable.hpp"

namespace flocsim::orchestrator {

std::size_t display_width(const std::string& s) {
  std::size_t w = 0;
  for (unsigned char ch : s) w += (ch & 0xC0) != 0x80;
  return w;
}

std::size_t terminal_width(int out_fd) {
  if (isatty(out_fd)) {
    winsize ws{};
    if (ioctl(out_fd, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0) return ws.ws_col;
  }
  if (const char* columns = std::getenv("COLUMNS"); columns && *columns) {
    const long n = std::strtol(columns, nullptr, 10);
    if (n > 0) return static_cast<std::size_t>(n);
  }
  return 0;
}

std::vector<std::string> write_fitted(const std::vector<TerminalColumn>& given, std::size_t width,
                                      std::ostream& out) {
  // every header and cell as the terminal should show it (names and values
  // come from sweep files and databases)
  std::vector<TerminalColumn> columns = given;
  for (TerminalColumn& c : columns) {
    c.header = text::printable(c.header);
    for (std::string& cell : c.cells) cell = text::printable(cell);
  }
  std::vector<std::size_t> w(columns.size(), 0);
  for (std::size_t c = 0; c < columns.size(); ++c) {
    w[c] = display_width(columns[c].header);
    for (const std::string& cell : columns[c].cells) w[c] = std::max(w[c], display_width(cell));
  }
  std::vector<std::size_t> shown;
  std::vector<std::string> left_out;
  std::size_t used = 0;
  for (std::size_t c = 0; c < columns.size(); ++c) {
    const std::size_t need = (shown.empty() ? 0 : 2) + w[c];
    if (c == 0 || width == 0 || used + need <= width) {
      shown.push_back(c);
      used += need;
    } else {
      left_out.push_back(columns[c].header);
    }
  }
  const std::size_t rows = columns.empty() ? 0 : columns.front().cells.size();
  for (std::size_t r = 0; r <= rows; ++r) {
    std::string line;
    for (std::size_t k = 0; k < shown.size(); ++k) {
      const TerminalColumn& col = columns[shown[k]];
      const std::string& cell =
          r == 0 ? col.header : (r - 1 < col.cells.size() ? col.cells[r - 1] : "");
      line += cell;
      if (k + 1 < shown.size()) line += std::string(w[shown[k]] - display_width(cell) + 2, ' ');
    }
    line.erase(line.find_last_not_of(' ') + 1);
    out << line << "\n";
  }
  return left_out;
}

}  // namespace flocsim::orchestrator
