#pragma once
// The table files `flocsim calibrate` extends: checked before any work (a
// calibration runs for minutes to hours), then extended one entry at a time
// under a lock, from the file as it is at that moment, so that calibrations
// running at once into one table keep every entry.
#include <string>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/calibration/pair_resistance.hpp"

namespace flocsim::calibration {

enum class TableKind { hydrodynamic_radius, close_pair };

// Throws input::InputError naming the file and what is wrong unless a table of
// `kind` can be written at `path`: not a folder; an existing file must be a
// readable table of this kind (a table of the other kind is named as such);
// its folder must exist and take new files (the system's reason otherwise, a
// read-only file system say).
void check_table_file(const std::string& path, TableKind kind);

// Adds the entry to the table at `path` (made when missing) under the file's
// lock (output::FileLock): reads the table as it is now, adds, replaces the
// file atomically. `note` says how the table was made.
void add_to_table_file(const std::string& path, const CalibrationEntry& entry,
                       const std::string& note);
void add_to_table_file(const std::string& path, const PairResistanceEntry& entry,
                       const std::string& note);

}  // namespace flocsim::calibration
