#pragma once
// The paper's figures from the runs of a results database, drawn by gnuplot:
// PNG for the screen and PDF for papers, with the data and the gnuplot script
// of each figure kept beside it (DIR/data, DIR/scripts) so that a figure can be
// restyled without flocsim. Time series, distributions and phi(x, t) come from
// each run's series.h5; a figure whose data do not exist is skipped with the
// reason.
#include <filesystem>
#include <string>
#include <vector>

#include "postprocess/tables.hpp"

namespace flocsim::postprocess {

struct Figure {
  std::string name;     // file stem, e.g. "drag_vs_Re"
  std::string caption;  // what it shows, as in the paper
  std::filesystem::path png, pdf;
  std::vector<std::string> runs;  // ids of the runs whose data it draws
};

struct FigureSet {
  std::vector<Figure> figures;
  std::vector<std::string> skipped;  // "name: reason"
  // Completed runs left out of the figures drawn from series.h5: the run, the
  // file, the reason and the figures it is missing from.
  std::vector<std::string> runs_left_out;
};

// Why no figure can be drawn here (gnuplot is not on PATH), empty when they can.
std::string why_no_figures();

// Writes every figure the runs have data for into `dir`; without gnuplot none,
// with the reason in `skipped`. gnuplot runs without a shell, in `dir`, on the
// scripts it keeps there. Throws std::runtime_error naming the figure when
// gnuplot fails.
FigureSet write_figures(const std::vector<RunSummary>& runs, const std::filesystem::path& dir);

}  // namespace flocsim::postprocess
