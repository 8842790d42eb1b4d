#include "postprocess/report.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "engine/output/atomic_file.hpp"
#include "orchestrator/terminal_table.hpp"

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
    else if (c == '\'')
      out += "&#39;";
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

// The longest value a cell shows whole. A longer one (a sweep name made from
// every parameter, a case's numerics) is cut, with the whole text on hover:
// no single value may widen a table beyond the page.
constexpr std::size_t kLongestCell = 32;

// The first `n` characters of UTF-8 text (whole code points).
std::string first_characters(const std::string& s, std::size_t n) {
  std::size_t chars = 0, i = 0;
  for (; i < s.size(); ++i) {
    if ((static_cast<unsigned char>(s[i]) & 0xC0) != 0x80) {
      if (chars == n) break;
      ++chars;
    }
  }
  return s.substr(0, i);
}

// `s` whole when it has at most `most` characters, else cut with the whole on hover.
std::string short_text(const std::string& s, std::size_t most) {
  if (orchestrator::display_width(s) <= most) return escape(s);
  return "<span class='cut' title='" + escape(s) + "'>" + escape(first_characters(s, most - 1)) +
         "\u2026</span>";
}

std::string cell_text(const std::string& s) {
  return short_text(s, kLongestCell);
}

// A row's marks, each a short badge with its meaning on hover.
std::string flags_html(const RowFlags& f) {
  std::string out;
  std::istringstream details(f.detail);
  std::string line;
  std::map<char, std::string> why;
  while (std::getline(details, line))
    if (line.size() > 3) why[line[0]] = line.substr(3);
  for (char m : f.marks)
    out += std::string("<span class='flag' title='") + escape(why[m]) + "'>" + m + "</span>";
  return out;
}

struct HtmlTable {
  std::vector<std::string> headers;            // HTML already
  std::vector<std::vector<std::string>> rows;  // HTML already
  std::vector<bool> text_columns;              // left-aligned
  std::vector<std::string> groups;  // a header above each column ("": none), spanning equal ones
};

// A table in its own box, which scrolls sideways where the window is narrower.
std::string html(const HtmlTable& t) {
  std::string out = "<div class='scroll'><table>\n";
  bool grouped = false;
  for (const std::string& g : t.groups) grouped = grouped || !g.empty();
  if (grouped) {
    out += "<tr class='group'>";
    for (std::size_t c = 0; c < t.groups.size();) {
      std::size_t span = 1;
      while (c + span < t.groups.size() && t.groups[c + span] == t.groups[c]) ++span;
      out += "<th colspan='" + std::to_string(span) + "'" +
             (t.groups[c].empty() ? " class='blank'>" : ">") + t.groups[c] + "</th>";
      c += span;
    }
    out += "</tr>\n";
  }
  out += "<tr>";
  for (std::size_t c = 0; c < t.headers.size(); ++c)
    out += (c < t.text_columns.size() && t.text_columns[c] ? "<th class='text'>" : "<th>") +
           t.headers[c] + "</th>";
  out += "</tr>\n";
  for (const auto& row : t.rows) {
    out += "<tr>";
    for (std::size_t c = 0; c < row.size(); ++c)
      out += (c < t.text_columns.size() && t.text_columns[c] ? "<td class='text'>" : "<td>") +
             row[c] + "</td>";
    out += "</tr>\n";
  }
  return out + "</table></div>\n";
}

// A column of a grid for the page: its name in the grid, and the group and the
// header it shows under (empty header: the quantity's own label).
struct Shown {
  std::string name, group, header;
};

// Leaves out the columns no row fills.
void drop_empty_columns(HtmlTable& t) {
  for (std::size_t c = t.headers.size(); c-- > 0;) {
    bool filled = false;
    for (const auto& row : t.rows) filled = filled || (c < row.size() && !row[c].empty());
    if (filled) continue;
    t.headers.erase(t.headers.begin() + static_cast<long>(c));
    if (c < t.text_columns.size())
      t.text_columns.erase(t.text_columns.begin() + static_cast<long>(c));
    if (c < t.groups.size()) t.groups.erase(t.groups.begin() + static_cast<long>(c));
    for (auto& row : t.rows)
      if (c < row.size()) row.erase(row.begin() + static_cast<long>(c));
  }
}

