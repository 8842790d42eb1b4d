// flocsim run CASE.json --out DIR [--resume] [--quiet] [--device cpu|cuda]
// One solver instance; also what the orchestrator's workers execute.
// Exit codes: 0 completed, 1 failed, 2 input refused, 3 stopped by a signal
// after writing a checkpoint (continue with --resume), 4 the output folder is
// held by another live run (nothing done).
#include <cstdio>

#include "apps/flocsim/command_registry.hpp"
#include "apps/flocsim/gpu_fit.hpp"
#include "engine/case/case_file.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/process/stop_signal.hpp"
#include "engine/run/fluid_run.hpp"
#include "engine/run/output_directory.hpp"
#include "engine/run/sphere_run.hpp"

namespace flocsim::app {
namespace {

struct RunArguments {
  std::string case_file;
  std::string out_dir;
  bool resume = false;
  bool quiet = false;
  long stop_after_steps = 0;
  std::string device;  // overrides the case's "device" when given
};

int run_command(const RunArguments& a) {
  // Read and validate the whole case before any work starts.
  cases::ParsedCase parsed;
  try {
    nlohmann::json document = input::read_json_file(a.case_file);
    if (!a.device.empty() && document.is_object()) document["device"] = a.device;
    parsed = cases::parse_case(document);
  } catch (const input::InputError& e) {
    // file-level refusals (read_json_file) already start with the file's name
    const std::string what = printable(e.what());
    const std::string file = printable(a.case_file);
    const bool named = what.rfind(file + ":", 0) == 0;
    std::fprintf(stderr, "flocsim run: input error%s%s: %s\n", named ? "" : " in ",
                 named ? "" : file.c_str(), what.c_str());
    return kExitBadInput;
  }
  // A GPU that is not there, or too small, is found out now, before any output is written.
  if (const std::string why = gpu_refusal(parsed); !why.empty()) {
    std::fprintf(stderr, "flocsim run: input error in %s: %s\n", printable(a.case_file).c_str(),
                 printable(why).c_str());
    return kExitBadInput;
  }
  process::install_stop_handlers(process::SecondSignal::ends_the_process);
  run::RunOptions options;
  options.out_dir = a.out_dir;
  options.resume = a.resume;
  options.quiet = a.quiet;
  options.stop_after_steps = a.stop_after_steps;
  run::RunReport report;
  try {
    report = parsed.fluid_scene ? run::run_fluid_case(parsed.fluid, options)
                                : run::run_sphere_case(parsed.spheres, options);
  } catch (const run::OutputDirectoryBusy& e) {
    std::fprintf(stderr, "flocsim run: %s\n", printable(e.what()).c_str());
    return process::kExitBusy;
  } catch (const input::InputError& e) {
    std::fprintf(stderr, "flocsim run: input error: %s\n", printable(e.what()).c_str());
    return kExitBadInput;
  }
  switch (report.outcome) {
    case run::RunOutcome::completed:
      return kExitOk;
    case run::RunOutcome::interrupted:
      return kExitInterrupted;
    case run::RunOutcome::failed:
      std::fprintf(stderr, "flocsim run: failed: %s\n", printable(report.message).c_str());
      return kExitFailure;
  }
  return kExitFailure;
}

const bool registered = register_command(
    {"run", "Run one simulation case (also the orchestrator's worker)", [](CLI::App& cmd) {
       auto args = std::make_shared<RunArguments>();
       cmd.add_option("case", args->case_file, "Case file (JSON)")
           ->required()
           ->check(CLI::ExistingFile);
       cmd.add_option("--out,-o", args->out_dir, "Output directory")->required();
       cmd.add_flag("--resume", args->resume, "Continue from OUT/checkpoint.h5 if it exists");
       cmd.add_option("--device", args->device,
                      "Where the lattice steps: cpu or cuda (overrides the case's \"device\")")
           ->check(CLI::IsMember({"cpu", "cuda"}));
       cmd.add_flag("--quiet,-q", args->quiet, "Write only the log file, nothing on stderr");
       cmd.add_option("--stop-after", args->stop_after_steps,
                      "Stop after N steps as if SIGTERM arrived (checkpoint, exit 3); for tests")
           ->check(CLI::Validator(
               [](std::string& v) -> std::string {
                 // a whole number of steps, at least one (0 would be the engine's
                 // "no stop" and run the whole case); CLI11's own range check
                 // would print the range of long (19 digits) or of double (309)
                 const bool digits = !v.empty() && v.size() <= 18 &&
                                     v.find_first_not_of("0123456789") == std::string::npos &&
                                     v.find_first_not_of('0') != std::string::npos;
                 return digits ? std::string() : "must be a whole number of steps >= 1, got " + v;
               },
               "STEPS"));
       return [args] { return run_command(*args); };
     }});

}  // namespace
}  // namespace flocsim::app
