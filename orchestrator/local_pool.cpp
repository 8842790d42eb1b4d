#include "orchestrator/local_pool.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include "engine/case/resolved_case.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/process/exit_codes.hpp"
#include "engine/process/stop_signal.hpp"
#include "engine/run/output_directory.hpp"
#include "orchestrator/process.hpp"
#include "orchestrator/terminal_table.hpp"

namespace flocsim::orchestrator {

namespace fs = std::filesystem;
using db::RunState;
using db::unix_now;
using nlohmann::json;

std::string default_runs_dir(const std::string& db_path) {
  fs::path p = fs::absolute(db_path);
  p.replace_extension(".runs");
  return p.string();
}

namespace {

// The first dotted path at which two JSON values differ ("" when equal).
std::string first_difference(const json& a, const json& b, const std::string& path = "") {
  if (a.is_object() && b.is_object()) {
    for (auto it = a.begin(); it != a.end(); ++it) {
      const std::string sub = path.empty() ? it.key() : path + "." + it.key();
      if (!b.contains(it.key())) return sub;
      const std::string d = first_difference(it.value(), b[it.key()], sub);
      if (!d.empty()) return d;
    }
    for (auto it = b.begin(); it != b.end(); ++it)
      if (!a.contains(it.key())) return path.empty() ? it.key() : path + "." + it.key();
    return "";
  }
  return canonical(a) == canonical(b) ? "" : (path.empty() ? std::string("(top level)") : path);
}

// A sweep may grow (more axis values) or change how it runs (description,
// retries, Slurm), but a relaunch under the same name with another base or
// other axes would merge two different grids into one sweep: refuse it.
void refuse_changed_grid(const db::SweepRecord& known, const SweepSpec& spec,
                         const std::string& db_path) {
  const SweepSpec before = parse_sweep(nlohmann::ordered_json::parse(known.spec_json), db_path);
  const std::string changed = first_difference(before.base, spec.base);
  if (!changed.empty()) {
    const auto was = get_path(before.base, changed), now = get_path(spec.base, changed);
    throw flocsim::input::InputError(
        "sweep " + spec.name + " in " + db_path + " was launched with base." + changed + " = " +
        (was ? flocsim::input::shown(*was) : std::string("(absent)")) + "; this file has " +
        (now ? flocsim::input::shown(*now) : std::string("(absent)")) +
        ". A sweep's base cannot change (its runs would mix two grids): give the new grid "
        "another \"name\"");
  }
  std::vector<std::string> old_axes, new_axes;
  for (const Axis& a : before.axes) old_axes.push_back(a.path);
  for (const Axis& a : spec.axes) new_axes.push_back(a.path);
  std::sort(old_axes.begin(), old_axes.end());
  std::sort(new_axes.begin(), new_axes.end());
  if (old_axes != new_axes) {
    auto list = [](const std::vector<std::string>& v) {
      std::string out;
      for (const auto& x : v) out += (out.empty() ? "" : ", ") + x;
      return out;
    };
    throw flocsim::input::InputError(
        "sweep " + spec.name + " in " + db_path + " was launched with the axes " + list(old_axes) +
        "; this file has " + list(new_axes) +
        ". A sweep may add values to its axes but not change them: give the new grid another "
        "\"name\"");
  }
}

}  // namespace

void refuse_changed_grid(db::ResultsDb& db, const SweepSpec& spec) {
  if (const auto known = db.find_sweep(spec.name)) refuse_changed_grid(*known, spec, db.path());
}

Registered register_sweep(db::ResultsDb& db, const SweepSpec& spec, const std::string& runs_dir) {
  refuse_changed_grid(db, spec);
  const std::vector<RunPoint> points = expand(spec);
  nlohmann::json axes = nlohmann::json::array();
  for (const Axis& a : spec.axes) axes.push_back(a.path);
  const fs::path dir = fs::absolute(runs_dir);
  std::vector<db::ResultsDb::NewRun> runs;
  for (const RunPoint& p : points)
    runs.push_back({p.id, p.case_json.dump(), (dir / p.id.substr(0, 16)).string(), p.point.dump()});
  Registered r;
  const std::int64_t id =
      db.upsert_sweep(spec.name, spec.source.dump(), axes.dump(), spec.max_attempts);
  r.added = db.add_runs(id, runs);
  r.runs = static_cast<int>(runs.size());
  r.sweep = *db.find_sweep(spec.name);
  return r;
}

namespace {

std::string short_id(const std::string& id) {
  return id.substr(0, 12);
}

void say(std::ostream* out, const std::string& line) {
  if (out) *out << printable(line) << std::endl;  // names a run folder, a host, a reason
}

// DIR/result.json read as this run's result: complete, and of this run's case.
// A result.json is only a file in a folder: one copied or left there by
// another run (another seed, another sweep) must not become this run's result,
// so its "case" is compared as `run --resume` compares it, with the case as
// given (what a worker that copies it records) or as this version resolves it
// (what `flocsim run` records).
ResultRead read_own_result(const db::RunRecord& run) {
  ResultRead rr = read_result(run.run_dir, run.id);
  if (!rr.record) return rr;
  const json result = json::parse(rr.record->result_json, nullptr, false);
  const json given = json::parse(run.case_json, nullptr, false);
  const json recorded = result.is_object() ? result.value("case", json()) : json();
  if (run::completed_under(recorded, given)) return rr;
  json resolved = given;
  try {
    resolved = cases::resolved_case(given);
    if (run::completed_under(recorded, resolved)) return rr;
  } catch (const std::exception&) {
    // this version refuses the case: only the case as given could have matched
  }
  const std::string field = recorded.is_object() ? first_difference(recorded, resolved) : "";
  return {std::nullopt,
          run.run_dir + "/result.json is the result of another case (" +
              (field.empty() ? std::string("it records no case")
                             : "first difference at case field " + field) +
              "); it is not this run's result, so it is not recorded and is left as it is",
          true};
}

// Records a result found complete on disk; returns whether it was valid (a
// worker found gone may have left one of another case: not recorded, and the
// attempt ends lost; the pool's claim says what to do about such a file).
bool record_if_complete(db::ResultsDb& db, std::int64_t attempt_id, const db::RunRecord& run) {
  ResultRead rr = read_own_result(run);
  if (!rr.record) return false;
  db.record_result(attempt_id, *rr.record);
  return true;
}

struct Orphan {
  db::AttemptRecord attempt;
  db::RunRecord run;
};

std::vector<Orphan> reconcile(db::ResultsDb& db, double lease_s, std::ostream* out, int* closed) {
  const std::string host = host_name();
  const pid_t self = getpid();
  const double now = unix_now();
  std::vector<Orphan> orphans;
  for (const db::AttemptRecord& a : db.live_attempts()) {
    if (a.owner_pid == self) continue;
    const auto run = db.find_run(a.run_id);
    if (!run) continue;
    if (a.host == host) {
      if (process_alive(static_cast<pid_t>(a.owner_pid))) continue;  // watched by its owner
      if (a.pid > 0 && process_alive(static_cast<pid_t>(a.pid), a.pid_start)) {
        orphans.push_back({a, *run});
        continue;
      }
      if (record_if_complete(db, a.id, *run)) {
        say(out, "recorded   " + short_id(a.run_id) +
                     ": finished while its orchestrator was gone (result.json complete)");
      } else {
        const std::string why =
            "worker " + (a.pid > 0 ? "pid " + std::to_string(a.pid) : "(not started)") + " on " +
            host + " is gone and its orchestrator (pid " + std::to_string(a.owner_pid) + ") died";
        if (db.end_attempt(a.id, RunState::kLost, std::nullopt, std::nullopt, why))
          say(out, "lost       " + short_id(a.run_id) + ": " + why);
      }
      if (closed) ++*closed;
    } else {
      const double beat = a.heartbeat_at.value_or(a.started_at);
      if (now - beat <= lease_s) continue;
      if (record_if_complete(db, a.id, *run)) {
        say(out, "recorded   " + short_id(a.run_id) + ": finished on " + a.host);
      } else {
        char why[256];
        std::snprintf(why, sizeof why, "no heartbeat from %s (pid %lld) for %.0f s (lease %.0f s)",
                      a.host.c_str(), static_cast<long long>(a.pid), now - beat, lease_s);
        if (db.end_attempt(a.id, RunState::kLost, std::nullopt, std::nullopt, why))
          say(out, "lost       " + short_id(a.run_id) + ": " + why);
      }
      if (closed) ++*closed;
    }
  }
  return orphans;
}

struct Worker {
  pid_t pid = 0;
  bool child = true;  // our child (waitpid) or adopted from a dead orchestrator
  std::string pid_start;
  std::int64_t attempt_id = 0;
  db::RunRecord run;
  double started = 0, last_beat = 0;
  double term_sent = 0;
  bool kill_sent = false;
  bool lease_expired = false;
  int gpu = -1;  // the GPU given to it (CUDA_VISIBLE_DEVICES), -1 none
};

// The GPU (0 .. gpus - 1) that the fewest running workers use, the lowest
// index among equals: workers spread over the GPUs one each, then share.
int least_busy_gpu(const std::vector<Worker>& running, int gpus) {
  std::vector<int> load(static_cast<std::size_t>(gpus), 0);
  for (const Worker& w : running)
    if (w.gpu >= 0 && w.gpu < gpus) ++load[static_cast<std::size_t>(w.gpu)];
  return static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
}

}  // namespace

std::vector<std::string> visible_gpu_ids(const char* inherited,
                                         const std::vector<int>& cuda_indices) {
  std::vector<std::string> list;
  if (inherited) {
    std::stringstream in(inherited);
    for (std::string item; std::getline(in, item, ',');) {
      const auto first = item.find_first_not_of(" \t");
      const auto last = item.find_last_not_of(" \t");
      list.push_back(first == std::string::npos ? "" : item.substr(first, last - first + 1));
    }
  }
  std::vector<std::string> ids;
  for (int i : cuda_indices) {
    const auto at = static_cast<std::size_t>(i);
    ids.push_back(i >= 0 && at < list.size() && !list[at].empty() ? list[at] : std::to_string(i));
  }
  return ids;
}

namespace {

void write_case_file(const std::string& run_dir, const std::string& case_json) {
  const fs::path dir(run_dir);
  const fs::path tmp = dir / "case.json.tmp";
  {
    std::ofstream f(tmp);
    f << nlohmann::json::parse(case_json).dump(2) << "\n";
    f.flush();
    if (!f) throw std::runtime_error("cannot write " + tmp.string());
  }
  fs::rename(tmp, dir / "case.json");
}

}  // namespace

int reconcile_lost_workers(db::ResultsDb& db, double lease_s, std::ostream* out) {
  int closed = 0;
  reconcile(db, lease_s, out, &closed);
  return closed;
}

PoolSummary run_pool(db::ResultsDb& db, const db::SweepRecord& sweep, const PoolOptions& o) {
  PoolSummary sum;
  if (o.jobs < 1) throw std::invalid_argument("--jobs must be at least 1");
  const std::string host = host_name();
  const pid_t self = getpid();
  std::vector<Worker> workers;

  // Runs of this sweep that a dead orchestrator left running: watch them to the end.
  std::set<std::string> in_sweep;
  for (const db::RunRecord& r : db.runs(sweep.id)) in_sweep.insert(r.id);
  for (Orphan& orphan : reconcile(db, o.lease_s, o.out, nullptr)) {
    if (!in_sweep.count(orphan.run.id)) continue;
    if (!db.adopt_attempt(orphan.attempt.id, self)) continue;
    Worker w;
    w.pid = static_cast<pid_t>(orphan.attempt.pid);
    w.child = false;
    w.pid_start = orphan.attempt.pid_start;
    w.attempt_id = orphan.attempt.id;
    w.run = orphan.run;
    w.started = orphan.attempt.started_at;
    w.last_beat = std::max(unix_now(), orphan.attempt.heartbeat_at.value_or(0));
    say(o.out, "adopted    " + short_id(w.run.id) + ": worker pid " + std::to_string(w.pid) +
                   " still running from an earlier orchestrator");
    workers.push_back(std::move(w));
  }

  std::vector<std::string> only;
  if (o.only_runs) only = *o.only_runs;
  std::size_t only_next = 0;
  std::vector<std::string> tried;
  const int total = static_cast<int>(in_sweep.size());
  auto progress_tag = [&] {
    const auto counts = db.count_states(sweep.id);
    int done = 0;
    for (const auto& c : counts)
      if (c.status == RunState::kCompleted) done = c.runs;
    return "[" + std::to_string(done) + "/" + std::to_string(total) + "]";
  };

  // Claims and starts one run; false when nothing is claimable.
  auto start_one = [&]() -> bool {
    while (true) {
      // One attempt per run per pool: a run that fails or is lost here waits
      // for the next launch or resume (no tight retry loops).
      db::ClaimRequest req{sweep.id, o.states, sweep.max_attempts, std::nullopt, tried};
      if (o.only_runs) {
        if (only_next >= only.size()) return false;
        req.run_id = only[only_next++];
      }
      db::AttemptStart start;
      start.backend = o.backend;
      start.host = host;
      start.owner_pid = self;
      start.job_id = o.job_id;
      const std::optional<db::Claim> claim = db.claim_run(req, start);
      if (!claim) {
        if (o.only_runs) continue;  // that run is not claimable (done, or taken): next one
        return false;
      }
      const db::RunRecord& run = claim->run;
      tried.push_back(run.id);
      fs::create_directories(run.run_dir);
      // A complete result already on disk (its recording was cut short): record, don't rerun.
      const ResultRead found = read_own_result(run);
      if (found.record) {
        db.record_result(claim->attempt_id, *found.record);
        ++sum.recovered;
        say(o.out, progress_tag() + " recorded " + short_id(run.id) + " " +
                       point_text(run.point_json) + " (result.json found complete on disk)");
        continue;
      }
      // Another case's result.json in the run folder: `flocsim run` refuses
      // to run over it (exit 2), which made the run `refused` for good, with
      // a hint (another --out) a sweep cannot follow. The attempt fails
      // instead, saying what to move; the next resume retries the run.
      if (found.foreign) {
        const std::string why = found.problem +
                                "; no worker was started: move it out of the run folder, then " +
                                "resume the sweep";
        db.end_attempt(claim->attempt_id, RunState::kFailed, std::nullopt, std::nullopt, why);
        ++sum.failed;
        say(o.out, progress_tag() + " failed   " + short_id(run.id) + " " +
                       point_text(run.point_json) + ": " + why);
        return true;
      }
      const bool resume = run.status != RunState::kPending;
      try {
        write_case_file(run.run_dir, run.case_json);
        std::vector<std::string> argv{o.worker, "run", run.run_dir + "/case.json", "--out",
                                      run.run_dir};
        if (resume) argv.push_back("--resume");
        argv.push_back("--quiet");
        Worker w;
        std::vector<std::pair<std::string, std::string>> env;
        if (!o.device.empty()) {
          argv.push_back("--device");
          argv.push_back(o.device);
        }
        if (o.device == "cuda" && o.gpus > 1) {
          w.gpu = least_busy_gpu(workers, o.gpus);
          const auto slot = static_cast<std::size_t>(w.gpu);
          env.emplace_back("CUDA_VISIBLE_DEVICES",
                           slot < o.gpu_ids.size() ? o.gpu_ids[slot] : std::to_string(w.gpu));
        }
        w.pid = spawn(argv, run.run_dir + "/worker.log", env);
        w.pid_start = process_start_time(w.pid);
        w.attempt_id = claim->attempt_id;
        w.run = run;
        w.started = unix_now();
        w.last_beat = w.started;
        db.set_attempt_pid(w.attempt_id, w.pid, w.pid_start, run.run_dir + "/run.log");
        ++sum.started;
        say(o.out, progress_tag() + " started  " + short_id(run.id) + " " +
                       point_text(run.point_json) + (resume ? " (resuming)" : "") + " pid " +
                       std::to_string(w.pid));
        workers.push_back(std::move(w));
      } catch (const std::exception& e) {
        db.end_attempt(claim->attempt_id, RunState::kFailed, std::nullopt, std::nullopt,
                       std::string("could not start the worker: ") + e.what());
        ++sum.failed;
        say(o.out, "failed   " + short_id(run.id) + ": could not start the worker: " + e.what());
      }
      return true;
    }
  };

  // Records how a worker ended.
  auto finish = [&](const Worker& w, std::optional<int> exit_code, std::optional<int> sig) {
    const std::string tag = short_id(w.run.id) + " " + point_text(w.run.point_json);
    ResultRead rr = read_own_result(w.run);
    if (rr.record) {
      db.record_result(w.attempt_id, *rr.record);
      ++sum.completed;
      char secs[32];
      std::snprintf(secs, sizeof secs, "%.1f", unix_now() - w.started);
      say(o.out, progress_tag() + " done     " + tag + " in " + secs + " s");
      return;
    }
    const std::string tail = tail_of_file(w.run.run_dir + "/worker.log");
    RunState state = RunState::kLost;
    std::string why;
    if (w.lease_expired) {
      state = RunState::kLost;
      char buf[160];
      std::snprintf(buf, sizeof buf,
                    "no heartbeat (progress.json) for more than %.0f s; worker stopped", o.lease_s);
      why = buf;
    } else if (exit_code) {
      switch (*exit_code) {
        case process::kExitOk:
          state = RunState::kFailed;
          why = "worker exited 0 but its result is not usable: " + rr.problem;
          break;
        case process::kExitBadInput:
          state = RunState::kRefused;
          why = "case refused (exit " + std::to_string(process::kExitBadInput) + "): " + tail;
          break;
        case process::kExitBusy:
          // an earlier worker of this run still writes its folder (one whose
          // orchestrator died, say): not the case's fault; a later resume
          // retries once that worker has ended
          state = RunState::kLost;
          why = "its run folder is held by another flocsim still running (exit " +
                std::to_string(process::kExitBusy) + "): " + tail;
          break;
        case process::kExitInterrupted:
          state = RunState::kInterrupted;
          why = "stopped by a signal after writing a checkpoint (exit " +
                std::to_string(process::kExitInterrupted) + ")";
          break;
        default:
          state = RunState::kFailed;
          why = "exit code " + std::to_string(*exit_code) + ": " + tail;
      }
    } else if (sig) {
      const bool external = *sig == SIGKILL || *sig == SIGTERM || *sig == SIGINT || *sig == SIGHUP;
      state = external ? RunState::kLost : RunState::kFailed;
      why = "worker killed by " + signal_name(*sig) + (tail.empty() ? "" : ": " + tail);
    } else {
      state = RunState::kLost;
      why = "worker pid " + std::to_string(w.pid) +
            " ended unwatched (its orchestrator had died) without a result";
    }
    db.end_attempt(w.attempt_id, state, exit_code, sig, why);
    if (state == RunState::kFailed) ++sum.failed;
    if (state == RunState::kRefused) ++sum.refused;
    if (state == RunState::kInterrupted) ++sum.interrupted;
    if (state == RunState::kLost) ++sum.lost;
    const std::string first_line = why.substr(0, why.find('\n'));
    const std::string name = to_string(state);
    say(o.out, progress_tag() + " " + name +
                   (name.size() < 8 ? std::string(8 - name.size(), ' ') : "") + " " + tag + ": " +
                   first_line);
  };

  double last_heartbeat_write = 0;
  double stop_seen = 0;
  while (true) {
    const int stops = process::stop_requests();
    const double now = unix_now();
    if (stops > 0 && stop_seen == 0) {
      stop_seen = now;
      sum.stopped = true;
      say(o.out, "stopping: asking " + std::to_string(workers.size()) +
                     " worker(s) to checkpoint and exit (signal again to kill them)");
    }
    bool exhausted = false;
    if (stops == 0) {
      while (static_cast<int>(workers.size()) < o.jobs) {
        if (!start_one()) {
          exhausted = true;
          break;
        }
      }
    }
    // Reap and watch.
    for (std::size_t i = 0; i < workers.size();) {
      Worker& w = workers[i];
      bool ended = false;
      std::optional<int> code, sig;
      if (w.child) {
        int status = 0;
        const pid_t r = waitpid(w.pid, &status, WNOHANG);
        if (r == w.pid) {
          ended = true;
          if (WIFEXITED(status)) code = WEXITSTATUS(status);
          if (WIFSIGNALED(status)) sig = WTERMSIG(status);
        }
      } else if (!process_alive(w.pid, w.pid_start)) {
        ended = true;
      }
      if (ended) {
        finish(w, code, sig);
        workers.erase(workers.begin() + static_cast<std::ptrdiff_t>(i));
        continue;
      }
      // Stop requests and expired leases.
      if (stop_seen > 0 && w.term_sent == 0) {
        kill(w.pid, SIGTERM);
        w.term_sent = now;
      }
      if (!w.kill_sent && w.term_sent > 0 &&
          (stops >= 2 || now - w.term_sent > (w.lease_expired ? 10.0 : o.grace_s))) {
        kill(w.pid, SIGKILL);
        w.kill_sent = true;
      }
      if (!w.lease_expired && now - w.last_beat > o.lease_s) {
        w.lease_expired = true;
        if (w.term_sent == 0) {
          kill(w.pid, SIGTERM);
          w.term_sent = now;
        }
      }
      ++i;
    }
    // Heartbeats into the database, at most every 2 s, in one short transaction.
    if (now - last_heartbeat_write >= 2.0) {
      std::vector<db::Heartbeat> beats;
      for (Worker& w : workers) {
        auto hb = read_progress(w.run.run_dir);
        if (!hb || hb->at < w.started) continue;  // progress.json of an earlier attempt
        w.last_beat = std::max(w.last_beat, hb->at);
        hb->attempt_id = w.attempt_id;
        beats.push_back(*hb);
      }
      db.record_heartbeats(beats);
      last_heartbeat_write = now;
    }
    if (workers.empty() && (stops > 0 || exhausted)) break;
    std::this_thread::sleep_for(std::chrono::duration<double>(o.poll_s));
  }
  return sum;
}

}  // namespace flocsim::orchestrator
