#include "apps/flocsim/sweep_checks.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "engine/case/case_file.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/lattice_gpu/gpu_runtime.hpp"
#include "orchestrator/local_pool.hpp"
#include "orchestrator/process.hpp"

namespace flocsim::app {

namespace orc = flocsim::orchestrator;

std::string default_worker() {
  if (const char* env = std::getenv("FLOCSIM_WORKER"); env && *env) return env;
  std::error_code ec;
  auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) return self.string();
  throw flocsim::input::InputError(
      "cannot find the flocsim executable to run as the worker; give --worker PATH");
}

// Refuses a --worker (or $FLOCSIM_WORKER) that cannot be started, before any
// run is claimed: a missing one failed every run with exit 127, naming no
// path, and each failure used up one of the run's attempts.
void check_worker(const std::string& given) {
  // the worker the runs would get: --worker, else $FLOCSIM_WORKER, else this flocsim
  const char* env = std::getenv("FLOCSIM_WORKER");
  const std::string worker = !given.empty() ? given : env && *env ? env : "";
  if (worker.empty()) return;  // this flocsim
  const std::string option = !given.empty() ? "--worker " : "FLOCSIM_WORKER=";
  std::string found;
  if (worker.find('/') != std::string::npos) {
    found = worker;
  } else {
    const char* path = std::getenv("PATH");
    std::istringstream dirs(path ? path : "/bin:/usr/bin");
    for (std::string d; std::getline(dirs, d, ':') && found.empty();) {
      const std::filesystem::path p = std::filesystem::path(d.empty() ? "." : d) / worker;
      if (access(p.c_str(), X_OK) == 0 && !std::filesystem::is_directory(p)) found = p.string();
    }
    if (found.empty())
      throw flocsim::input::InputError(option + worker + ": not found on PATH (" +
                                       (path ? path : "unset") +
                                       "); give the worker program's path");
  }
  std::error_code ec;
  if (!std::filesystem::exists(found, ec))
    throw flocsim::input::InputError(option + worker + ": no such file" +
                                     (ec ? " (" + ec.message() + ")" : std::string()) +
                                     "; give the path of a program run as `WORKER run CASE "
                                     "--out DIR` (default: this flocsim)");
  if (std::filesystem::is_directory(found, ec))
    throw flocsim::input::InputError(option + worker +
                                     ": is a directory; give the worker program's path");
  if (access(found.c_str(), X_OK) != 0)
    throw flocsim::input::InputError(option + worker + ": cannot be run (" + std::strerror(errno) +
                                     "); allowed: an executable file");
}

// --device cuda is checked before anything is recorded or started: the build
// and (local backend) this machine must have a GPU, and every point of the
// grid that runs at all must be a case that runs on one. Without --device, a
// grid some of whose cases ask for "device": "cuda" themselves (flocsim's
// cases) needs the GPU the same way; where all of them do it runs as with
// --device cuda (a GPU per worker, or per Slurm task), and where only some do
// (a device axis: the CPU against the GPU) each worker follows its case.
// Returns what CUDA_VISIBLE_DEVICES
// names each GPU the local pool spreads its workers over by (none on the
// CPU; on Slurm, which gives each task its own GPU, they go unused).
std::vector<std::string> check_device(SweepOptions& o, const std::vector<orc::RunPoint>& points,
                                      bool flocsim_cases) {
  const bool given = !o.device.empty();
  int on_cuda = 0;
  if (!given && flocsim_cases)
    for (const orc::RunPoint& p : points)
      on_cuda += p.case_json.is_object() && p.case_json.contains("device") &&
                 p.case_json["device"] == "cuda";
  if (!given && on_cuda > 0 && on_cuda == static_cast<int>(points.size())) o.device = "cuda";
  if (o.device != "cuda" && on_cuda == 0) return {};
  const std::string asked = given ? "--device cuda" : "the grid's cases ask for device = \"cuda\"";
  const gpu::GpuQuery q = gpu::query_gpus();
  if (!gpu::built_with_cuda() || (o.backend == "local" && q.devices.empty()))
    throw flocsim::input::InputError(asked + ": " + q.why_none +
                                     "; run on the CPU with --device cpu");
  for (const orc::RunPoint& p : points) {
    nlohmann::json c = p.case_json;
    // with no --device, a point left on the CPU by its own case is the CPU's
    if (o.device != "cuda" && !(c.is_object() && c.contains("device") && c["device"] == "cuda"))
      continue;
    // a point refused on every device (below a stability floor, say) is the
    // sweep's business as without --device: its worker records the refusal.
    // Only what cuda alone cannot run stops the launch here.
    c["device"] = "cpu";
    try {
      cases::parse_case(c);
    } catch (const flocsim::input::InputError&) {
      continue;
    }
    c["device"] = "cuda";
    try {
      cases::parse_case(c);
    } catch (const flocsim::input::InputError& e) {
      throw flocsim::input::InputError(asked + ": grid point " + p.point.dump() + ": " + e.what());
    }
  }
  std::vector<int> indices;
  for (const gpu::GpuDevice& d : q.devices) indices.push_back(d.index);
  gpu::release_gpus();  // the workers take them; this process runs nothing there
  return orc::visible_gpu_ids(std::getenv("CUDA_VISIBLE_DEVICES"), indices);
}

