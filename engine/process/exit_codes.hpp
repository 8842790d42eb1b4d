#pragma once
// How a flocsim process ends: the exit codes every subcommand uses and the
// orchestrator reads back from its workers (`flocsim run`). One definition for
// both sides of that contract; docs/user-guide.md lists them for users.
namespace flocsim::process {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;      // the run failed (numerical blow-up, I/O error)
inline constexpr int kExitBadInput = 2;     // input refused before any work started
inline constexpr int kExitInterrupted = 3;  // stopped by a signal after writing a checkpoint
inline constexpr int kExitBusy =
    4;  // the output directory is held by another live flocsim; nothing done

}  // namespace flocsim::process
