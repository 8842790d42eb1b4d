#pragma once
// Sweep files and their expansion into runs.
//
// A sweep file is a JSON object:
//   {
//     "name": "demo",                       identifies the sweep in the database
//     "description": "...",                 optional
//     "base": { ...a case... },             the case every run starts from
//     "axes": { "fluid.viscosity": [0.01, 0.02], "phi": [0.12, 0.2] },
//     "fidelity": "paper",                  optional: written to the case field "fidelity"
//     "max_attempts": 3,                    optional retry limit (failed attempts per run)
//     "slurm": { "runs_per_task": 4, "time_limit": "01:00:00", "partition": "debug",
//                "max_parallel": 8, "cpus_per_task": 1 }      optional, --backend slurm only
//   }
// Axes are dotted paths into the case; the grid is their Cartesian product,
// the first axis varying slowest. A run is identified by the SHA-256 of its
// canonical case (sorted keys, normalised numbers), so two sweeps (or a grown
// grid) that produce the same case share one run.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace flocsim::orchestrator {

// The case with object keys sorted (nlohmann::json keeps them sorted) and
// numbers normalised: an integral value that a double holds exactly becomes an
// integer (2000, 2000.0 and 2e3 are one number), -0 becomes 0, every other
// number is a double printed in its shortest round-trip form (0.2 == 0.20).
nlohmann::json canonical(const nlohmann::json& value);
std::string canonical_text(const nlohmann::json& value);
std::string sha256_hex(std::string_view bytes);
// SHA-256 (hex) of canonical_text(case).
std::string case_id(const nlohmann::json& case_json);

// The value at a dotted path ("fluid.viscosity"); empty when absent.
std::optional<nlohmann::json> get_path(const nlohmann::json& object, const std::string& path);

struct Axis {
  std::string path;
  std::vector<nlohmann::json> values;
};

struct SlurmOptions {
  int runs_per_task = 1;
  std::string time_limit = "01:00:00";
  std::string partition;
  int max_parallel = 0;  // array throttle (%k); 0 = no throttle
  int cpus_per_task = 1;
  // generic resources per task (sbatch --gres); empty: "gpu:1" when the
  // sweep runs on cuda, none otherwise
  std::string gres;
};

struct SweepSpec {
  std::string name, description;
  nlohmann::json base;
  std::vector<Axis> axes;
  std::optional<std::string> fidelity;
  int max_attempts = 3;
  SlurmOptions slurm;
  nlohmann::json source;  // the file as read
};

struct RunPoint {
  std::string id;                // case_id(case_json)
  nlohmann::json case_json;      // canonical
  nlohmann::ordered_json point;  // axis path -> value, in axis order
};

// Parses and checks a sweep; errors (flocsim::input::InputError) name the
// file, the field, the value and what is allowed.
SweepSpec parse_sweep(const nlohmann::ordered_json& file, const std::string& origin);
SweepSpec read_sweep_file(const std::string& filename);
// The runs of the grid, in grid order; duplicates (axes that produce the
// same case) are an error.
std::vector<RunPoint> expand(const SweepSpec& sweep);

inline constexpr std::size_t kMaxRunsPerSweep = 100000;

// A grid point as a user reads it: "Re_inf=6 du_over_Uinf=0.03" (its JSON text
// when it is not an object).
std::string point_text(const std::string& point_json);

// `word` as one word of a POSIX shell command a user may paste (the commands
// flocsim suggests): as it is when it holds only letters, digits and
// - _ . / : , + = @, single-quoted otherwise, so that no name or path runs as
// a command ("$(touch X)" stays text). A word holding characters a terminal
// obeys (ESC, U+202E, a newline; text::printable) or bytes that are not UTF-8
// is written as $'...' with those bytes as \xNN: shown as what it is, and the
// same bytes when pasted into bash, zsh or ksh.
std::string shell_word(const std::string& word);

}  // namespace flocsim::orchestrator
