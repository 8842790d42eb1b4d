#include "postprocess/report.hpp"

#include <fstream>
#include <sstream>

#include "engine/output/atomic_file.hpp"

namespace flocsim::postprocess {

namespace {

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

std::string base64(const std::string& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) |
                       (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    for (int k = 3; k >= 0; --k) out += table[(v >> (6 * k)) & 63];
  }
  if (i < bytes.size()) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// A Markdown table as written by write_aggregation(..., "md") turned into HTML.
std::string html_table(const std::string& markdown) {
  std::istringstream in(markdown);
  std::string line, out = "<table>\n";
  bool head = true;
  while (std::getline(in, line)) {
    if (line.rfind("|---", 0) == 0) continue;
    std::vector<std::string> cells;
    std::size_t start = 1;
    while (start < line.size()) {
      const std::size_t end = line.find(" |", start);
      if (end == std::string::npos) break;
      std::string c = line.substr(start, end - start);
      c.erase(0, c.find_first_not_of(' '));
      cells.push_back(c);
      start = end + 2;
    }
    out += "<tr>";
    for (const auto& c : cells) {
      // Numbers keep "mean ± error" on one line; a long verdict or reason (the drifting
      // observables, why a run has no baseline) wraps so the table fits the page.
      const bool prose = !head && c.size() > 24 && c.find("±") == std::string::npos;
      out += (head ? "<th>" : (prose ? "<td class='prose'>" : "<td>")) + escape(c) +
             (head ? "</th>" : "</td>");
    }
    out += "</tr>\n";
    head = false;
  }
  return out + "</table>\n";
}

}  // namespace

void write_report(const std::vector<RunSummary>& runs, const FigureSet& figures,
                  const std::string& database, const std::filesystem::path& file) {
  std::ostringstream agg, non;
  write_aggregation(aggregation_table(runs), "md", agg);
  write_non_aggregating(non_aggregating_table(runs), "md", non);
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>flocsim results: "
    << escape(database) << "</title>\n<style>body{font-family:sans-serif;margin:2em;max-width:"
    << "1400px}table{border-collapse:collapse;font-size:13px;margin-bottom:1.5em}td,th{white-space:"
       "nowrap;border:1px "
       "solid #bbb;padding:3px 6px;text-align:right}th{background:#eee}img{max-width:100%;"
       "border:1px solid #ddd}figure{margin:1.5em 0}figcaption{font-size:13px;color:#333}"
       ".bad{color:#a00}td.prose{white-space:normal;min-width:14em;text-align:left}</style></"
       "head><body>\n";
  h << "<h1>flocsim results</h1>\n<p>Database <code>" << escape(database)
    << "</code>: " << runs.size()
    << " runs. Errors are batch-means standard errors; ratios carry first-order "
    << "propagated errors of two independent runs. Each aggregating run is paired only with the "
    << "du = 0 run of the same case.</p>\n";
  h << "<h2>Drag and aggregation relative to the non-aggregating case</h2>\n"
    << html_table(agg.str());
  h << "<h2>Non-aggregating drag against the correlations</h2>\n" << html_table(non.str());
  h << "<h2>Figures</h2>\n";
  for (const Figure& f : figures.figures) {
    std::ifstream in(f.png, std::ios::binary);
    std::stringstream bytes;
    bytes << in.rdbuf();
    h << "<figure><img alt='" << escape(f.name) << "' src='data:image/png;base64,"
      << base64(bytes.str()) << "'><figcaption><b>" << escape(f.name)
      << "</b>: " << escape(f.caption) << " (PDF: " << escape(f.pdf.filename().string())
      << ")</figcaption></figure>\n";
  }
  for (const std::string& s : figures.skipped) h << "<p>Not drawn: " << escape(s) << "</p>\n";
  h << "<h2>Runs and provenance</h2>\n<table><tr><th>run</th><th>sweep</th><th>state</th>"
    << "<th>phi</th><th>Re_inf</th><th>du/U_inf</th><th>fidelity</th><th>numerics</th>"
    << "<th>window (a/U_inf)</th><th>N</th><th>errors reliable</th><th>stationary</th>"
    << "<th>wall time (s)</th><th>version</th></tr>\n";
  for (const RunSummary& r : runs) {
    const std::string numerics =
        r.case_json.contains("numerics") ? r.case_json["numerics"].dump() : std::string("{}");
    char window[64] = "";
    if (r.window_end > r.window_start)
      std::snprintf(window, sizeof window, "%.1f-%.1f", r.window_start, r.window_end);
    char wall[32] = "";
    if (r.wall_s) std::snprintf(wall, sizeof wall, "%.0f", *r.wall_s);
    std::string stationary = r.has_result ? "yes" : "";
    if (!r.not_stationary.empty()) {
      stationary = "no:";
      for (const auto& n : r.not_stationary) stationary += " " + n;
    }
    h << "<tr><td>" << escape(r.id.substr(0, 12)) << "</td><td>" << escape(r.sweep) << "</td><td"
      << (r.status == db::RunState::kCompleted ? "" : " class='bad'") << ">"
      << escape(to_string(r.status)) << "</td><td>" << r.phi << "</td><td>" << r.re_inf
      << "</td><td>" << r.du << "</td><td>" << escape(r.fidelity) << "</td><td>" << escape(numerics)
      << "</td><td>" << window << "</td><td>"
      << (r.sphere_count ? std::to_string(r.sphere_count) : "") << "</td><td>"
      << (r.has_result ? (r.errors_reliable ? "yes" : "no") : "") << "</td><td"
      << (r.not_stationary.empty() ? "" : " class='bad'") << ">" << escape(stationary)
      << "</td><td>" << wall << "</td><td>" << escape(r.flocsim_version) << "</td></tr>\n";
  }
  h << "</table>\n</body></html>\n";
  output::write_file_atomically(file, h.str());
}

}  // namespace flocsim::postprocess
