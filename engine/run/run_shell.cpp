#include "engine/run/run_shell.hpp"

#include <omp.h>

#include <fstream>

#include "engine/output/atomic_file.hpp"
#include "engine/process/stop_signal.hpp"

// The project's version, from CMake (engine/CMakeLists.txt).
#ifndef FLOCSIM_VERSION
#error "FLOCSIM_VERSION must come from the build (project VERSION)"
#endif

namespace flocsim::run {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

const char* const kFlocsimVersion = FLOCSIM_VERSION;

RunShell::RunShell(const RunOptions& options, const nlohmann::json& case_json,
                   const std::vector<std::string>& warnings, int threads)
    : options_(options),
      out_lock_(lock_output_directory(options.out_dir)),
      start_(prepare_output_directory(options.out_dir, options.resume, case_json)),
      log_(options.out_dir / "run.log", options.quiet),
      checkpoint_(options.out_dir / "checkpoint.h5") {
  if (start_ != StartMode::already_completed) {
    if (!out_lock_)
      log_.warning("the file system under " + options.out_dir.string() +
                   " offers no file locks: a second flocsim run given this folder while this one "
                   "runs would not be refused");
    for (const auto& w : warnings) log_.warning(w);
    if (threads > 0) omp_set_num_threads(threads);
  }
  t_start_ = Clock::now();
  last_checkpoint_ = t_start_;
}

RunReport RunShell::already_completed() {
  return completed_run(options_.out_dir, log_);
}

void RunShell::set_first_step(long step) {
  first_step_ = step;
  last_good_checkpoint_ = resuming() ? step : -1;
  last_checkpoint_ = Clock::now();
}

bool RunShell::stop_requested(long step) const {
  return process::stop_requested() != 0 ||
         (options_.stop_after_steps > 0 && step - first_step_ >= options_.stop_after_steps);
}

bool RunShell::checkpoint_due(long step, double every_s) const {
  return TimedStages::since(last_checkpoint_) >= every_s ||
         (options_.checkpoint_every_steps > 0 && step % options_.checkpoint_every_steps == 0);
}

void RunShell::checkpoint_written(long step) {
  last_checkpoint_ = Clock::now();
  last_good_checkpoint_ = step;
}

RunReport RunShell::interrupted(ProgressReporter& progress, long step) {
  progress.finish(step);
  log_.info("stopped at step " + std::to_string(step) +
            (process::stop_requested() ? " by signal " + std::to_string(process::stop_requested())
                                       : std::string()) +
            "; checkpoint written, continue with --resume");
  RunReport r;
  r.outcome = RunOutcome::interrupted;
  return r;
}

RunReport RunShell::blown_up(const std::string& where, const std::string& what,
                             const std::string& likely_causes) {
  return blown_up_run(log_, where, what, last_good_checkpoint_, checkpoint_, likely_causes);
}

nlohmann::json gpu_device_record(const gpu::GpuDevice& g) {
  return {{"kind", "cuda"},
          {"name", g.name},
          {"memory_gib", g.memory_gib},
          {"compute_capability",
           std::to_string(g.compute_major) + "." + std::to_string(g.compute_minor)}};
}

nlohmann::json cpu_device_record() {
  std::string model = "unknown CPU";
  std::ifstream info("/proc/cpuinfo");
  for (std::string line; std::getline(info, line);)
    if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
      model = line.substr(line.find(':') + 1);
      model.erase(0, model.find_first_not_of(' '));
      break;
    }
  return {{"kind", "cpu"}, {"name", model}, {"threads", omp_get_max_threads()}};
}

nlohmann::json RunShell::cost(double wall_before_s, double wall_s, long steps,
                              long steps_this_invocation, const TimedStages& stages) const {
  return {{"wall_s", wall_before_s + wall_s},
          {"wall_s_this_invocation", wall_s},
          {"steps", steps},
          {"steps_this_invocation", steps_this_invocation},
          {"threads", omp_get_max_threads()},
          {"modules_s", stages.seconds_by_name()}};
}

RunReport RunShell::complete(nlohmann::json result, double wall_s, const std::string& what,
                             const std::string& rate) {
  result["status"] = "completed";
  result["flocsim_version"] = kFlocsimVersion;
  // where it ran: a scene that stepped on a GPU has said so already
  if (!result.contains("device")) result["device"] = cpu_device_record();
  result["completed_at"] = utc_timestamp();
  const fs::path file = options_.out_dir / "result.json";
  output::write_file_atomically(file, result.dump(2) + "\n");
  // The result is complete on disk; the checkpoint is no longer needed.
  std::error_code ec;
  fs::remove(checkpoint_, ec);
  log_.info("completed " + what + " in " + format_duration(wall_s) + rate + "; result in " +
            file.string());
  RunReport r;
  r.outcome = RunOutcome::completed;
  r.result = std::move(result);
  return r;
}

}  // namespace flocsim::run
