#pragma once
// What a run finds in its output directory decides how it starts:
//   - result.json present: the run is complete; --resume of the same case
//     leaves it alone (of another case: refused, naming the fields that
//     differ), a fresh start refuses to overwrite it; one that cannot be read
//     completes nothing: --resume sets it aside (result.json.unreadable) and
//     goes on from the checkpoint or starts again;
//   - checkpoint.h5 present: --resume continues from it, a fresh start
//     refuses (it would silently discard the work);
//   - otherwise a fresh start. A run removes only files it can prove it
//     wrote: the directory's run record (kRunRecord) names the case whose
//     output it holds, and an earlier, never-checkpointed attempt of the same
//     case leaves stale snapshots and series that are removed, file by file,
//     by their names. Anything else is the user's: a directory that holds
//     something in the place of a run output, and no run record of this case,
//     is refused, and nothing in it is touched.
// Refusals are input errors naming the file and the way out.
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "engine/input/input_reader.hpp"
#include "engine/output/file_lock.hpp"
#include "engine/run/run_log.hpp"
#include "engine/run/run_types.hpp"

namespace flocsim::run {

enum class StartMode { fresh, from_checkpoint, already_completed };

// The file in an output directory that records which case's output it holds.
inline constexpr const char* kRunRecord = "flocsim-run.json";

// The refusal of an output directory that another live flocsim holds: not a
// fault of the case (exit 4, not 2), so an orchestrator retries the run later
// instead of giving it up.
class OutputDirectoryBusy : public input::InputError {
 public:
  using input::InputError::InputError;
};

// Makes the output directory (a path taken by a file is refused) and takes its
// lock, held while the returned object lives: a second flocsim given the same
// --out while this one runs (a fresh start or a --resume) is refused, naming
// the process that holds it, before it reads or writes anything there. The
// lock lives in DIR/.flocsim-run.lock, which the holder removes as it ends
// (one killed leaves it, and the next run takes it over: the kernel let go).
// nullptr where the file system offers no locks (the run goes on unguarded,
// and says so in its log).
std::unique_ptr<output::FileLock> lock_output_directory(const std::filesystem::path& dir);

// `case_json` is the canonical case (to_json()) of the run about to start.
StartMode prepare_output_directory(const std::filesystem::path& dir, bool resume,
                                   const nlohmann::json& case_json);

// The report of a run found complete (StartMode::already_completed): its
// stored result.json, untouched.
RunReport completed_run(const std::filesystem::path& dir, RunLog& log);

// The report of a run stopped by a numerical blow-up: what happened where,
// whether a last good checkpoint (step >= 0) is kept, and the likely causes;
// also written to the log.
RunReport blown_up_run(RunLog& log, const std::string& where, const std::string& what,
                       long last_good_checkpoint, const std::filesystem::path& checkpoint,
                       const std::string& likely_causes);

// The report of a run a module gave up on (event cap, I/O such as a full
// disk): the reason, also written to the run's log when the directory exists.
// The last checkpoint stays for a look or a --resume after the cause is fixed.
RunReport failed_run(const std::filesystem::path& dir, const std::exception& e);

// Now, as result.json's completed_at: ISO 8601 in UTC.
std::string utc_timestamp();

// A checkpoint may be continued under a case that differs only in run
// control (threads, progress and checkpoint cadence; for the fluid scene the
// total number of steps, to extend a run). Everything else must match.
bool resumable_under(const nlohmann::json& checkpoint_case, const nlohmann::json& current_case);
// Whether a completed run's result (its recorded case) is the result of the
// current case: as resumable_under, but every step counts (a completed run is
// not extended).
bool completed_under(const nlohmann::json& result_case, const nlohmann::json& current_case);
// What keeps a checkpoint from being continued: "field = old in the
// checkpoint, new now" for each differing field, joined by "; ".
std::string case_differences(const nlohmann::json& checkpoint_case,
                             const nlohmann::json& current_case);
// Throws the failure of a checkpoint that cannot be read (`why`): it names the
// file and the way out (move it away, --resume starts the case over).
[[noreturn]] void damaged_checkpoint(const std::filesystem::path& checkpoint,
                                     const std::string& why);
// Throws input::InputError naming the checkpoint file and the differing
// fields unless the checkpoint's case is resumable under the current one.
void require_resumable(const std::filesystem::path& checkpoint, const nlohmann::json& recorded_case,
                       const nlohmann::json& current_case);

}  // namespace flocsim::run
