// flocsim sweep launch|resume|status|cancel: run a parameter grid through the
// results database (docs/orchestrator.md).
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "apps/flocsim/command_registry.hpp"
#include "db/results_db.hpp"
#include "engine/case/case_file.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/lattice_gpu/gpu_runtime.hpp"
#include "engine/process/stop_signal.hpp"
#include "orchestrator/local_pool.hpp"
#include "orchestrator/plan.hpp"
#include "orchestrator/process.hpp"
#include "orchestrator/report.hpp"
#include "orchestrator/slurm_backend.hpp"
#include "orchestrator/sweep.hpp"
#include "orchestrator/terminal_table.hpp"

namespace flocsim::app {
namespace {

namespace orc = flocsim::orchestrator;
using db::RunState;

struct SweepOptions {
  std::string sweep_file, db_path, runs_dir, backend = "local", worker, sweep_name;
  std::string device;  // --device: every worker's, overriding the cases' own
  int jobs = 1;
  double lease_s = 60;
  double grace_s = 120;
  bool no_wait = false;
  bool jobs_given = false;  // --jobs on the command line (the local pool's; Slurm has its own)
  int measure_steps = 3;
  double watch_s = 0;
  std::string plan_db;
  std::vector<std::string> gpu_rate_files;  // plan --gpu-rate
  // slurm-task (internal)
  std::string task_file;
};

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

int exit_code_for(db::ResultsDb& db, const db::SweepRecord& sweep, bool stopped) {
  if (stopped) return kExitInterrupted;
  for (const db::StateCount& c : db.count_states(sweep.id))
    if (c.status != RunState::kCompleted && c.runs > 0) return kExitFailure;
  return kExitOk;
}

void print_summary(const orc::PoolSummary& s, db::ResultsDb& db, const db::SweepRecord& sweep) {
  std::cout << "this session: started " << s.started << ", completed " << s.completed
            << ", recovered " << s.recovered << ", failed " << s.failed << ", refused " << s.refused
            << ", interrupted " << s.interrupted << ", lost " << s.lost << "\n";
  orc::write_status(db, sweep.name, std::cout);
  bool restartable = false;
  for (const db::StateCount& c : db.count_states(sweep.id))
    if ((c.status == RunState::kFailed || c.status == RunState::kLost ||
         c.status == RunState::kInterrupted) &&
        c.runs > 0)
      restartable = true;
  if (restartable)
    // quoted: the line is made to be pasted, and a name or path must stay text
    std::cout << "restart what did not finish with: flocsim sweep resume --db "
              << orc::shell_word(db.path()) << " --sweep " << orc::shell_word(sweep.name) << "\n";
}

db::SweepRecord pick_sweep(db::ResultsDb& db, const std::string& name) {
  if (!name.empty()) {
    auto s = db.find_sweep(name);
    if (!s) throw flocsim::input::InputError("--sweep " + name + ": no such sweep in " + db.path());
    return *s;
  }
  auto all = db.sweeps();
  if (all.size() == 1) return all.front();
  std::string known;
  for (const auto& s : all) known += (known.empty() ? "" : ", ") + s.name;
  throw flocsim::input::InputError(db.path() + " holds " + std::to_string(all.size()) +
                                   " sweeps; choose one with --sweep (" +
                                   (known.empty() ? "none" : known) + ")");
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

int run_sweep(const SweepOptions& o, db::ResultsDb& db, const db::SweepRecord& sweep,
              std::vector<RunState> states, const std::vector<std::string>& gpu_ids) {
  if (o.backend == "slurm") {
    orc::SlurmLaunch launch;
    launch.worker = o.worker.empty() ? default_worker() : o.worker;
    launch.flocsim = default_worker();
    if (std::getenv("FLOCSIM_SWEEP_EXE")) launch.flocsim = std::getenv("FLOCSIM_SWEEP_EXE");
    launch.states = states;
    launch.lease_s = o.lease_s;
    launch.wait = !o.no_wait;
    launch.device = o.device;
    launch.out = &std::cout;
    process::install_stop_handlers(process::SecondSignal::is_counted);
    const orc::SlurmSummary s = orc::run_slurm(db, sweep, launch);
    if (!launch.wait) return kExitOk;
    orc::write_status(db, sweep.name, std::cout);
    return exit_code_for(db, sweep, s.stopped);
  }
  orc::PoolOptions p;
  p.worker = o.worker.empty() ? default_worker() : o.worker;
  p.jobs = o.jobs;
  p.states = std::move(states);
  p.lease_s = o.lease_s;
  p.grace_s = o.grace_s;
  p.device = o.device;
  p.gpus = std::max(1, static_cast<int>(gpu_ids.size()));
  p.gpu_ids = gpu_ids;
  p.out = &std::cout;
  process::install_stop_handlers(process::SecondSignal::is_counted);
  const orc::PoolSummary s = orc::run_pool(db, sweep, p);
  print_summary(s, db, sweep);
  return exit_code_for(db, sweep, s.stopped);
}

// `status --watch`: the status again every `every_s` seconds, in place on a
// terminal (one frame after another otherwise), until nothing of the sweep
// runs (two frames in a row), or Ctrl-C.
int watch_status(db::ResultsDb& db, bool writable, const std::optional<std::string>& sweep,
                 double every_s, double lease_s) {
  process::install_stop_handlers(process::SecondSignal::ends_the_process);
  const bool terminal = isatty(STDOUT_FILENO) != 0;
  int idle = 0;
  while (true) {
    std::ostringstream frame;
    if (writable) orc::reconcile_lost_workers(db, lease_s, &frame);
    const bool active = orc::write_status(db, sweep, frame);
    const std::time_t now = std::time(nullptr);
    char clock[32];
    std::strftime(clock, sizeof clock, "%H:%M:%S", std::localtime(&now));
    std::cout << (terminal ? "\033[H\033[2J" : "\n") << "flocsim sweep status at " << clock
              << ", every " << every_s << " s (Ctrl-C stops watching; the sweep goes on)\n"
              << frame.str() << std::flush;
    // two frames without a running run: not the moment between two runs
    idle = active ? 0 : idle + 1;
    if (idle >= 2) {
      std::cout << "nothing is running: stopped watching\n";
      return kExitOk;
    }
    for (double slept = 0; slept < every_s; slept += 0.1) {
      if (process::stop_requested()) return kExitOk;
      usleep(100000);
    }
  }
}

void common_run_options(CLI::App& cmd, SweepOptions& o) {
  cmd.add_option("--jobs,-j", o.jobs, "Worker processes at once (local backend)")
      ->check(CLI::Range(1, 4096))
      ->capture_default_str()
      ->each([&o](const std::string&) { o.jobs_given = true; });
  cmd.add_option("--backend", o.backend, "Where workers run")
      ->check(CLI::IsMember({"local", "slurm"}))
      ->capture_default_str();
  cmd.add_option("--lease", o.lease_s,
                 "Seconds without a heartbeat (progress.json) after which a worker is lost")
      ->check(finite_number(5.0, 1e6))
      ->capture_default_str();
  cmd.add_option("--grace", o.grace_s,
                 "Seconds a stopping worker may take to write its checkpoint before it is killed")
      ->check(finite_number(1.0, 1e6))
      ->capture_default_str();
  cmd.add_option("--worker", o.worker,
                 "Program run as `WORKER run CASE --out DIR` (default: this flocsim, or "
                 "$FLOCSIM_WORKER)");
  cmd.add_flag("--no-wait", o.no_wait, "Slurm: submit and return without following the jobs");
  cmd.add_option("--device", o.device,
                 "Where every worker's lattice steps, cpu or cuda (default: each case's "
                 "\"device\"); cuda gives each worker its own GPU while there are enough")
      ->check(CLI::IsMember({"cpu", "cuda"}));
}

const bool registered = register_command(
    {"sweep", "Launch, resume, follow or cancel a parameter sweep", [](CLI::App& cmd) {
       auto o = std::make_shared<SweepOptions>();
       auto action = std::make_shared<std::string>();
       cmd.require_subcommand(1);

       CLI::App* plan = cmd.add_subcommand(
           "plan",
           "What SWEEP.json will cost before it starts: every run's box, N, steps, lattice "
           "updates, memory and wall time, and the points that would be refused");
       plan->add_option("sweep", o->sweep_file, "Sweep file (JSON)")->required();
       plan->add_option("--jobs,-j", o->jobs, "Worker processes at once (local backend)")
           ->check(CLI::Range(1, 4096))
           ->capture_default_str();
       plan->add_option("--backend", o->backend, "Where workers would run")
           ->check(CLI::IsMember({"local", "slurm"}))
           ->capture_default_str();
       plan->add_option("--db", o->plan_db,
                        "A results database: completed runs of the same configuration give the "
                        "rate, and runs already complete there are not counted");
       plan->add_option("--measure-steps", o->measure_steps,
                        "Time steps of each configuration measured here (0: none)")
           ->check(CLI::Range(0, 1000))
           ->capture_default_str();
       plan->add_option("--gpu-rate", o->gpu_rate_files,
                        "Estimate on a GPU: the JSON files bench_fluid_gpu and bench_coupling_gpu "
                        "wrote there (scripts/device-check.sh writes both); configurations the "
                        "GPU cannot run are measured here as usual")
           ->expected(1, 2);
       plan->callback([action] { *action = "plan"; });

       CLI::App* launch = cmd.add_subcommand(
           "launch", "Expand SWEEP.json into runs, record them in the database and run them");
       launch->add_option("sweep", o->sweep_file, "Sweep file (JSON)")->required();
       launch->add_option("--db", o->db_path, "Results database (created when missing)")
           ->required();
       launch->add_option("--runs-dir", o->runs_dir,
                          "Folder of the run directories (default: DB name with .runs)");
       common_run_options(*launch, *o);
       launch->callback([action] { *action = "launch"; });

       CLI::App* resume = cmd.add_subcommand(
           "resume", "Restart failed, lost and interrupted runs (from their checkpoints)");
       resume->add_option("--db", o->db_path, "Results database")->required();
       resume->add_option("--sweep", o->sweep_name,
                          "Sweep name (needed when the database has several)");
       common_run_options(*resume, *o);
       resume->callback([action] { *action = "resume"; });

       CLI::App* status = cmd.add_subcommand("status", "Runs by state, progress, ETA, failures");
       status->add_option("--db", o->db_path, "Results database")->required();
       status->add_option("--sweep", o->sweep_name, "Only this sweep");
       status->add_option("--lease", o->lease_s, "Heartbeat lease for remote workers (s)")
           ->check(finite_number(5.0, 1e6));
       status
           ->add_option("--watch", o->watch_s,
                        "Refresh every SECONDS, in place, until nothing runs")
           ->check(finite_number(0.5, 86400.0));
       status->callback([action] { *action = "status"; });

       CLI::App* cancel = cmd.add_subcommand(
           "cancel", "Stop the running orchestrators and Slurm jobs of the database gracefully");
       cancel->add_option("--db", o->db_path, "Results database")->required();
       cancel->callback([action] { *action = "cancel"; });

       CLI::App* task = cmd.add_subcommand("slurm-task", "Internal: one Slurm array task");
       task->group("");  // hidden from --help
       task->add_option("--db", o->db_path)->required();
       task->add_option("--sweep", o->sweep_name)->required();
       task->add_option("--task-file", o->task_file)->required();
       task->add_option("--worker", o->worker)->required();
       task->add_option("--lease", o->lease_s)->check(finite_number(5.0, 1e6));
       task->callback([action] { *action = "slurm-task"; });

       return CommandHandler([o, action]() -> int {
         try {
           if (*action == "plan") {
             const orc::SweepSpec spec = orc::read_sweep_file(o->sweep_file);
             std::unique_ptr<db::ResultsDb> db;
             if (!o->plan_db.empty())
               db = std::make_unique<db::ResultsDb>(o->plan_db, db::ResultsDb::Mode::kReadOnly);
             std::optional<orc::GpuRates> gpu;
             if (!o->gpu_rate_files.empty()) gpu = orc::read_gpu_rates(o->gpu_rate_files);
             orc::PlanOptions p;
             p.jobs = o->jobs;
             p.backend = o->backend;
             p.measure_steps = o->measure_steps;
             p.db = db.get();
             p.gpu = gpu ? &*gpu : nullptr;
             p.progress = &std::cerr;
             orc::write_plan(orc::plan_sweep(spec, p), std::cout, true);
             return kExitOk;
           }
           if (*action == "launch") {
             refuse_options_of_the_other_backend(*o);
             const orc::SweepSpec spec = orc::read_sweep_file(o->sweep_file);
             // a grid refused here leaves no database file behind
             const std::vector<orc::RunPoint> points = orc::expand(spec);
             // another --worker reads its cases its own way: only flocsim's are checked
             const bool flocsim_cases = reads_flocsim_cases(*o);
             if (flocsim_cases && o->backend == "local")
               refuse_an_unrunnable_grid(points, o->device);
             const std::vector<std::string> gpus = check_device(*o, points, flocsim_cases);
             check_worker(o->worker);
             const std::string runs_dir =
                 o->runs_dir.empty() ? orc::default_runs_dir(o->db_path) : o->runs_dir;
             const auto made = make_runs_dir(runs_dir, !o->runs_dir.empty());
             std::unique_ptr<db::ResultsDb> opened;
             try {
               opened = open_db(o->db_path, db::ResultsDb::Mode::kCreate);
               // a grid changed under its name: refused before the plan times anything
               orc::refuse_changed_grid(*opened, spec);
             } catch (...) {
               unmake_runs_dir(made);
               throw;
             }
             db::ResultsDb& db = *opened;
             if (flocsim_cases) {
               // what it will cost, on one screen, before anything starts (asks
               // nothing); another --worker reads its cases its own way
               orc::PlanOptions p;
               p.jobs = o->jobs;
               p.backend = o->backend;
               p.db = &db;
               orc::write_plan(orc::plan_sweep(spec, p), std::cout, false);
               std::cout << std::flush;
             }
             orc::reconcile_lost_workers(db, o->lease_s, &std::cout);
             const orc::Registered reg = orc::register_sweep(db, spec, runs_dir);
             std::cout << "sweep " << orc::printable(spec.name) << ": " << reg.runs << " runs ("
                       << reg.added.added << " new, " << reg.added.reused << " already in "
                       << orc::printable(o->db_path) << "); run folders under "
                       << orc::printable(std::filesystem::absolute(runs_dir).string()) << "\n";
             return run_sweep(*o, db, reg.sweep,
                              {RunState::kPending, RunState::kInterrupted, RunState::kLost}, gpus);
           }
           if (*action == "resume") {
             refuse_options_of_the_other_backend(*o);
             check_worker(o->worker);
             const auto opened = open_db(o->db_path, db::ResultsDb::Mode::kExisting);
             db::ResultsDb& db = *opened;
             orc::reconcile_lost_workers(db, o->lease_s, &std::cout);
             const db::SweepRecord sweep = pick_sweep(db, o->sweep_name);
             const bool flocsim_cases = reads_flocsim_cases(*o);
             std::vector<orc::RunPoint> points;
             if (!o->device.empty() || flocsim_cases)
               for (const db::RunRecord& r : db.runs(sweep.id))
                 points.push_back({r.id, nlohmann::json::parse(r.case_json),
                                   r.point_json.empty()
                                       ? nlohmann::ordered_json::object()
                                       : nlohmann::ordered_json::parse(r.point_json)});
             const std::vector<std::string> gpus = check_device(*o, points, flocsim_cases);
             return run_sweep(
                 *o, db, sweep,
                 {RunState::kPending, RunState::kInterrupted, RunState::kLost, RunState::kFailed},
                 gpus);
           }
           if (*action == "status") {
             // status only reads, but where it may write it also marks workers
             // found dead as lost; a read-only database is read as it is
             std::unique_ptr<db::ResultsDb> opened;
             bool writable = true;
             try {
               opened = std::make_unique<db::ResultsDb>(o->db_path, db::ResultsDb::Mode::kExisting);
               orc::reconcile_lost_workers(*opened, o->lease_s, &std::cout);
             } catch (const db::ReadOnlyDbError& e) {
               writable = false;
               opened = std::make_unique<db::ResultsDb>(o->db_path, db::ResultsDb::Mode::kReadOnly);
               std::cout << orc::printable(o->db_path)
                         << (dynamic_cast<const db::DiskFullDbError*>(&e)
                                 ? ": the file system under it is full (free some space)"
                                 : " is read-only")
                         << ": shown as recorded (workers that died are not marked lost)\n";
             }
             db::ResultsDb& db = *opened;
             const std::optional<std::string> which =
                 o->sweep_name.empty() ? std::nullopt : std::optional<std::string>(o->sweep_name);
             if (o->watch_s <= 0) {
               orc::write_status(db, which, std::cout);
               return kExitOk;
             }
             return watch_status(db, writable, which, o->watch_s, o->lease_s);
           }
           if (*action == "cancel") {
             // cancel only reads the live attempts and signals their owners (or
             // scancels their jobs): a read-only database is read as it is
             std::unique_ptr<db::ResultsDb> opened;
             try {
               opened = std::make_unique<db::ResultsDb>(o->db_path, db::ResultsDb::Mode::kExisting);
             } catch (const db::ReadOnlyDbError&) {
               opened = std::make_unique<db::ResultsDb>(o->db_path, db::ResultsDb::Mode::kReadOnly);
             }
             return orc::cancel_all(*opened, std::cout) >= 0 ? kExitOk : kExitFailure;
           }
           if (*action == "slurm-task") {
             db::ResultsDb db(o->db_path, db::ResultsDb::Mode::kExisting);
             const db::SweepRecord sweep = pick_sweep(db, o->sweep_name);
             process::install_stop_handlers(process::SecondSignal::is_counted);
             return orc::run_slurm_task(db, sweep, o->task_file, o->worker, o->lease_s, std::cout);
           }
         } catch (const flocsim::input::InputError& e) {
           std::cerr << "flocsim sweep: " << printable(e.what()) << "\n";
           return kExitBadInput;
         } catch (const db::DbError& e) {
           std::cerr << "flocsim sweep: " << printable(e.what()) << "\n";
           return kExitFailure;
         } catch (const std::runtime_error& e) {
           // the place failing (make_runs_dir: a read-only or full file system)
           std::cerr << "flocsim sweep: " << printable(e.what()) << "\n";
           return kExitFailure;
         }
         return kExitBadInput;
       });
     }});

}  // namespace
}  // namespace flocsim::app
