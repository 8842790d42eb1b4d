#include "engine/calibration/table_file.hpp"

#include <stdlib.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "engine/input/input_reader.hpp"
#include "engine/output/atomic_file.hpp"
#include "engine/output/file_lock.hpp"

namespace flocsim::calibration {

namespace fs = std::filesystem;
using input::InputError;
using nlohmann::json;

namespace {

const char* what_writes(TableKind kind) {
  return kind == TableKind::hydrodynamic_radius
             ? "a hydrodynamic-radius table (entries of input_radius, written by `flocsim "
               "calibrate`)"
             : "a close-pair table (entries of points and box_offset, written by `flocsim "
               "calibrate --close-pairs`)";
}

// An existing table file: readable, JSON, a table of this kind, every entry
// readable by the table's own reader.
void check_contents(const std::string& path, TableKind kind) {
  const std::string name = "--table " + path;
  std::ifstream in(path);
  if (!in) throw InputError(name + ": cannot be read (" + std::strerror(errno) + ")");
  std::stringstream text;
  text << in.rdbuf();
  json j;
  try {
    j = json::parse(text.str());
  } catch (const json::parse_error& e) {
    throw InputError(name + ": not a calibration table: not JSON (" +
                     (text.str().empty() ? std::string("an empty file")
                                         : "bad syntax at byte " + std::to_string(e.byte)) +
                     ")");
  }
  if (!j.is_object() || !j.contains("entries") || !j["entries"].is_array())
    throw InputError(name + ": not a calibration table (a JSON object with a list \"entries\")");
  for (const json& e : j["entries"]) {
    if (!e.is_object()) continue;  // the reader below names it
    const bool radius = e.contains("input_radius");
    const bool pairs = e.contains("points") || e.contains("box_offset");
    const TableKind other = kind == TableKind::hydrodynamic_radius ? TableKind::close_pair
                                                                   : TableKind::hydrodynamic_radius;
    if ((kind == TableKind::hydrodynamic_radius && pairs && !radius) ||
        (kind == TableKind::close_pair && radius && !pairs))
      throw InputError(name + ": is " + what_writes(other) + "; this calibration writes " +
                       what_writes(kind) + ". Name another file" +
                       (kind == TableKind::close_pair ? ", or leave out --close-pairs"
                                                      : ", or add --close-pairs"));
  }
  try {
    if (kind == TableKind::hydrodynamic_radius)
      CalibrationTable::parse(text.str(), path);
    else
      PairResistanceTable::parse(text.str(), path);
  } catch (const std::exception& e) {
    throw InputError(
        name + ": not a readable " +
        (kind == TableKind::hydrodynamic_radius ? "hydrodynamic-radius" : "close-pair") +
        " table: " + e.what());
  }
}

template <class Table, class Entry>
void add_locked(const std::string& path, const Entry& entry, const std::string& note) {
  const output::FileLock lock(path);  // a calibration writing at the same time waits here
  Table table;
  if (fs::exists(path)) table = Table::load(path);  // with what others added since we started
  table.note = note;
  table.add(entry);
  output::TemporaryFile file(path);
  table.save(file.path().string());
  file.commit();
}

}  // namespace

void check_table_file(const std::string& path, TableKind kind) {
  if (path.empty()) throw InputError("--table \"\": must name the table's file");
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (fs::is_directory(st))
    throw InputError("--table " + path + ": is a folder; name the table's file in it, e.g. " +
                     (fs::path(path) / "table.json").string());
  if (fs::exists(st)) {
    if (!fs::is_regular_file(st)) throw InputError("--table " + path + ": is not a regular file");
    check_contents(path, kind);
  }
  // The table is replaced through a new file in its folder (and locked through
  // another): the folder must take new files now, not after the calibration.
  const fs::path folder = fs::path(path).has_parent_path() ? fs::path(path).parent_path() : ".";
  std::string probe = (folder / ".flocsim-calibrate-check.XXXXXX").string();
  const int fd = ::mkstemp(probe.data());
  if (fd < 0)
    throw InputError("--table " + path + ": cannot be written: its folder " + folder.string() +
                     " does not take new files (" + std::strerror(errno) +
                     "); checked before the calibration starts");
  ::close(fd);
  ::unlink(probe.c_str());
}

void add_to_table_file(const std::string& path, const CalibrationEntry& entry,
                       const std::string& note) {
  add_locked<CalibrationTable>(path, entry, note);
}

void add_to_table_file(const std::string& path, const PairResistanceEntry& entry,
                       const std::string& note) {
  add_locked<PairResistanceTable>(path, entry, note);
}

}  // namespace flocsim::calibration
