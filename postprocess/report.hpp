#pragma once
// One self-contained HTML page: the aggregation and non-aggregating tables,
// every figure (PNG embedded as base64, so the page travels as one file), and
// each run's provenance (code version, fidelity, numerics, window, reliability
// of the errors, stationarity, wall time, state).
#include <filesystem>
#include <string>
#include <vector>

#include "postprocess/figures.hpp"
#include "postprocess/tables.hpp"

namespace flocsim::postprocess {

// `left_out`: the database rows that cannot be read, one line each.
void write_report(const std::vector<RunSummary>& runs, const FigureSet& figures,
                  const std::string& database, const std::filesystem::path& file,
                  const std::vector<std::string>& left_out = {});

}  // namespace flocsim::postprocess
