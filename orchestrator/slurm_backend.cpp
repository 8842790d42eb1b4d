#include "orchestrator/slurm_backend.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "engine/input/input_reader.hpp"
#include "engine/process/exit_codes.hpp"
#include "engine/process/stop_signal.hpp"
#include "orchestrator/local_pool.hpp"
#include "orchestrator/process.hpp"
#include "orchestrator/sweep.hpp"
#include "orchestrator/terminal_table.hpp"

namespace flocsim::orchestrator {

namespace fs = std::filesystem;
using db::RunState;

namespace {

// Runs a program (looked up in PATH), capturing stdout and stderr; returns its
// exit code, or -1 when it could not be run. A `stoppable` one is ended
// (SIGTERM, then SIGKILL) when flocsim is asked to stop: an sbatch that never
// answers otherwise held flocsim in read() through every Ctrl-C and SIGTERM.
int run_program(const std::vector<std::string>& argv, std::string* output, bool stoppable = false) {
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
  int stop_sent = 0;
  while (true) {
    if (stoppable) {
      if (process::stop_requests() > 0 && stop_sent == 0) {
        kill(pid, SIGTERM);
        stop_sent = 1;
        text += "(stopped: flocsim was asked to stop while " + argv.front() + " ran) ";
      }
      pollfd p{pipe_fd[0], POLLIN, 0};
      const int ready = poll(&p, 1, stop_sent > 0 ? 2000 : 200);
      if (ready < 0) continue;  // a signal: look at the stop request again
      if (ready == 0) {
        if (stop_sent == 1) {  // still there two seconds after SIGTERM
          kill(pid, SIGKILL);
          stop_sent = 2;
        }
        if (stop_sent == 2) {
          // a grandchild may hold the pipe open: flocsim does not wait for it
          pid_t done = waitpid(pid, nullptr, WNOHANG);
          if (done == pid) {
            close(pipe_fd[0]);
            if (output) *output = text;
            return -1;
          }
        }
        continue;
      }
    }
    n = read(pipe_fd[0], buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    text.append(buf, static_cast<std::size_t>(n));
  }
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
  if (out) *out << printable(line) << std::endl;  // names a job, a path, Slurm's reason
}

// Where execvp would find `program` ("" when nowhere): run_program's -1 says
// only that it could not run.
std::string on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/bin:/usr/bin");
  for (std::string d; std::getline(dirs, d, ':');) {
    const fs::path p = fs::path(d.empty() ? "." : d) / program;
    if (access(p.c_str(), X_OK) == 0) return p.string();
  }
  return "";
}

// A value of an sbatch --output pattern: there % starts a replacement (%a, %j,
// %x), so a % of a folder's name must be written %% or the task's output goes
// to a file that cannot be opened, and the task fails before it runs.
std::string output_pattern(const std::string& path) {
  std::string out;
  for (char c : path) out += c == '%' ? std::string("%%") : std::string(1, c);
  return out;
}

// The job folder's name: the sweep name's first 40 characters that need no
// quoting anywhere (others become _), then the time and this process: a long
// or odd sweep name never makes a path too long or a pattern of it.
std::string job_folder_name(const std::string& sweep) {
  std::string part;
  for (char c : sweep.substr(0, 40))
    part +=
        std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.' ? c : '_';
  return part + "-" + std::to_string(static_cast<long long>(db::unix_now())) + "-" +
         std::to_string(getpid());
}

// How the array tasks of a job that left the queue ended, from Slurm's own
// record (scontrol while it remembers the job, MinJobAge; then sacct): task
// id -> "STATE (exit CODE)". Empty when neither answers.
std::map<std::string, std::string> task_states(const std::string& job_id) {
  std::map<std::string, std::string> out;
  std::string text;
  if (run_program({"scontrol", "-o", "show", "job", job_id}, &text) == 0) {
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) {
      auto field = [&line](const std::string& key) {
        const auto at = line.find(" " + key + "=");
        if (at == std::string::npos) return std::string();
        const auto from = at + key.size() + 2;
        return line.substr(from, line.find(' ', from) - from);
      };
      const std::string task = field("ArrayTaskId"), state = field("JobState");
      if (!state.empty())
        out[task.empty() ? job_id : task] = state + " (exit " + field("ExitCode") + ")";
    }
    if (!out.empty()) return out;
  }
  if (run_program({"sacct", "-n", "-X", "-P", "-j", job_id, "-o", "JobID,State,ExitCode"}, &text) ==
      0) {
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) {
      std::istringstream f(line);
      std::string id, state, code;
      std::getline(f, id, '|');
      std::getline(f, state, '|');
      std::getline(f, code, '|');
      if (state.empty()) continue;
      const auto us = id.find('_');
      out[us == std::string::npos ? id : id.substr(us + 1)] = state + " (exit " + code + ")";
    }
  }
  return out;
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
  // The Slurm settings as `sweep launch` checks them: the database is only a
  // file, and a stored runs_per_task of 0 wrote empty task files without end.
  SlurmOptions settings;
  try {
    settings = parse_sweep(nlohmann::ordered_json::parse(sweep.spec_json),
                           db.path() + " (sweep " + sweep.name + " as stored)")
                   .slurm;
  } catch (const nlohmann::json::parse_error& e) {
    // said in words: the library's own "[json.exception.parse_error.101]" is
    // no help to a user
    throw flocsim::input::InputError(db.path() + ": the stored file of sweep " + sweep.name +
                                     " is not JSON (bad syntax at byte " + std::to_string(e.byte) +
                                     "); launch its sweep file again");
  } catch (const nlohmann::json::exception&) {
    throw flocsim::input::InputError(db.path() + ": the stored file of sweep " + sweep.name +
                                     " cannot be read as a sweep file; launch its sweep file "
                                     "again");
  }
  const int per_task = settings.runs_per_task;
  const int max_parallel = settings.max_parallel;
  const std::string time_limit = settings.time_limit;
  const std::string partition = settings.partition;
  const int cpus = settings.cpus_per_task;
  std::string why;
  if (!slurm_available(&why))
    throw std::runtime_error("--backend slurm: Slurm is not reachable (" + why +
                             "); is SLURM_CONF set and slurmctld running?");
  // said before anything is written: "sbatch failed (exit -1):" named no reason
  if (on_path("sbatch").empty())
    throw std::runtime_error(std::string("--backend slurm: sbatch is not on PATH (") +
                             (std::getenv("PATH") ? std::getenv("PATH") : "unset") +
                             "), though squeue answers; install Slurm's client commands "
                             "(slurm-client) or add their folder to PATH");
  // a GPU per task when the workers run on cuda, unless the sweep says which
  const std::string gres =
      !settings.gres.empty() ? settings.gres : (l.device == "cuda" ? "gpu:1" : "");

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
      fs::path(to_submit.front().run_dir).parent_path() / "slurm" / job_folder_name(sweep.name);
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
  // The options go to sbatch as its arguments, not as #SBATCH lines: sbatch
  // reads those with rules of its own (a space ends the value, " must pair, #
  // starts a comment), and a space in the runs folder or a " in the sweep name
  // made it refuse the script. Arguments reach it as they are (no shell); only
  // --output's % needs escaping. The job name is cut short: it only labels.
  const std::vector<std::string> options = {
      "--job-name=flocsim-" + sweep.name.substr(0, 64),
      "--array=0-" + std::to_string(tasks - 1) +
          (max_parallel > 0 ? "%" + std::to_string(max_parallel) : ""),
      "--time=" + time_limit,
      "--cpus-per-task=" + std::to_string(cpus),
      "--ntasks=1",
      "--output=" + output_pattern(job_dir.string()) + "/task_%a.out"};
  std::vector<std::string> argv = {"sbatch", "--parsable"};
  argv.insert(argv.end(), options.begin(), options.end());
  if (!partition.empty()) argv.push_back("--partition=" + partition);
  if (!gres.empty()) argv.push_back("--gres=" + gres);
  argv.push_back(script.string());
  {
    std::ofstream f(script);
    f << "#!/bin/sh\n# submitted by flocsim as:";
    for (const std::string& a : argv) f << " " << shell_word(a);
    f << "\nexec " << shell_quote(l.flocsim) << " sweep slurm-task --db "
      << shell_quote(fs::absolute(db.path()).string()) << " --sweep " << shell_quote(sweep.name)
      << " --task-file " << shell_quote((job_dir).string()) << "/task_${SLURM_ARRAY_TASK_ID}.json"
      << " --worker " << shell_quote(l.worker) << " --lease " << l.lease_s << "\n";
  }
  std::string text;
  const int rc = run_program(argv, &text, true);
  if (rc != 0)
    throw std::runtime_error(rc < 0 ? "sbatch (" + on_path("sbatch") + ") could not be run: " + text
                                    : "sbatch refused the job (exit " + std::to_string(rc) +
                                          "): " + text);
  sum.job_id = text.substr(0, text.find_first_of(";\n"));
  // sbatch --parsable answers "JOBID" or "JOBID;CLUSTER": anything else is not
  // a job flocsim can follow (or scancel), so it is not said to be submitted
  if (sum.job_id.empty() || sum.job_id.size() > 18 ||
      sum.job_id.find_first_not_of("0123456789") != std::string::npos)
    throw std::runtime_error("sbatch (" + on_path("sbatch") + ") answered \"" +
                             text.substr(0, 200) +
                             "\" where --parsable gives the job id; flocsim cannot follow that "
                             "job: see squeue whether one was queued, and scancel it");
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
  // Slurm's own word on how the tasks ended: a task that failed before it ran
  // (its output file unwritable, the program missing) recorded nothing, and
  // "finished" left its runs pending without a reason.
  const std::map<std::string, std::string> states = task_states(sum.job_id);
  std::string failed;
  for (const auto& [task, state] : states)
    if (state.rfind("COMPLETED", 0) != 0)
      failed += (failed.empty() ? "" : "; ") + std::string("task ") + task + " " + state +
                ", output " + (job_dir / ("task_" + task + ".out")).string();
  if (states.empty())
    say(l.out, "slurm: job " + sum.job_id + " left the queue (Slurm no longer says how it ended)");
  else if (failed.empty())
    say(l.out, "slurm: job " + sum.job_id + " finished");
  else {
    sum.failed_tasks = failed;
    say(l.out, "slurm: job " + sum.job_id + " ended with Slurm's failure: " + failed +
                   "; runs its tasks did not record stay as they were (sweep status lists "
                   "them)");
  }
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
    out << "scancel " << printable(j) << (rc == 0 ? "" : ": failed: " + printable(text)) << "\n";
  }
  if (owners.empty() && jobs.empty()) out << "nothing is running\n";
  return static_cast<int>(owners.size() + jobs.size());
}

}  // namespace flocsim::orchestrator