// Columns of a grid (aggregation_cells and the like) by name, as HTML cells;
// a column no row fills is left out.
HtmlTable pick(const std::vector<std::vector<std::string>>& grid, const std::vector<Shown>& names) {
  HtmlTable t;
  std::vector<std::size_t> at;
  for (const Shown& n : names) {
    const auto it = std::find(grid.front().begin(), grid.front().end(), n.name);
    if (it == grid.front().end()) continue;
    const std::size_t c = static_cast<std::size_t>(it - grid.front().begin());
    bool filled = false;
    for (std::size_t r = 1; r < grid.size(); ++r) filled = filled || !grid[r][c].empty();
    if (!filled) continue;
    at.push_back(c);
    t.headers.push_back(n.header.empty() ? column_label(n.name, true) : n.header);
    t.text_columns.push_back(false);
    t.groups.push_back(n.group);
  }
  for (std::size_t r = 1; r < grid.size(); ++r) {
    std::vector<std::string> row;
    for (std::size_t c : at) row.push_back(cell_text(grid[r][c]));
    t.rows.push_back(std::move(row));
  }
  return t;
}

// Appends a column of HTML cells.
void add_column(HtmlTable& t, const std::string& header, const std::vector<std::string>& cells,
                bool text) {
  if (std::all_of(cells.begin(), cells.end(), [](const std::string& c) { return c.empty(); }))
    return;  // a column no row fills
  t.headers.push_back(header);
  if (!t.groups.empty()) t.groups.push_back("");
  t.text_columns.resize(t.headers.size() - 1, false);
  t.text_columns.push_back(text);
  for (std::size_t r = 0; r < t.rows.size() && r < cells.size(); ++r) t.rows[r].push_back(cells[r]);
}

std::string run_cell(const RunSummary& r, const RunSummary* baseline) {
  const std::string title =
      "run " + r.id + (baseline ? "\nbaseline (du = 0) " + baseline->id : std::string());
  return "<span class='id' title='" + escape(title) + "'>" + escape(r.id.substr(0, 12)) + "</span>";
}

std::string state_counts(const std::vector<RunSummary>& runs) {
  std::map<std::string, int> n;
  for (const RunSummary& r : runs) ++n[to_string(r.status)];
  std::string out;
  for (const auto& [state, count] : n)
    out += (out.empty() ? "" : ", ") + std::to_string(count) + " " + state;
  return out;
}

// What a figure shows, from its name ("spacetime_phi0.2_Re12_du0.03"): its
// kind, and the case it belongs to when it is drawn per case.
struct FigureName {
  std::string kind;         // "spacetime"
  std::string phi, re, du;  // "0.2", "12", "0.03"; empty for figures across cases
};

FigureName parse_figure_name(const std::string& name) {
  FigureName f;
  const auto at = name.find("_phi");
  f.kind = name.substr(0, at);
  if (at == std::string::npos) return f;
  const std::string rest = name.substr(at + 4);
  const auto re = rest.find("_Re");
  const auto du = rest.find("_du");
  f.phi = rest.substr(0, re);
  if (re != std::string::npos)
    f.re = rest.substr(re + 3, du == std::string::npos ? std::string::npos : du - re - 3);
  if (du != std::string::npos) f.du = rest.substr(du + 3);
  return f;
}

std::string figure_kind_label(const std::string& kind) {
  static const std::map<std::string, std::string> labels{
      {"drag_vs_Re", "F against Re, with Beetstra and Wylie (Fig. 1a, c)"},
      {"ReT_vs_Re", "Re<sub>T</sub> against Re (Fig. 4)"},
      {"n_a_vs_du", "&lang;n<sub>a</sub>&rang; against du/U<sub>&infin;</sub> (Fig. 10)"},
      {"drag_vs_Re_per_du", "F against Re per du/U<sub>&infin;</sub> (Fig. 11)"},
      {"drag_ratio_vs_size_ratio",
       "F/F<sub>0</sub> against &lang;n<sub>a</sub>&rang;/&lang;n<sub>a</sub>&rang;<sub>0</sub> "
       "(Fig. 12)"},
      {"timeseries", "U/U<sub>&infin;</sub>, C<sub>sph</sub>(t)"},
      {"size_distribution", "p(n<sub>a</sub>)"},
      {"pair_structure", "g(r), h(&theta;)"},
      {"spacetime", "&phi;(x, t) per du/U<sub>&infin;</sub>"}};
  const auto it = labels.find(kind);
  return it == labels.end() ? escape(kind) : it->second;
}

