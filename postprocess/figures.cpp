#include "postprocess/figures.hpp"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "engine/observables/reference_correlations.hpp"
#include "engine/output/atomic_file.hpp"
#include "engine/output/hdf5_file.hpp"
#include "postprocess/paper_values.hpp"

namespace flocsim::postprocess {

namespace fs = std::filesystem;

namespace {

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.8g", v);
  return b;
}

std::string label(double phi, double re_inf) {
  return "phi" + num(phi) + "_Re" + num(re_inf);
}

// A file name part from anything (a run id read from the database): only
// letters, digits and . _ + -, so that a gnuplot script can quote it as it is.
std::string file_part(const std::string& text) {
  std::string out = text;
  for (char& ch : out)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '.' && ch != '_' && ch != '+' &&
        ch != '-')
      ch = '_';
  return out;
}

// Runs `gnuplot SCRIPT` in `dir` with its output in `log`, without a shell:
// no path or name ever reaches a command line that a shell would read. The
// exit status; 127 when gnuplot cannot be started.
int run_gnuplot(const fs::path& dir, const std::string& script, const fs::path& log) {
  const std::string log_path = log.string(), dir_path = dir.string();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("cannot start gnuplot: ") + strerror(errno));
  if (pid == 0) {
    const int fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
      close(fd);
    }
    if (chdir(dir_path.c_str()) != 0) _exit(127);
    char* const argv[] = {const_cast<char*>("gnuplot"), const_cast<char*>(script.c_str()), nullptr};
    execvp("gnuplot", argv);
    const char* why = "gnuplot: cannot be started (not found on PATH?)\n";
    [[maybe_unused]] const auto n = write(STDERR_FILENO, why, strlen(why));
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw std::runtime_error(std::string("gnuplot: ") + strerror(errno));
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// One figure under construction: its data blocks and gnuplot commands.
class Plot {
 public:
  Plot(const fs::path& dir, std::string name, std::string caption)
      : dir_(dir), name_(std::move(name)), caption_(std::move(caption)) {}
  // Writes a data file and returns its path as gnuplot should quote it:
  // relative to the figures folder, where gnuplot runs, so that neither the
  // folder's name nor anything read from the database enters the script.
  std::string data(const std::string& tag, const std::string& rows) {
    fs::create_directories(dir_ / "data");
    const std::string file = file_part(name_ + (tag.empty() ? "" : "_" + tag)) + ".dat";
    // by rename, never through a symbolic link left in the folder
    output::write_file_atomically(dir_ / "data" / file, rows);
    return "'data/" + file + "'";
  }
  std::ostringstream& commands() { return commands_; }
  // Records a run whose data the figure draws (each once, in order).
  void uses(const RunSummary* r) {
    if (r && std::find(runs_.begin(), runs_.end(), r->id) == runs_.end()) runs_.push_back(r->id);
  }
  // The rendered figure with the runs it drew.
  Figure with_runs(Figure f) const {
    f.runs = runs_;
    return f;
  }
  // Renders PNG and PDF with the same commands.
  Figure render(const std::string& size_png = "900,650",
                const std::string& size_pdf = "6in,4.3in") {
    fs::create_directories(dir_ / "scripts");
    Figure f{name_, caption_, dir_ / (name_ + ".png"), dir_ / (name_ + ".pdf")};
    const fs::path script = dir_ / "scripts" / (name_ + ".gp");
    // keep symbols off the frame (not for maps, which fill it)
    const std::string offsets =
        name_.rfind("spacetime", 0) == 0
            ? ""
            : "set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05\n";
    // The commands once per terminal, from a reset state, not replot: gnuplot 5.4's replot
    // after a multiplot redraws only its last panel.
    // (run in the figures folder: `cd figures && gnuplot scripts/NAME.gp` redraws)
    std::ostringstream text;
    text << "set terminal pngcairo size " << size_png << " enhanced font 'sans,11'\nset output '"
         << f.png.filename().string() << "'\n"
         << offsets << commands_.str() << "\nunset output\nreset\n"
         << "set terminal pdfcairo size " << size_pdf << " enhanced font 'sans,9'\nset output '"
         << f.pdf.filename().string() << "'\n"
         << offsets << commands_.str() << "\nunset output\n";
    output::write_file_atomically(script, text.str());
    const fs::path log = dir_ / "scripts" / (name_ + ".log");
    if (run_gnuplot(dir_, "scripts/" + name_ + ".gp", log) != 0)
      throw std::runtime_error("gnuplot failed on figure " + name_ + "; see " + log.string());
    return f;
  }

