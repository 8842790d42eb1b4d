#pragma once
// The states of a run, and of an attempt at a run, in the results database.
// db/ owns them: the text of each state (to_string) is what the database
// stores in runs.status and attempts.state, what a Slurm task file lists and
// what `flocsim sweep status` and `flocsim query` show, so it never changes.
//
// A run is `pending` until first started, `running` while an attempt is live,
// then ends `completed`, `failed` (exit 1 or crash), `refused` (exit 2: the
// case was rejected, retrying cannot help), `interrupted` (stopped by a signal
// after a checkpoint) or `lost` (the worker vanished: kill -9, node loss,
// scheduler time-out, heartbeat lease expired). An attempt takes the same
// states but `pending`: it starts `running` and ends as its run does.
#include <ostream>
#include <stdexcept>
#include <string>
#include <string_view>

namespace flocsim::db {

enum class RunState { kPending, kRunning, kCompleted, kFailed, kRefused, kInterrupted, kLost };

// Every state, in the order `flocsim sweep status` counts them.
inline constexpr RunState kAllRunStates[] = {
    RunState::kPending, RunState::kRunning,     RunState::kCompleted, RunState::kFailed,
    RunState::kRefused, RunState::kInterrupted, RunState::kLost};

// The text of a state, as stored and shown ("pending", "running", ...).
inline std::string to_string(RunState state) {
  switch (state) {
    case RunState::kPending:
      return "pending";
    case RunState::kRunning:
      return "running";
    case RunState::kCompleted:
      return "completed";
    case RunState::kFailed:
      return "failed";
    case RunState::kRefused:
      return "refused";
    case RunState::kInterrupted:
      return "interrupted";
    case RunState::kLost:
      return "lost";
  }
  throw std::logic_error("RunState " + std::to_string(static_cast<int>(state)) + " has no name");
}

// The state named `text`; throws std::invalid_argument naming the text (and
// the known states) when it is none of them.
inline RunState run_state_from_string(std::string_view text) {
  for (RunState s : kAllRunStates)
    if (to_string(s) == text) return s;
  std::string known;
  for (RunState s : kAllRunStates) known += (known.empty() ? "" : ", ") + to_string(s);
  throw std::invalid_argument("unknown run state \"" + std::string(text) + "\" (known: " + known +
                              ")");
}

inline std::ostream& operator<<(std::ostream& out, RunState state) {
  return out << to_string(state);
}

// nlohmann::json finds these by argument-dependent lookup: a RunState goes to
// JSON as its text, never as the enum's number (its default for enums).
template <typename BasicJsonType>
void to_json(BasicJsonType& j, const RunState& state) {
  j = to_string(state);
}
template <typename BasicJsonType>
void from_json(const BasicJsonType& j, RunState& state) {
  state = run_state_from_string(j.template get<std::string>());
}

}  // namespace flocsim::db