// Whether the workers are this flocsim, reading flocsim's cases: another
// --worker (or $FLOCSIM_WORKER) reads its cases its own way, so neither the
// plan nor the checks of a case apply to them.
bool reads_flocsim_cases(const SweepOptions& o) {
  return o.worker.empty() && !std::getenv("FLOCSIM_WORKER");
}

// A grid whose every point `flocsim run` would refuse (a misspelt axis, a
// preset that does not exist) would be recorded, its workers refused, and its
// name kept for that grid: refused here instead, before anything is recorded,
// with the first point's reason. Points refused beside runnable ones are the
// sweep's business (its plan lists them; their workers record the refusal).
// Asked on the local backend only: a case is also checked against this
// machine's memory, and a Slurm sweep's login node is not where it runs.
void refuse_an_unrunnable_grid(const std::vector<orc::RunPoint>& points,
                               const std::string& device) {
  std::string first;
  for (const orc::RunPoint& p : points) {
    try {
      nlohmann::json c = p.case_json;
      if (!device.empty() && c.is_object()) c["device"] = device;  // as the workers will get it
      cases::parse_case(c);
      return;
    } catch (const flocsim::input::InputError& e) {
      if (first.empty()) first = "grid point " + p.point.dump() + ": " + e.what();
    }
  }
  if (!points.empty())
    throw flocsim::input::InputError(
        "every point of the grid is refused, as `flocsim run` would "
        "refuse it; the first: " +
        first);
}

// The folder the run folders go under: made now, or refused (exit 2) before
// the database is made, so that no run is recorded with a folder it cannot have.
// Returns the folders it made, deepest first (for unmake_runs_dir).
std::vector<std::filesystem::path> make_runs_dir(const std::string& dir, bool given) {
  namespace fs = std::filesystem;
  std::vector<fs::path> made;
  std::error_code ec;
  for (fs::path p = fs::absolute(dir, ec).lexically_normal(); !ec && p.has_relative_path();
       p = p.parent_path()) {
    if (p.filename().empty()) continue;  // a trailing separator
    std::error_code absent;
    if (fs::exists(p, absent) || absent) break;
    made.push_back(p);
  }
  ec.clear();
  const std::string what = given ? "--runs-dir " + dir : "the run folders' " + dir + " (from --db)";
  if (fs::exists(fs::symlink_status(dir, ec)) && !fs::is_directory(dir, ec))
    throw flocsim::input::InputError(what + ": exists and is not a folder; give a folder");
  fs::create_directories(dir, ec);
  int err = ec ? ec.value() : 0;
  if (!err && !fs::is_directory(dir)) err = ENOTDIR;
  if (!err && ::access(dir.c_str(), W_OK | X_OK) != 0) err = errno;
  if (err) {
    const std::string text = what + ": cannot make or write a folder there (" + std::strerror(err) +
                             "); give a writable folder";
    // a read-only or full file system, or one refused to this user, is the
    // place failing (exit 1, as for the database); anything else is the path
    if (err == EROFS || err == ENOSPC || err == EDQUOT || err == EACCES || err == EPERM)
      throw std::runtime_error(text);
    throw flocsim::input::InputError(text);
  }
  return made;
}

// Takes back what make_runs_dir made for a launch refused after it: each
// folder only while it is still empty.
void unmake_runs_dir(const std::vector<std::filesystem::path>& made) {
  std::error_code ec;
  for (const auto& p : made)
    if (std::filesystem::is_empty(p, ec) && !ec) std::filesystem::remove(p, ec);
}

// The database, with a path that cannot be one (a folder, a device, a file
// that is not SQLite or not flocsim's) refused as the input error it is (exit
// 2). Where the place fails (read-only, full, locked, a network file system
// without WAL) it stays a failure (exit 1).
std::unique_ptr<db::ResultsDb> open_db(const std::string& path, db::ResultsDb::Mode mode) {
  try {
    return std::make_unique<db::ResultsDb>(path, mode);
  } catch (const db::NotADatabaseError& e) {
    throw flocsim::input::InputError(e.what());  // it names --db and the file
  }
}

// Options that one backend would silently ignore are refused: --no-wait is
// Slurm's (the local pool follows its workers itself), --jobs the local
// pool's (Slurm runs the array's tasks as its queue allows; slurm.max_parallel
// throttles them).
void refuse_options_of_the_other_backend(const SweepOptions& o) {
  if (o.no_wait && o.backend != "slurm")
    throw flocsim::input::InputError(
        "--no-wait: only with --backend slurm (the local pool follows its workers until they end; "
        "stop it with Ctrl-C and continue with `flocsim sweep resume`)");
  if (o.jobs_given && o.backend == "slurm")
    throw flocsim::input::InputError(
        "--jobs " + std::to_string(o.jobs) +
        ": only for the local backend; Slurm runs the array's tasks as its queue allows (limit "
        "them with the sweep file's slurm.max_parallel)");
}

}  // namespace flocsim::app
