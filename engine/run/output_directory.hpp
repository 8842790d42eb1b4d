#pragma once
// What a run finds in its output directory decides how it starts:
//   - result.json present: the run is complete; --resume leaves it alone, a
//     fresh start refuses to overwrite it;
//   - checkpoint.h5 present: --resume continues from it, a fresh start
//     refuses (it would silently discard the work);
//   - otherwise a fresh start, after removing snapshot output an earlier,
//     never-checkpointed attempt may have left.
// Refusals are input errors naming the file and the way out.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "engine/run/run_log.hpp"
#include "engine/run/run_types.hpp"

namespace flocsim::run {

enum class StartMode { fresh, from_checkpoint, already_completed };

StartMode prepare_output_directory(const std::filesystem::path& dir, bool resume);

// The report of a run found complete (StartMode::already_completed): its
// stored result.json, untouched.
RunReport completed_run(const std::filesystem::path& dir, RunLog& log);

// The report of a run stopped by a numerical blow-up: what happened where,
// whether a last good checkpoint (step >= 0) is kept, and the likely causes;
// also written to the log.
RunReport blown_up_run(RunLog& log, const std::string& where, const std::string& what,
                       long last_good_checkpoint, const std::filesystem::path& checkpoint,
                       const std::string& likely_causes);

// Now, as result.json's completed_at: ISO 8601 in UTC.
std::string utc_timestamp();

// A checkpoint may be continued under a case that differs only in run
// control (threads, progress and checkpoint cadence; for the fluid scene the
// total number of steps, to extend a run). Everything else must match.
bool resumable_under(const nlohmann::json& checkpoint_case, const nlohmann::json& current_case);

}  // namespace flocsim::run
