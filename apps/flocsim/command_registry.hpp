#pragma once
// Subcommands of the flocsim executable register themselves here from their
// own source file:
//
//   static const bool registered = flocsim::app::register_command(
//       {"run", "Run one simulation case", [](CLI::App& cmd) { ...; return handler; }});
//
// `setup` declares the subcommand's options on `cmd` and returns the function
// that runs it once parsing succeeded; that function returns the exit code.
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace flocsim::app {

using CommandHandler = std::function<int()>;

struct Command {
  std::string name;
  std::string description;
  std::function<CommandHandler(CLI::App&)> setup;
};

bool register_command(Command command);
const std::vector<Command>& commands();

// Exit codes shared by all subcommands (documented in docs/user-guide.md).
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;      // the run failed (numerical blow-up, I/O error)
inline constexpr int kExitBadInput = 2;     // input refused before any work started
inline constexpr int kExitInterrupted = 3;  // stopped by a signal after writing a checkpoint

}  // namespace flocsim::app