// "p(n_a), phi = 0.2, Re_inf = 12": what the figure shows and its case.
std::string figure_title(const Figure& f) {
  const FigureName n = parse_figure_name(f.name);
  std::string t = n.kind == "spacetime" ? std::string("&phi;(x, t)") : figure_kind_label(n.kind);
  if (!n.phi.empty()) t += ", &phi; = " + escape(n.phi);
  if (!n.re.empty()) t += ", Re<sub>&infin;</sub> = " + escape(n.re);
  if (!n.du.empty()) t += ", du/U<sub>&infin;</sub> = " + escape(n.du);
  return t;
}

// The figures' contents: those across cases by what they show, those drawn
// per case in a table of cases (phi, Re_inf) against kinds, so that a grid of
// a hundred figures stays one screen.
std::string figure_contents(const FigureSet& figures) {
  std::string across;
  std::vector<std::string> kinds;  // per-case kinds, in order of appearance
  std::map<std::pair<std::string, std::string>, std::map<std::string, std::string>> cases;
  std::vector<std::pair<std::string, std::string>> case_order;
  for (const Figure& f : figures.figures) {
    const FigureName n = parse_figure_name(f.name);
    const std::string link = "#fig-" + escape(f.name);
    if (n.phi.empty()) {
      across += "<li><a href='" + link + "'>" + figure_kind_label(n.kind) + "</a></li>";
      continue;
    }
    if (std::find(kinds.begin(), kinds.end(), n.kind) == kinds.end()) kinds.push_back(n.kind);
    const auto key = std::make_pair(n.phi, n.re);
    if (!cases.count(key)) case_order.push_back(key);
    std::string& cell = cases[key][n.kind];
    cell += (cell.empty() ? "" : " ") + std::string("<a href='") + link + "'>" +
            (n.du.empty() ? "show" : escape(n.du)) + "</a>";
  }
  std::string out = across.empty() ? "" : "<ol>" + across + "</ol>";
  if (!case_order.empty()) {
    out += "<div class='scroll'><table class='toc'><tr><th>&phi;</th><th>Re<sub>&infin;</sub></th>";
    for (const std::string& k : kinds) out += "<th>" + figure_kind_label(k) + "</th>";
    out += "</tr>";
    for (const auto& key : case_order) {
      out += "<tr><td>" + escape(key.first) + "</td><td>" + escape(key.second) + "</td>";
      for (const std::string& k : kinds) {
        const auto it = cases[key].find(k);
        out += "<td class='text'>" + (it == cases[key].end() ? "" : it->second) + "</td>";
      }
      out += "</tr>";
    }
    out += "</table></div>";
  }
  return out;
}

const char* kStyle =
    "body{font-family:sans-serif;margin:1.5em auto;max-width:1400px;padding:0 1em;"
    "box-sizing:border-box;color:#222;line-height:1.4}"
    "h2{margin-top:1.6em;border-bottom:1px solid #ddd}"
    ".scroll{overflow:auto;max-width:100%;max-height:85vh;margin:0 0 1.2em 0}"
    "table{border-collapse:collapse;font-size:13px}"
    "td,th{white-space:nowrap;border:1px solid #ccc;padding:3px 5px;text-align:right}"
    "th{background:#eee;font-weight:600}td.text,th.text{text-align:left}"
    "tr:not(.group) th{position:sticky;top:0;z-index:1}"
    "tr.group th{text-align:center;font-weight:normal;font-style:italic}"
    "tr.group th.blank{background:none;border:none}"
    "tr:nth-child(even) td{background:#fafafa}"
    ".cut,.id{cursor:help;border-bottom:1px dotted #888}"
    ".flag{display:inline-block;min-width:1.1em;margin-right:2px;padding:0 3px;border-radius:3px;"
    "background:#fde2b3;color:#6b4100;font-weight:bold;text-align:center;cursor:help}"
    ".bad{color:#a00}.note{font-size:13px;color:#444;max-width:60em}"
    "nav.toc{font-size:14px;background:#f6f6f6;border:1px solid #e2e2e2;padding:.4em 1em;"
    "display:inline-block}nav.toc ol{margin:.3em 0;padding-left:1.6em}"
    "table.toc{font-size:13px;margin:.3em 0 .3em 1.6em}table.toc td a{margin-right:.4em}"
    "img{max-width:100%;height:auto;border:1px solid #ddd}figure{margin:1.5em 0}"
    "figcaption{font-size:13px;color:#333;max-width:70em}";

}  // namespace

