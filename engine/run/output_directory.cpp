#include "engine/run/output_directory.hpp"

#include <ctime>
#include <fstream>

#include "engine/input/input_reader.hpp"

namespace flocsim::run {

namespace fs = std::filesystem;

StartMode prepare_output_directory(const fs::path& dir, bool resume) {
  fs::create_directories(dir);
  const bool completed = fs::exists(dir / "result.json");
  const bool checkpoint = fs::exists(dir / "checkpoint.h5");
  if (completed) {
    if (resume) return StartMode::already_completed;
    throw input::InputError(
        (dir / "result.json").string() +
        " exists: the run in this directory has completed; use another --out directory");
  }
  if (checkpoint) {
    if (resume) return StartMode::from_checkpoint;
    throw input::InputError((dir / "checkpoint.h5").string() +
                            " exists: continue it with --resume, or use another --out directory");
  }
  for (const char* stale : {"fields", "spheres"}) fs::remove_all(dir / stale);
  for (const char* stale : {"fields.xdmf", "spheres.xdmf", "series.h5", "progress.json"})
    fs::remove(dir / stale);
  return StartMode::fresh;
}

RunReport completed_run(const fs::path& dir, RunLog& log) {
  log.info("already completed: " + (dir / "result.json").string() + " is kept as it is");
  RunReport r;
  r.outcome = RunOutcome::completed;
  std::ifstream in(dir / "result.json");
  r.result = nlohmann::json::parse(in);
  return r;
}

std::string utc_timestamp() {
  const std::time_t now = std::time(nullptr);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return buf;
}

bool resumable_under(const nlohmann::json& checkpoint_case, const nlohmann::json& current_case) {
  auto physics_only = [](nlohmann::json c) {
    for (const char* group : {"run", "protocol"}) {
      if (!c.contains(group)) continue;
      for (const char* key : {"threads", "progress_every_s", "checkpoint_every_s"})
        c[group].erase(key);
    }
    if (c.value("scene", "") == "fluid" && c.contains("run")) c["run"].erase("steps");
    return c;
  };
  return physics_only(checkpoint_case) == physics_only(current_case);
}

RunReport blown_up_run(RunLog& log, const std::string& where, const std::string& what,
                       long last_good_checkpoint, const std::filesystem::path& checkpoint,
                       const std::string& likely_causes) {
  RunReport r;
  r.outcome = RunOutcome::failed;
  r.message = "numerical blow-up detected at " + where + ": " + what + ". " +
              (last_good_checkpoint >= 0
                   ? "The last good checkpoint (step " + std::to_string(last_good_checkpoint) +
                         ") is kept in " + checkpoint.string() + ". "
                   : std::string("No checkpoint had been written yet. ")) +
              "Likely causes: " + likely_causes + ".";
  log.error(r.message);
  return r;
}

}  // namespace flocsim::run