 private:
  fs::path dir_;
  std::string name_, caption_;
  std::ostringstream commands_;
  std::vector<std::string> runs_;
};

// A run's series.h5, read once; empty when the run has none.
struct Series {
  std::vector<double> time, stage, U_over_Uinf, C_sph, size_distribution, r_over_a, g, theta, h,
      phi_x;
  std::size_t slabs = 0;
};
// `problem`: why there is none ("" when the file was read).
Series read_series(const RunSummary& r, std::string* problem) {
  Series s;
  const fs::path file = fs::path(r.run_dir) / "series.h5";
  if (r.run_dir.empty()) {
    *problem = "the database records no folder for it";
    return s;
  }
  if (!fs::exists(file)) {
    *problem = file.string() + " is missing";
    return s;
  }
  try {
    const output::Hdf5File f(file, output::Hdf5File::Mode::read);
    auto read = [&](const std::string& name, std::vector<double>& into) {
      if (f.exists(name)) into = f.read<double>(name);
    };
    read("/time", s.time);
    read("/stage", s.stage);
    read("/U_over_Uinf", s.U_over_Uinf);
    read("/C_sph", s.C_sph);
    read("/distributions/size_distribution", s.size_distribution);
    read("/distributions/r_over_a", s.r_over_a);
    read("/distributions/g", s.g);
    read("/distributions/theta", s.theta);
    read("/distributions/h", s.h);
    if (f.exists("/phi_x")) {
      std::vector<hsize_t> shape;
      s.phi_x = f.read<double>("/phi_x", &shape);
      if (shape.size() == 2) s.slabs = shape[1];
    }
  } catch (const std::exception& e) {
    // a truncated file of a running run: no series yet (said only of completed runs)
    *problem = file.string() + " cannot be read (" + e.what() + ")";
    return Series{};
  }
  if (s.time.empty()) *problem = file.string() + " holds no time series (/time)";
  return s;
}

const char* kPoint = "with yerrorbars pt 7 ps 1.2";

}  // namespace

std::string why_no_figures() {
  // where execvp looks (its default search path when PATH is unset)
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/bin:/usr/bin");
  for (std::string d; std::getline(dirs, d, ':');)
    if (access((fs::path(d.empty() ? "." : d) / "gnuplot").c_str(), X_OK) == 0) return "";
  return "gnuplot, which draws them, is not on PATH (" + std::string(path ? path : "unset") +
         "); install gnuplot (5.2 or later, with the cairo "
         "terminals) and run flocsim post figures again";
}