void write_report(const std::vector<RunSummary>& runs, const FigureSet& figures,
                  const std::string& database, const std::filesystem::path& file,
                  const std::vector<std::string>& left_out) {
  const std::vector<AggregationRow> agg = aggregation_table(runs);
  const std::vector<NonAggregatingRow> non = non_aggregating_table(runs);
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
    << "<meta name='viewport' content='width=device-width, initial-scale=1'>"
    << "<title>flocsim results: " << escape(database) << "</title>\n<style>" << kStyle
    << "</style></head><body>\n";
  h << "<h1>flocsim results</h1>\n<p>Database <code>" << cell_text(database)
    << "</code>: " << runs.size() << " runs (" << escape(state_counts(runs))
    << "). Errors are batch-means standard errors; ratios carry first-order propagated errors of "
       "two independent runs. Each aggregating run is paired only with the du = 0 run of the same "
       "case. Flags: <span class='flag'>u</span> errors not reliable, <span class='flag'>s</span> "
       "a window still drifts (not stationary), <span class='flag'>b</span> no F/F<sub>0</sub>; "
       "hover over a flag, a cut value or a run for the details.</p>\n";
  for (const std::string& l : left_out)
    h << "<p class='bad'>Left out, unreadable: " << escape(l) << "</p>\n";

  // contents
  h << "<nav class='toc'><b>Contents</b><ol>"
    << "<li><a href='#aggregation'>Drag and aggregation relative to the non-aggregating "
       "case</a></li>"
    << "<li><a href='#non-aggregating'>Non-aggregating drag against the correlations</a></li>"
    << "<li><a href='#figures'>Figures</a>" << figure_contents(figures) << "</li>"
    << "<li><a href='#runs'>Runs and provenance</a></li></ol></nav>\n";

  // aggregation: the columns a reader needs, every column in the files
  h << "<h2 id='aggregation'>Drag and aggregation relative to the non-aggregating case</h2>\n";
  if (agg.empty()) {
    h << "<p>No run with du/U<sub>&infin;</sub> &gt; 0.</p>\n";
  } else {
    const std::string paper = "the paper (its text)";
    HtmlTable t = pick(aggregation_cells(agg),
                       {{"phi"},
                        {"Re_inf"},
                        {"du_over_Uinf"},
                        {"F_over_F0"},
                        {"n_a_over_n_a0"},
                        {"U_over_Uinf"},
                        {"F"},
                        {"F0"},
                        {"n_a"},
                        {"n_a0"},
                        {"C_sph"},
                        {"Re_T"},
                        {"n_a_paper", paper, column_label("n_a", true)},
                        {"n_a_over_paper", paper, "flocsim / paper"},
                        {"n_a_over_n_a0_paper", paper, column_label("n_a_over_n_a0", true)}});
    std::vector<std::string> flags, ids;
    for (const AggregationRow& row : agg) {
      flags.push_back(flags_html(aggregation_flags(row)));
      ids.push_back(run_cell(*row.run, row.baseline));
    }
    add_column(t, "flags", flags, true);
    add_column(t, "run", ids, true);
    h << html(t)
      << "<p class='note'>Every column (Re, the window, N, the verdicts in words, the baseline's "
         "id, the reason a row has no F/F<sub>0</sub>) is in <code>aggregation.md</code> and "
         "<code>aggregation.csv</code> beside this page; <code>columns.md</code> defines "
         "them.</p>\n";
  }

  h << "<h2 id='non-aggregating'>Non-aggregating drag against the correlations</h2>\n";
  if (non.empty()) {
    h << "<p>No completed run with du/U<sub>&infin;</sub> = 0.</p>\n";
  } else {
    HtmlTable t = pick(non_aggregating_cells(non), {{"phi"},
                                                    {"Re_inf"},
                                                    {"Re"},
                                                    {"F"},
                                                    {"F_Beetstra"},
                                                    {"dev_Beetstra_pct"},
                                                    {"F_Wylie"},
                                                    {"dev_Wylie_pct"},
                                                    {"U_over_Uinf"},
                                                    {"U_over_Uinf_RZ"},
                                                    {"dev_RZ_pct"},
                                                    {"Re_T"}});
    std::vector<std::string> flags, ids;
    for (const NonAggregatingRow& row : non) {
      flags.push_back(flags_html(run_flags(*row.run)));
      ids.push_back(run_cell(*row.run, nullptr));
    }
    add_column(t, "flags", flags, true);
    add_column(t, "run", ids, true);
    h << html(t);
  }

  h << "<h2 id='figures'>Figures</h2>\n";
  for (std::size_t i = 0; i < figures.figures.size(); ++i) {
    const Figure& f = figures.figures[i];
    std::ifstream in(f.png, std::ios::binary);
    std::stringstream bytes;
    bytes << in.rdbuf();
    std::string used, all;
    for (std::size_t k = 0; k < f.runs.size(); ++k) {
      all += (all.empty() ? "" : " ") + f.runs[k];
      if (k < 6) used += (used.empty() ? "" : ", ") + f.runs[k].substr(0, 12);
    }
    if (f.runs.size() > 6) used += " and " + std::to_string(f.runs.size() - 6) + " more";
    h << "<figure id='fig-" << escape(f.name) << "'><img alt='" << escape(f.name)
      << "' src='data:image/png;base64," << base64(bytes.str()) << "'><figcaption><b>Figure "
      << i + 1 << ": " << figure_title(f) << "</b>. " << escape(f.caption) << ". Runs ("
      << f.runs.size() << "): <span class='id' title='" << escape(all) << "'>" << escape(used)
      << "</span>. PDF, data and gnuplot script beside this page: <code>figures/"
      << escape(f.pdf.filename().string()) << "</code>.</figcaption></figure>\n";
  }
  for (const std::string& s : figures.skipped) h << "<p>Not drawn: " << escape(s) << "</p>\n";
  for (const std::string& s : figures.runs_left_out)
    h << "<p>Left out of figures: " << escape(s) << "</p>\n";

  h << "<h2 id='runs'>Runs and provenance</h2>\n";
  HtmlTable t;
  t.headers = {"run",
               "sweep",
               "state",
               "&phi;",
               "Re<sub>&infin;</sub>",
               "du/U<sub>&infin;</sub>",
               "fidelity",
               "numerics",
               "window (a/U<sub>&infin;</sub>)",
               "N",
               "flags",
               "wall time (s)",
               "version"};
  t.text_columns = {true, true,  true,  false, false, false, true,
                    true, false, false, true,  false, true};
  for (const RunSummary& r : runs) {
    const std::string numerics =
        r.case_json.contains("numerics") ? r.case_json["numerics"].dump() : std::string("{}");
    char window[64] = "", wall[32] = "", number[32];
    if (r.window_end > r.window_start)
      std::snprintf(window, sizeof window, "%.1f-%.1f", r.window_start, r.window_end);
    if (r.wall_s) std::snprintf(wall, sizeof wall, "%.0f", *r.wall_s);
    std::vector<std::string> row{run_cell(r, nullptr), cell_text(r.sweep)};
    row.push_back(r.status == db::RunState::kCompleted
                      ? escape(to_string(r.status))
                      : "<span class='bad'>" + escape(to_string(r.status)) + "</span>");
    for (double v : {r.phi, r.re_inf, r.du}) {
      std::snprintf(number, sizeof number, "%g", v);
      row.push_back(number);
    }
    row.push_back(cell_text(r.fidelity));
    row.push_back(cell_text(numerics));
    row.push_back(window);
    row.push_back(r.sphere_count ? std::to_string(r.sphere_count) : "");
    row.push_back(flags_html(run_flags(r)));
    row.push_back(wall);
    row.push_back(cell_text(r.flocsim_version));
    t.rows.push_back(std::move(row));
  }
  drop_empty_columns(t);
  h << html(t) << "</body></html>\n";
  output::write_file_atomically(file, h.str());
}

}  // namespace flocsim::postprocess
