// flocsim post tables|figures|report --db F --out DIR: the paper's tables and
// figures from a results database (docs/postprocess.md). Only reads the
// database (also a read-only one, and one a running sweep is writing).
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "apps/flocsim/command_registry.hpp"
#include "db/results_db.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/output/atomic_file.hpp"
#include "orchestrator/terminal_table.hpp"
#include "postprocess/figures.hpp"
#include "postprocess/report.hpp"
#include "postprocess/tables.hpp"

namespace flocsim::app {
namespace {

namespace fs = std::filesystem;
namespace pp = flocsim::postprocess;

struct PostOptions {
  std::string db_path, out_dir, sweep;
  std::vector<std::string> where, columns;
  bool all = false;
};

// By a temporary file and a rename: a file replaced this way is never written
// through (an ofstream follows a symbolic link and overwrites its target).
void write_file(const fs::path& p, const std::string& text) {
  output::write_file_atomically(p, text);
}

// Every place in --out that post writes and finds taken (a file, a folder or
// a link by that name): the tables, the report and the figures folder at the
// top, and inside figures/ PNG, PDF, data/*.dat, scripts/*.gp and their logs.
std::vector<fs::path> taken_output_places(const fs::path& out) {
  auto taken = [](const fs::path& p) {
    std::error_code ec;
    return fs::exists(fs::symlink_status(p, ec));
  };
  auto ends_with = [](const std::string& name, const std::string& tail) {
    return name.size() >= tail.size() &&
           name.compare(name.size() - tail.size(), tail.size(), tail) == 0;
  };
  std::vector<fs::path> places;
  for (const char* name : {"aggregation.csv", "aggregation.md", "aggregation.tex",
                           "non_aggregating.csv", "non_aggregating.md", "non_aggregating.tex",
                           "columns.md", "left_out.md", "report.html", "figures"})
    if (taken(out / name)) places.push_back(out / name);
  const std::vector<std::pair<std::string, std::vector<std::string>>> folders = {
      {"figures", {".png", ".pdf"}},
      {"figures/data", {".dat"}},
      {"figures/scripts", {".gp", ".log"}}};
  for (const auto& [folder, tails] : folders) {
    const fs::path f = out / folder;
    std::error_code ec;
    if (folder != "figures" && taken(f)) places.push_back(f);
    if (fs::is_symlink(fs::symlink_status(f, ec)) || !fs::is_directory(f, ec)) continue;
    for (const auto& e : fs::directory_iterator(f, ec)) {
      const std::string name = e.path().filename().string();
      for (const std::string& tail : tails)
        if (ends_with(name, tail)) places.push_back(e.path());
    }
  }
  return places;
}

std::string joined(const std::vector<std::string>& items) {
  std::string list;
  for (const auto& l : items) list += (list.empty() ? "" : ", ") + l;
  return list;
}

// What an --out folder says it holds: written by an earlier flocsim post.
constexpr const char* kPostRecord = ".flocsim-post";

// Makes --out ready before any work, or refuses it (exit 2):
// - a path taken by a file, or a folder that cannot be made;
// - a symbolic link where post writes: post would write through it and
//   overwrite the link's target (gnuplot writes the figures itself, so a
//   rename cannot help there); the links are the user's, named, never removed;
// - files where post writes in a folder no earlier post wrote (no record):
//   they are the user's (their own aggregation.csv, say), and post replaces
//   only what it wrote. A folder with the record is post's to refresh.
// Then records the folder as post's.
void prepare_out(const fs::path& out) {
  std::error_code ec;
  if (fs::exists(fs::symlink_status(out, ec)) && !fs::is_directory(out, ec))
    throw input::InputError(
        "--out " + out.string() +
        ": exists and is not a folder; give a folder for the tables and figures");
  const std::vector<fs::path> places = taken_output_places(out);
  std::vector<std::string> links, files;
  for (const fs::path& p : places) {
    if (fs::is_symlink(fs::symlink_status(p, ec)))
      links.push_back(p.string());
    else if (!fs::is_directory(p, ec))
      files.push_back(p.string());
  }
  if (!links.empty())
    throw input::InputError("--out " + out.string() + ": " + joined(links) +
                            (links.size() > 1 ? " are symbolic links" : " is a symbolic link") +
                            " where flocsim post writes its output, which would overwrite what " +
                            (links.size() > 1 ? "they point" : "it points") +
                            " to; remove the link (flocsim does not) or use another --out folder");
  if (!files.empty() && !fs::exists(out / kPostRecord, ec))
    throw input::InputError(
        "--out " + out.string() + ": " + joined(files) + (files.size() > 1 ? " are" : " is") +
        " where flocsim post writes, and this folder has no " + kPostRecord +
        " record of an earlier flocsim post; post replaces only its own output, so move " +
        (files.size() > 1 ? "them" : "it") + " away or use another --out folder (a folder an " +
        "earlier version of post wrote has no record: if these are post's, `touch " +
        (out / kPostRecord).string() + "`)");
  fs::create_directories(out, ec);
  if (!ec) try {
      write_file(
          out / kPostRecord,
          "This folder holds the output of flocsim post, which replaces it when run again.\n");
    } catch (const std::exception& e) {
      throw input::InputError("--out " + out.string() + ": cannot write there (" + e.what() + ")");
    }
  if (ec)
    throw input::InputError("--out " + out.string() + ": cannot make the folder (" + ec.message() +
                            ")");
}

// Writes the tables (CSV, Markdown, LaTeX) and prints the aggregation table:
// the columns a user reads first, fitted to the terminal (the files keep all).
// The rows left out as unreadable are listed beside them in left_out.md.
void write_tables(const std::vector<pp::RunSummary>& runs, const std::vector<std::string>& left_out,
                  const fs::path& out, const PostOptions& o) {
  const auto agg = pp::aggregation_table(runs);
  const auto non = pp::non_aggregating_table(runs);
  for (const std::string format : {"csv", "md", "tex"}) {
    std::ostringstream a, n;
    pp::write_aggregation(agg, format, a);
    pp::write_non_aggregating(non, format, n);
    write_file(out / ("aggregation." + format), a.str());
    write_file(out / ("non_aggregating." + format), n.str());
  }
  write_file(out / "columns.md", pp::column_definitions());
  // written every time, so that an earlier post's list never outlives its truth
  std::string text = "# Rows left out\n\n";
  if (left_out.empty())
    text += "None: every selected row of the database could be read.\n";
  else
    text += "These rows of the database cannot be read and are in no table:\n\n";
  for (const std::string& l : left_out) text += "- " + l + "\n";
  write_file(out / "left_out.md", text);
  std::cout << "Aggregation: F/F0 against <n_a>/<n_a>0 (" << agg.size()
            << " runs with du > 0; every column in " << printable((out / "aggregation.md").string())
            << ")\n\n";
  pp::write_aggregation_terminal(agg, o.columns, o.all,
                                 o.all || !o.columns.empty() ? 0 : orchestrator::terminal_width(),
                                 std::cout);
  std::cout << "\nNon-aggregating runs against Beetstra, Wylie and "
            << "Richardson-Zaki: " << non.size() << " rows in "
            << printable((out / "non_aggregating.md").string())
            << "\nTables (CSV, Markdown, LaTeX) and their column definitions (columns.md) in "
            << printable(out.string()) << "\n";
  if (!left_out.empty())
    std::cout << left_out.size() << " unreadable row" << (left_out.size() > 1 ? "s" : "")
              << " left out of the tables: " << printable((out / "left_out.md").string()) << "\n";
}

int post(const std::string& what, const PostOptions& o) {
  try {
    std::vector<orchestrator::Filter> where;
    for (const std::string& w : o.where) where.push_back(orchestrator::parse_filter(w));
    // every option is checked before any work: --columns named an unknown
    // column only after every figure and table was written, and no report
    if (what != "figures") {
      std::ostringstream unused;
      pp::write_aggregation_terminal({}, o.columns, o.all, 0, unused);
    }
    // said before any work: without gnuplot there are no figures
    const std::string no_figures = what == "tables" ? "" : pp::why_no_figures();
    if (!no_figures.empty()) {
      if (what == "figures") {
        std::cerr << "flocsim post figures: no figures can be drawn: " << printable(no_figures)
                  << "\n";
        return kExitFailure;
      }
      std::cerr << "flocsim post report: no figures: " << printable(no_figures)
                << "; the tables and a report without figures are written\n";
    }
    db::ResultsDb db(o.db_path, db::ResultsDb::Mode::kReadOnly);
    prepare_out(fs::path(o.out_dir));  // after the database: a --db refused leaves no folder
    std::vector<orchestrator::DamagedRun> damaged;
    const auto runs = pp::load_runs(
        db, o.sweep.empty() ? std::nullopt : std::optional<std::string>(o.sweep), where, &damaged);
    std::vector<std::string> left_out;
    for (const auto& d : damaged) {
      left_out.push_back(d.text());
      std::cerr << "flocsim post: left out, unreadable: " << printable(d.text()) << "\n";
    }
    const fs::path out(o.out_dir);
    if (what == "tables") {
      write_tables(runs, left_out, out, o);
    } else {
      const pp::FigureSet figures = pp::write_figures(runs, out / "figures");
      if (what == "figures")
        for (const auto& f : figures.figures) std::cout << printable(f.png.string()) << "\n";
      for (const auto& s : figures.skipped) std::cout << "not drawn: " << printable(s) << "\n";
      for (const auto& s : figures.runs_left_out)
        std::cerr << "flocsim post: left out of figures: " << printable(s) << "\n";
      if (what == "report") {
        write_tables(runs, left_out, out, o);
        pp::write_report(runs, figures, o.db_path, out / "report.html", left_out);
      }
      std::cout << figures.figures.size() << " figures (PNG and PDF, with their data and gnuplot "
                << "scripts) in " << printable((out / "figures").string()) << "\n";
      if (what == "report")
        std::cout << "Report (tables, figures, provenance; one file): "
                  << printable((out / "report.html").string()) << "\n";
    }
    return kExitOk;
  } catch (const input::InputError& e) {
    std::cerr << "flocsim post: " << printable(e.what()) << "\n";
    return kExitBadInput;
  } catch (const db::DbError& e) {
    std::cerr << "flocsim post: " << printable(e.what()) << "\n";
    return kExitFailure;
  } catch (const std::exception& e) {
    std::cerr << "flocsim post: " << printable(e.what()) << "\n";
    return kExitFailure;
  }
}

const bool registered = register_command(
    {"post", "The paper's tables, figures and an HTML report from a results database",
     [](CLI::App& cmd) {
       auto o = std::make_shared<PostOptions>();
       auto what = std::make_shared<std::string>();
       cmd.require_subcommand(1);
       for (const auto& [name, help] :
            {std::pair<std::string, std::string>{"tables",
                                                 "F/F0 against <n_a>/<n_a>0 per run, and the "
                                                 "non-aggregating drag against the correlations "
                                                 "(CSV, Markdown, LaTeX)"},
             {"figures", "The paper's figures where the data exist (PNG and PDF, gnuplot)"},
             {"report", "One self-contained HTML page: tables, figures and provenance"}}) {
         CLI::App* sub = cmd.add_subcommand(name, help);
         sub->add_option("--db", o->db_path, "Results database")->required();
         sub->add_option("--out,-o", o->out_dir, "Output folder")->required();
         sub->add_option("--sweep", o->sweep, "Only the runs of this sweep");
         sub->add_option("--where,-w", o->where, "Filter FIELD OP VALUE, as in flocsim query")
             ->take_all();
         if (name != "figures") {
           sub->add_option("--columns,-c", o->columns,
                           "The printed table's columns, by their names in the files (and "
                           "flags), e.g. phi,du_over_Uinf,F,F0,F_over_F0")
               ->delimiter(',');
           sub->add_flag("--all", o->all, "Print every column, however wide");
         }
         sub->callback([what, name = name] { *what = name; });
       }
       return CommandHandler([o, what] { return post(*what, *o); });
     }});

}  // namespace
}  // namespace flocsim::app