FigureSet write_figures(const std::vector<RunSummary>& runs, const fs::path& dir) {
  FigureSet set;
  if (const std::string why = why_no_figures(); !why.empty()) {
    set.skipped.push_back("every figure: " + why);
    return set;
  }
  fs::create_directories(dir);
  std::vector<const RunSummary*> done;
  for (const RunSummary& r : runs)
    if (r.status == db::RunState::kCompleted && r.F && r.Re) done.push_back(&r);
  std::set<double> phis, res, dus;
  for (const RunSummary* r : done) {
    phis.insert(r->phi);
    res.insert(r->re_inf);
    dus.insert(r->du);
  }

  // ---- Fig. 1a/c: F against Re per phi (du = 0) with Beetstra and Wylie ----
  {
    Plot p(dir, "drag_vs_Re",
           "Non-aggregating drag F against Re per phi (symbols, batch-means errors), Beetstra's "
           "static random arrays (eq. 4, lines) and Wylie et al. eq. 5 at the runs' Re_T (open "
           "triangles) (paper Fig. 1a, c)");
    std::string plots;
    double re_max = 0;
    for (double phi : phis) {
      std::ostringstream rows, wylie;
      for (const RunSummary* r : done)
        if (r->phi == phi && r->du == 0) {
          p.uses(r);
          rows << num(r->Re->mean) << " " << num(r->F->mean) << " " << num(r->F->error.value_or(0))
               << "\n";
          wylie << num(r->Re->mean) << " "
                << num(observables::wylie_drag(phi, r->Re->mean, r->Re_T ? r->Re_T->mean : 0))
                << "\n";
          re_max = std::max(re_max, r->Re->mean);
        }
      if (rows.str().empty()) continue;
      plots += (plots.empty() ? "" : ", ") + p.data("phi" + num(phi), rows.str()) + " " + kPoint +
               " lc " + std::to_string(plots.size() % 7 + 1) + " title 'phi = " + num(phi) + "'";
      plots += ", " + p.data("wylie_phi" + num(phi), wylie.str()) +
               " with points pt 10 ps 1.4 lc rgb 'gray30' title 'Wylie eq. 5, phi = " + num(phi) +
               "'";
      plots += ", 10*" + num(phi) + "/(1-" + num(phi) + ")**2 + (1-" + num(phi) +
               ")**2*(1+1.5*sqrt(" + num(phi) + ")) + 0.413*x/(24*(1-" + num(phi) + ")**2)*(1/(1-" +
               num(phi) + ")+3*" + num(phi) + "*(1-" + num(phi) + ")+8.4*x**(-0.343))/(1+10**(3*" +
               num(phi) + ")*x**(-(1+4*" + num(phi) +
               ")/2)) with lines dt 2 lc rgb 'black' title 'Beetstra phi = " + num(phi) + "'";
    }
    if (plots.empty()) {
      set.skipped.push_back("drag_vs_Re: no completed run with du = 0");
    } else {
      p.commands() << "set xlabel 'Re'\nset ylabel 'F'\nset key left top\nset grid\nset xrange [0:"
                   << num(1.15 * re_max) << "]\nset samples 200\nplot " << plots << "\n";
      set.figures.push_back(p.with_runs(p.render()));
    }
  }

  // ---- Fig. 4: Re_T against Re per phi (du = 0) ----
  {
    Plot p(dir, "ReT_vs_Re",
           "Granular-temperature Reynolds number Re_T against Re per phi (Fig. 4)");
    std::string plots;
    for (double phi : phis) {
      std::ostringstream rows;
      for (const RunSummary* r : done)
        if (r->phi == phi && r->du == 0 && r->Re_T) {
          p.uses(r);
          rows << num(r->Re->mean) << " " << num(r->Re_T->mean) << " "
               << num(r->Re_T->error.value_or(0)) << "\n";
        }
      if (rows.str().empty()) continue;
      plots += (plots.empty() ? "" : ", ") + p.data("phi" + num(phi), rows.str()) + " " + kPoint +
               " title 'phi = " + num(phi) + "'";
    }
    if (plots.empty()) {
      set.skipped.push_back("ReT_vs_Re: no completed run with du = 0 and Re_T");
    } else {
      p.commands() << "set xlabel 'Re'\nset ylabel 'Re_T'\nset grid\nset key left top\nplot "
                   << plots << "\n";
      set.figures.push_back(p.with_runs(p.render()));
    }
  }

  // ---- per (phi, Re_inf): time series, p(n_a), g(r), h(theta) (Figs. 5, 7, 9, 2) ----
  std::map<std::pair<double, double>, std::vector<std::pair<const RunSummary*, Series>>> groups;
  for (const RunSummary& r : runs) {
    std::string problem;
    Series s = read_series(r, &problem);
    if (!s.time.empty()) {
      groups[{r.phi, r.re_inf}].push_back({&r, std::move(s)});
    } else if (r.status == db::RunState::kCompleted) {
      // a completed run the tables list but these figures cannot draw: never
      // left out without a word (a running run simply has no series yet)
      const std::string tag = label(r.phi, r.re_inf);
      set.runs_left_out.push_back(
          "run " + r.id.substr(0, 12) + " (phi = " + num(r.phi) + ", Re_inf = " + num(r.re_inf) +
          ", du/U_inf = " + num(r.du) + "): " + problem + "; it is missing from the figures " +
          "timeseries_" + tag + ", size_distribution_" + tag + ", pair_structure_" + tag +
          " and spacetime_" + tag + "_du" + num(r.du));
    }
  }
  if (groups.empty())
    set.skipped.push_back("time series, p(n_a), g(r), h(theta), phi(x,t): no series.h5 found");
  for (auto& [key, members] : groups) {
    const auto [phi, re_inf] = key;
    const std::string tag = label(phi, re_inf);
    // time series with t = 0 at the switch-on of the well (for du = 0: the end of stage 1)
    {
      Plot p(dir, "timeseries_" + tag,
             "U/U_inf (top) and C_sph (bottom) against time at phi = " + num(phi) +
                 ", Re_inf = " + num(re_inf) +
                 ", one curve per du/U_inf; t = 0 where the square "
                 "well is switched on (Figs. 5, 7)");
      std::string top, bottom;
      for (const auto& [r, s] : members) {
        p.uses(r);
        // without a well there is no switch: its statistics start where stage 1
        // was found stationary, the moment the others switch the well on
        double t0 = r->window_end > r->window_start ? r->window_start : s.time.front();
        for (std::size_t k = 0; k < s.stage.size(); ++k)
          if (s.stage[k] >= 2) {
            t0 = s.time[k];
            break;
          }
        std::ostringstream rows;
        for (std::size_t k = 0; k < s.time.size() && k < s.U_over_Uinf.size(); ++k)
          rows << num(s.time[k] - t0) << " " << num(s.U_over_Uinf[k]) << " "
               << num(k < s.C_sph.size() ? s.C_sph[k] : 0) << "\n";
        const std::string file = p.data("du" + num(r->du) + "_" + r->id.substr(0, 8), rows.str());
        top += (top.empty() ? "" : ", ") + file +
               " using 1:2 with lines lw 2 title 'du/U_{inf} = " + num(r->du) + "'";
        bottom += (bottom.empty() ? "" : ", ") + file +
                  " using 1:3 with lines lw 2 title 'du/U_{inf} = " + num(r->du) + "'";
      }
      p.commands() << "set multiplot layout 2,1\nset grid\nset xlabel 't U_{inf} / a'\nset ylabel "
                      "'U/U_{inf}'\nset key left top\nplot "
                   << top << "\nset ylabel 'C_{sph}'\nplot " << bottom << "\nunset multiplot\n";
      set.figures.push_back(p.with_runs(p.render("900,800", "6in,5.4in")));
    }
    // mass-weighted p(n_a) on log axes
    {
      Plot p(dir, "size_distribution_" + tag,
             "Mass-weighted aggregate size distribution p(n_a) at phi = " + num(phi) +
                 ", Re_inf = " + num(re_inf) + ", one curve per du/U_inf (Fig. 9)");
      std::string plots;
      for (const auto& [r, s] : members) {
        std::ostringstream rows;
        for (std::size_t n = 1; n < s.size_distribution.size(); ++n)
          if (s.size_distribution[n] > 0) rows << n << " " << num(s.size_distribution[n]) << "\n";
        if (rows.str().empty()) continue;
        p.uses(r);
        plots += (plots.empty() ? "" : ", ") +
                 p.data("du" + num(r->du) + "_" + r->id.substr(0, 8), rows.str()) +
                 " with linespoints pt 7 title 'du/U_{inf} = " + num(r->du) + "'";
      }
      if (!plots.empty()) {
        p.commands() << "set logscale xy\nset grid\nset xlabel 'n_a'\nset ylabel 'p(n_a)'\nplot "
                     << plots << "\n";
        set.figures.push_back(p.with_runs(p.render()));
      }
    }
    // g(r) and h(theta)
    {
      Plot p(dir, "pair_structure_" + tag,
             "Pair distribution g(r) (top) and angular distribution h(theta) of pairs closer than "
             "3a (bottom), theta = 0 along gravity, at phi = " +
                 num(phi) + ", Re_inf = " + num(re_inf) + " (Fig. 2)");
      std::string top, bottom;
      for (const auto& [r, s] : members) {
        if (s.g.empty() || s.h.empty()) continue;
        p.uses(r);
        std::ostringstream g, h;
        for (std::size_t k = 0; k < s.g.size() && k < s.r_over_a.size(); ++k)
          g << num(s.r_over_a[k]) << " " << num(s.g[k]) << "\n";
        for (std::size_t k = 0; k < s.h.size() && k < s.theta.size(); ++k)
          h << num(s.theta[k]) << " " << num(s.h[k]) << "\n";
        const std::string t = "du" + num(r->du) + "_" + r->id.substr(0, 8);
        top += (top.empty() ? "" : ", ") + p.data("g_" + t, g.str()) +
               " with lines lw 2 title 'du/U_{inf} = " + num(r->du) + "'";
        bottom += (bottom.empty() ? "" : ", ") + p.data("h_" + t, h.str()) +
                  " with lines lw 2 title 'du/U_{inf} = " + num(r->du) + "'";
      }
      if (!top.empty()) {
        // g and h are non-negative, r and theta start at 0: no padding below 0
        p.commands()
            << "set multiplot layout 2,1\nset grid\nset xlabel 'r/a'\nset ylabel "
               "'g(r)'\nset offsets 0, 0, graph 0.05, 0\nset xrange [0:*]\nset yrange [0:*]\nplot "
            << top
            << "\nset xlabel 'theta (rad)'\nset ylabel 'h(theta)'\nset xrange [0:pi]\n"
               "plot "
            << bottom << "\nunset multiplot\n";
        set.figures.push_back(p.with_runs(p.render("900,800", "6in,5.4in")));
      }
    }
    // space-time maps of phi(x, t) - phi, one per run
    for (const auto& [r, s] : members) {
      if (s.slabs == 0 || s.phi_x.empty()) continue;
      Plot p(dir, "spacetime_" + tag + "_du" + num(r->du),
             "Space-time map of the slab solids fraction phi(x, t) - phi at phi = " + num(phi) +
                 ", Re_inf = " + num(re_inf) + ", du/U_inf = " + num(r->du) + " (Figs. 3, 13)");
      p.uses(r);
      std::ostringstream rows;
      const std::size_t samples = s.phi_x.size() / s.slabs;
      for (std::size_t k = 0; k < samples && k < s.time.size(); ++k) {
        for (std::size_t j = 0; j < s.slabs; ++j)
          rows << num(s.time[k]) << " " << num((j + 0.5) / s.slabs) << " "
               << num(s.phi_x[k * s.slabs + j] - phi) << "\n";
        rows << "\n";
      }
      // a colour scale symmetric about zero: white is the mean solids fraction
      const std::string file = p.data("", rows.str());
      p.commands()
          << "set xlabel 't U_{inf} / a'\nset ylabel 'x / L'\nset cblabel "
             "'phi(x,t) - phi'\nset palette defined (-1 'blue', 0 'white', 1 'red')\n"
             "stats "
          << file
          << " using 3 nooutput\nm = abs(STATS_min) > abs(STATS_max) ? abs(STATS_min) : "
             "abs(STATS_max)\nset cbrange [-m:m]\nset autoscale xfix\nset autoscale yfix\nplot "
          << file << " using 1:2:3 with image notitle\n";
      set.figures.push_back(p.with_runs(p.render()));
    }
  }

  // ---- aggregation: <n_a> against du, F against Re per du, F/F0 against <n_a>/<n_a>0 ----
  const std::vector<AggregationRow> agg = aggregation_table(runs);
  {
    Plot p(dir, "n_a_vs_du",
           "Mean aggregate size <n_a> against du/U_inf per (phi, Re_inf) (Fig. 10)");
    std::string plots;
    for (double phi : phis)
      for (double re : res) {
        std::ostringstream rows;
        for (const RunSummary* r : done)
          if (r->phi == phi && r->re_inf == re && r->n_a) {
            p.uses(r);
            rows << num(r->du) << " " << num(r->n_a->mean) << " " << num(r->n_a->error.value_or(0))
                 << "\n";
          }
        if (rows.str().empty()) continue;
        plots += (plots.empty() ? "" : ", ") + p.data(label(phi, re), rows.str()) + " " + kPoint +
                 " title 'phi = " + num(phi) + ", Re_{inf} = " + num(re) + "'";
        // the paper's stated values for the same (phi, Re_inf), open symbols
        std::ostringstream paper;
        for (const PaperAggregateSize& q : paper_aggregate_sizes(phi, re))
          paper << num(q.du_over_Uinf) << " " << num(q.n_a) << "\n";
        if (!paper.str().empty())
          plots += ", " + p.data("paper_" + label(phi, re), paper.str()) +
                   " with points pt 6 ps 1.5 title 'paper (Fig. 9), phi = " + num(phi) +
                   ", Re_{inf} = " + num(re) + "'";
      }
    if (dus.size() < 2 || plots.empty()) {
      set.skipped.push_back("n_a_vs_du: fewer than two values of du/U_inf");
    } else {
      p.commands() << "set xlabel 'du/U_{inf}'\nset ylabel '<n_a>'\nset logscale y\nset grid\nset "
                      "key left top\nplot "
                   << plots << "\n";
      set.figures.push_back(p.with_runs(p.render()));
    }
  }
  {
    Plot p(dir, "drag_vs_Re_per_du", "Drag F against Re, one symbol per du/U_inf (Fig. 11)");
    std::string plots;
    int style = 5;
    for (double du : dus) {
      std::ostringstream rows;
      for (const RunSummary* r : done)
        if (r->du == du) {
          p.uses(r);
          rows << num(r->Re->mean) << " " << num(r->F->mean) << " " << num(r->F->error.value_or(0))
               << "\n";
        }
      plots += (plots.empty() ? "" : ", ") + p.data("du" + num(du), rows.str()) +
               " with yerrorbars pt " + std::to_string(style++) +
               " ps 1.3 title 'du/U_{inf} = " + num(du) + "'";
    }
    if (plots.empty()) {
      set.skipped.push_back("drag_vs_Re_per_du: no completed run");
    } else {
      p.commands() << "set xlabel 'Re'\nset ylabel 'F'\nset grid\nset key right top\nplot " << plots
                   << "\n";
      set.figures.push_back(p.with_runs(p.render()));
    }
  }
  {
    std::map<double, std::map<double, std::string>> by_phi;  // phi -> Re_inf -> rows
    for (const AggregationRow& a : agg)
      if (a.F_over_F0 && a.n_over_n0)
        by_phi[a.run->phi][a.run->re_inf] += num(a.n_over_n0->mean) + " " + num(a.F_over_F0->mean) +
                                             " " + num(a.n_over_n0->error.value_or(0)) + " " +
                                             num(a.F_over_F0->error.value_or(0)) + "\n";
    if (by_phi.empty()) {
      set.skipped.push_back("drag_ratio_vs_size_ratio: no aggregating run with a baseline");
    } else {
      Plot p(dir, "drag_ratio_vs_size_ratio",
             "Relative drag F/F0 against normalised aggregate size <n_a>/<n_a>0, a panel per phi, "
             "a symbol per Re_inf, error bars from the batch-means errors of both runs (Fig. 12)");
      p.commands() << "set multiplot layout 1," << by_phi.size()
                   << "\nset grid\nset xlabel '<n_a>/<n_a>_0'\nset ylabel 'F/F_0'\nset logscale x\n"
                   << "set key top right font ',9'\n";  // F/F0 falls with size: that corner is free
      for (const auto& [phi, per_re] : by_phi) {
        std::string plots;
        int style = 5;
        for (const auto& [re, rows] : per_re)
          plots += (plots.empty() ? "" : ", ") + p.data(label(phi, re), rows) +
                   " with xyerrorbars pt " + std::to_string(style++) +
                   " ps 1.3 title 'Re_{inf} = " + num(re) + "'";
        // The paper's comparison points at this phi: it states only their common
        // normalised size (no F/F0), so a vertical line there, and flocsim's runs
        // of the same (Re_inf, du) ringed, to show where they fall against it.
        const std::vector<StatedComparisonPoint> stated = stated_comparison_points(phi);
        std::string ringed, pairs;
        for (const StatedComparisonPoint& q : stated) {
          pairs += (pairs.empty() ? "(" : ", (") + num(q.re_inf) + ", " + num(q.du) + ")";
          for (const AggregationRow& a : agg)
            if (a.F_over_F0 && a.n_over_n0 && a.run->phi == phi && a.run->re_inf == q.re_inf &&
                std::abs(a.run->du - q.du) <= 1e-9 * q.du)
              ringed += num(a.n_over_n0->mean) + " " + num(a.F_over_F0->mean) + "\n";
        }
        std::string title = "phi = " + num(phi);
        if (!stated.empty()) {
          p.commands() << "set arrow 1 from " << num(stated.front().value) << ", graph 0 to "
                       << num(stated.front().value)
                       << ", graph 1 nohead dt 2 lw 1.5 lc rgb 'gray30'\n";
          plots += ", NaN with lines dt 2 lw 1.5 lc rgb 'gray30' title 'paper: about " +
                   num(stated.front().value) + "'";
          if (!ringed.empty())
            plots += ", " + p.data("phi" + num(phi) + "_stated", ringed) +
                     " with points pt 6 ps 3 lc rgb 'black' title 'flocsim at those points'";
          title += "\\n{/*0.75 the paper's points (Re_{inf}, du/U_{inf}): " + pairs + "}";
        }
        p.commands() << "set title \"" << title << "\"\nplot " << plots << "\n"
                     << "unset arrow 1\n";
      }
      for (const AggregationRow& a : agg)
        if (a.F_over_F0 && a.n_over_n0) {
          p.uses(a.run);
          p.uses(a.baseline);
        }
      p.commands() << "unset multiplot\n";
      const int width = 450 * static_cast<int>(by_phi.size()) + 150;
      set.figures.push_back(
          p.with_runs(p.render(std::to_string(width) + ",550", num(width / 150.0) + "in,3.7in")));
    }
  }
  return set;
}

}  // namespace flocsim::postprocess
