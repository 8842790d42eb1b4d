#pragma once
// What every scene's time loop does around its steps, written once: prepare
// the output directory and open the log, set the threads, keep the wall
// clock, notice a stop request (SIGTERM/SIGINT, or --stop-after for tests),
// say when a checkpoint is due, and at the end write result.json's envelope
// (status, version, cost, completion time) atomically and drop the
// checkpoint. The scene's loop owns only its physics, its observables and its
// checkpoint's content.
#include <chrono>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "engine/input/input_reader.hpp"
#include "engine/lattice_gpu/gpu_fluid_lattice.hpp"
#include "engine/run/output_directory.hpp"
#include "engine/run/run_log.hpp"
#include "engine/run/run_types.hpp"
#include "engine/run/timed_stages.hpp"

namespace flocsim::run {

// The version every run writes into its log and result.json.
extern const char* const kFlocsimVersion;

class RunShell {
 public:
  // Prepares `options.out_dir` for `case_json` (output_directory.hpp), opens
  // the log and writes the case's warnings into it; `threads` > 0 sets OpenMP's.
  RunShell(const RunOptions& options, const nlohmann::json& case_json,
           const std::vector<std::string>& warnings, int threads);

  StartMode start() const { return start_; }
  bool resuming() const { return start_ == StartMode::from_checkpoint; }
  // The stored result of a run found complete (start() == already_completed).
  RunReport already_completed();

  RunLog& log() { return log_; }
  const RunOptions& options() const { return options_; }
  const std::filesystem::path& checkpoint_file() const { return checkpoint_; }
  // Wall seconds since this invocation started.
  double wall_s() const { return TimedStages::since(t_start_); }

  // The step this invocation started from (the checkpoint's, or 0).
  void set_first_step(long step);
  long first_step() const { return first_step_; }
  // A stop signal arrived, or this invocation ran its --stop-after steps.
  bool stop_requested(long step) const;
  // Wall time since the last checkpoint reached `every_s`, or the step is a
  // multiple of RunOptions::checkpoint_every_steps.
  bool checkpoint_due(long step, double every_s) const;
  // Records a checkpoint written at `step`: the last good one a blow-up keeps.
  void checkpoint_written(long step);

  // The report of a run stopped on request after its checkpoint at `step`.
  RunReport interrupted(ProgressReporter& progress, long step);
  // The report of a blow-up at `where` (blown_up_run with this run's checkpoint).
  RunReport blown_up(const std::string& where, const std::string& what,
                     const std::string& likely_causes);

  // result.json's cost: wall time over every invocation (`wall_before_s` the
  // earlier ones', `wall_s` this one's), steps (all, and this invocation's),
  // threads and seconds per stage.
  nlohmann::json cost(double wall_before_s, double wall_s, long steps, long steps_this_invocation,
                      const TimedStages& stages) const;
  // Completes `result` (the scene's case, observables, cost, ...) with the
  // envelope, writes it atomically as result.json, removes the checkpoint and
  // logs "completed <what> in <wall><rate>".
  RunReport complete(nlohmann::json result, double wall_s, const std::string& what,
                     const std::string& rate = "");

 private:
  RunOptions options_;
  // held for the run's life, taken before the directory is read: one flocsim per --out
  std::unique_ptr<output::FileLock> out_lock_;
  StartMode start_;
  RunLog log_;
  std::filesystem::path checkpoint_;
  std::chrono::steady_clock::time_point t_start_;
  std::chrono::steady_clock::time_point last_checkpoint_;
  long last_good_checkpoint_ = -1;
  long first_step_ = 0;
};

// result.json's "device" of a run on the CPU: {"kind": "cpu", "name": the
// processor's model, "threads"}.
nlohmann::json cpu_device_record();
// result.json's "device" of a run on a GPU: {"kind": "cuda", "name",
// "memory_gib", "compute_capability"}.
nlohmann::json gpu_device_record(const gpu::GpuDevice& g);

// The lattice of a case on "cuda", taken on the GPU before the output folder
// is touched, so that a GPU that cannot hold it refuses the run up front
// (input::InputError with the reason and what works); null for the CPU.
template <class Real>
std::unique_ptr<gpu::GpuFluidLattice<Real>> lattice_on_gpu(bool on_gpu, lattice::Extent extent,
                                                           lattice::Relaxation relaxation) {
  if (!on_gpu) return nullptr;
  try {
    return std::make_unique<gpu::GpuFluidLattice<Real>>(extent, relaxation);
  } catch (const std::exception& e) {
    throw input::InputError(std::string("device = \"cuda\": ") + e.what() +
                            "; run on the CPU with --device cpu");
  }
}

// Runs a scene's loop and turns a module's failure (event cap, I/O such as a
// full disk) into a failed run; a refused input stays an input::InputError.
template <class Loop>
RunReport run_guarded(const std::filesystem::path& out_dir, Loop&& loop);

}  // namespace flocsim::run

#include "engine/input/input_reader.hpp"

namespace flocsim::run {

template <class Loop>
RunReport run_guarded(const std::filesystem::path& out_dir, Loop&& loop) {
  try {
    return loop();
  } catch (const input::InputError&) {
    throw;
  } catch (const std::exception& e) {
    return failed_run(out_dir, e);
  }
}

}  // namespace flocsim::run
