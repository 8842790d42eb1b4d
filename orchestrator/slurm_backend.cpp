#include "orchestrator/slurm_backend.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "engine/input/input_reader.hpp"
#include "engine/process/exit_codes.hpp"
#include "engine/process/stop_signal.hpp"
#include "orchestrator/local_pool.hpp"
#include "orchestrator/process.hpp"

namespace flocsim::orchestrator {

namespace fs = std::filesystem;
using db::RunState;

namespace {

// Runs a program (looked up in PATH), capturing stdout and stderr; returns its
// exit code, or -1 when it could not be run.
int run_program(const std::vector<std::string>& argv, std::string* output) {
  int pipe_fd[2];
  if (pipe2(pipe_fd, O_CLOEXEC) != 0) return -1;  // daemons must not inherit it
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    dup2(pipe_fd[1], 1);
    dup2(pipe_fd[1], 2);
    close(pipe_fd[0]);
    close(pipe_fd[1]);
    execvp(args[0], args.data());
    _exit(127);
  }
  close(pipe_fd[1]);
  std::string text;
  char buf[4096];
  ssize_t n;
  while ((n = read(pipe_fd[0], buf, sizeof buf)) > 0) text.append(buf, static_cast<std::size_t>(n));
  close(pipe_fd[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (output) *output = text;
  if (!WIFEXITED(status)) return -1;
  return WEXITSTATUS(status) == 127 ? -1 : WEXITSTATUS(status);
}

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

void say(std::ostream* out, const std::string& line) {
  if (out) *out << line << std::endl;
}

// Array task ids of a job still in the queue (pending, running, completing).
std::set<std::string> queued_tasks(const std::string& job_id, bool* ok) {
  std::string text;
  const int rc = run_program({"squeue", "-h", "-j", job_id, "-o", "%i %T"}, &text);
  std::set<std::string> out;
  // squeue answers "Invalid job id" (rc 1) once a job has left the queue.
  *ok = rc == 0 || text.find("Invalid job id") != std::string::npos;
  if (rc != 0) return out;
  std::istringstream lines(text);
  std::string id, state;
  while (lines >> id >> state) out.insert(id);
  return out;
}

}  // namespace

bool slurm_available(std::string* why) {
  std::string text;
  if (run_program({"squeue", "-h", "-o", "%i"}, &text) != 0) {
    if (why) *why = "squeue did not answer: " + text.substr(0, text.find('\n'));
    return false;
  }
  return true;
}

SlurmSummary run_slurm(db::ResultsDb& db, const db::SweepRecord& sweep, const SlurmLaunch& l) {
  SlurmSummary sum;
  std::string why;
  if (!slurm_available(&why))
    throw std::runtime_error("--backend slurm: Slurm is not reachable (" + why +
                             "); is SLURM_CONF set and slurmctld running?");
  const nlohmann::json spec = nlohmann::json::parse(sweep.spec_json);
  const nlohmann::json slurm = spec.value("slurm", nlohmann::json::object());
  const int per_task = slurm.value("runs_per_task", 1);
  const int max_parallel = slurm.value("max_parallel", 0);
  const std::string time_limit = slurm.value("time_limit", std::string("01:00:00"));
  const std::string partition = slurm.value("partition", std::string());
  const int cpus = slurm.value("cpus_per_task", 1);
  // a GPU per task when the workers run on cuda, unless the sweep says which
  const std::string gres =
      slurm.value("gres", std::string(l.device == "cuda" ? "gpu:1" : ""));

  // What to do: claimable runs of the sweep (the tasks claim them for real).
  std::vector<db::RunRecord> to_submit;
  for (const db::RunRecord& r : db.runs(sweep.id)) {
    bool wanted = false;
    for (RunState s : l.states) wanted = wanted || r.status == s;
    if (wanted && r.failures < sweep.max_attempts) to_submit.push_back(r);
  }
  if (to_submit.empty()) {
    say(l.out, "slurm: nothing to run in sweep " + sweep.name);
    return sum;
  }
  const fs::path job_dir =
      fs::path(to_submit.front().run_dir).parent_path() / "slurm" /
      (sweep.name + "-" + std::to_string(static_cast<long long>(db::unix_now())) + "-" +
       std::to_string(getpid()));
  fs::create_directories(job_dir);
  int tasks = 0;
  for (std::size_t i = 0; i < to_submit.size(); i += static_cast<std::size_t>(per_task), ++tasks) {
    // states go to the task file as their stored text (db/run_state.hpp to_json)
    nlohmann::json task{{"states", l.states}, {"runs", nlohmann::json::array()}};
    if (!l.device.empty()) task["device"] = l.device;
    for (std::size_t j = i; j < std::min(to_submit.size(), i + static_cast<std::size_t>(per_task));
         ++j)
      task["runs"].push_back(to_submit[j].id);
    std::ofstream(job_dir / ("task_" + std::to_string(tasks) + ".json")) << task.dump(2) << "\n";
  }
  const fs::path script = job_dir / "job.sh";
  // a #SBATCH line ends at a line break: none may come from a path or a name
  for (const std::string& v : {sweep.name, job_dir.string(), partition, time_limit, gres})
    if (v.find_first_of("\n\r") != std::string::npos)
      throw std::runtime_error("cannot write a Slurm job script with a line break in " +
                               flocsim::input::shown(v));
  {
    std::ofstream f(script);
    f << "#!/bin/sh\n"
      << "#SBATCH --job-name=flocsim-" << sweep.name << "\n"
      << "#SBATCH --array=0-" << tasks - 1
      << (max_parallel > 0 ? "%" + std::to_string(max_parallel) : "") << "\n"
      << "#SBATCH --time=" << time_limit << "\n"
      << "#SBATCH --cpus-per-task=" << cpus << "\n"
      << "#SBATCH --ntasks=1\n"
      << "#SBATCH --output=" << (job_dir / "task_%a.out").string() << "\n"
      << (partition.empty() ? "" : "#SBATCH --partition=" + partition + "\n")
      << (gres.empty() ? "" : "#SBATCH --gres=" + gres + "\n") << "exec "
      << shell_quote(l.flocsim) << " sweep slurm-task --db "
      << shell_quote(fs::absolute(db.path()).string()) << " --sweep " << shell_quote(sweep.name)
      << " --task-file " << shell_quote((job_dir).string()) << "/task_${SLURM_ARRAY_TASK_ID}.json"
      << " --worker " << shell_quote(l.worker) << " --lease " << l.lease_s << "\n";
  }
  std::string text;
  const int rc = run_program({"sbatch", "--parsable", script.string()}, &text);
  if (rc != 0) throw std::runtime_error("sbatch failed (exit " + std::to_string(rc) + "): " + text);
  sum.job_id = text.substr(0, text.find_first_of(";\n"));
  sum.tasks = tasks;
  sum.runs = static_cast<int>(to_submit.size());
  say(l.out, "slurm: submitted job " + sum.job_id + ": " + std::to_string(to_submit.size()) +
                 " runs in " + std::to_string(tasks) + " array tasks (" + job_dir.string() + ")");
  if (!l.wait) return sum;

  bool cancelled = false;
  std::size_t last_done = static_cast<std::size_t>(-1);
  while (true) {
    if (process::stop_requests() > 0 && !cancelled) {
      say(l.out, "slurm: stopping: scancel " + sum.job_id + " (tasks checkpoint their runs)");
      run_program({"scancel", sum.job_id}, nullptr);
      cancelled = true;
      sum.stopped = true;
    }
    bool ok = false;
    const std::set<std::string> queued = queued_tasks(sum.job_id, &ok);
    if (ok && queued.empty()) break;
    std::size_t done = 0;
    for (const db::StateCount& c : db.count_states(sweep.id))
      if (c.status == RunState::kCompleted) done = static_cast<std::size_t>(c.runs);
    if (done != last_done) {
      say(l.out, "slurm: job " + sum.job_id + ": " + std::to_string(queued.size()) +
                     " task(s) queued or running; " + std::to_string(done) + " runs completed");
      last_done = done;
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(l.poll_s));
  }
  // The job left the queue: its attempts still open were lost with it (time limit,
  // node failure, scancel before the task could record).
  for (const db::AttemptRecord& a : db.live_attempts()) {
    if (a.backend != "slurm" || a.job_id.rfind(sum.job_id + "_", 0) != 0) continue;
    if (process_alive(static_cast<pid_t>(a.owner_pid)) && a.host == host_name()) continue;
    if (db.end_attempt(a.id, RunState::kLost, std::nullopt, std::nullopt,
                       "Slurm job " + a.job_id + " left the queue while the run was open")) {
      ++sum.lost;
      say(l.out, "lost       " + a.run_id.substr(0, 12) + ": Slurm job " + a.job_id +
                     " ended before the run was recorded");
    }
  }
  say(l.out, "slurm: job " + sum.job_id + " finished");
  return sum;
}

int run_slurm_task(db::ResultsDb& db, const db::SweepRecord& sweep, const std::string& task_file,
                   const std::string& worker, double lease_s, std::ostream& out) {
  std::ifstream f(task_file);
  if (!f) throw std::runtime_error("cannot read Slurm task file " + task_file);
  const nlohmann::json task = nlohmann::json::parse(f);
  PoolOptions p;
  p.worker = worker;
  p.jobs = 1;
  try {
    p.states = task.at("states").get<std::vector<RunState>>();
  } catch (const std::invalid_argument& e) {  // a state db/run_state.hpp does not know
    throw std::runtime_error("Slurm task file " + task_file + ": " + e.what());
  }
  p.only_runs = task.at("runs").get<std::vector<std::string>>();
  p.device = task.value("device", std::string());  // the task's GPU is the one Slurm gave it
  p.lease_s = lease_s;
  p.backend = "slurm";
  const char* job = std::getenv("SLURM_ARRAY_JOB_ID");
  const char* index = std::getenv("SLURM_ARRAY_TASK_ID");
  const char* plain = std::getenv("SLURM_JOB_ID");
  p.job_id = job && index ? std::string(job) + "_" + index : (plain ? plain : "");
  p.out = &out;
  const PoolSummary s = run_pool(db, sweep, p);
  if (s.stopped) return process::kExitInterrupted;
  return s.failed + s.refused + s.lost > 0 ? process::kExitFailure : process::kExitOk;
}

int cancel_all(db::ResultsDb& db, std::ostream& out) {
  std::set<long long> owners;
  std::set<std::string> jobs;
  const std::string host = host_name();
  for (const db::AttemptRecord& a : db.live_attempts()) {
    if (a.backend == "slurm" && !a.job_id.empty())
      jobs.insert(a.job_id.substr(0, a.job_id.find('_')));
    else if (a.host == host && process_alive(static_cast<pid_t>(a.owner_pid)))
      owners.insert(a.owner_pid);
  }
  for (long long pid : owners) {
    kill(static_cast<pid_t>(pid), SIGTERM);
    out << "asked orchestrator pid " << pid << " to stop (its workers checkpoint)\n";
  }
  for (const std::string& j : jobs) {
    std::string text;
    const int rc = run_program({"scancel", j}, &text);
    out << "scancel " << j << (rc == 0 ? "" : ": failed: " + text) << "\n";
  }
  if (owners.empty() && jobs.empty()) out << "nothing is running\n";
  return static_cast<int>(owners.size() + jobs.size());
}

}  // namespace flocsim::orchestrator
