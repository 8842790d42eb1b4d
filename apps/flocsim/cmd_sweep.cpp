// flocsim sweep plan|launch|resume|status|cancel: run a parameter grid through
// the results database (docs/orchestrator.md). What launch and resume check
// before anything is recorded or started is in sweep_checks.hpp.
#include <algorithm>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "apps/flocsim/command_registry.hpp"
#include "apps/flocsim/sweep_checks.hpp"
#include "apps/flocsim/sweep_options.hpp"
#include "db/results_db.hpp"
#include "engine/input/input_reader.hpp"
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
