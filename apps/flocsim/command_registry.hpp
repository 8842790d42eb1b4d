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

#include "engine/process/exit_codes.hpp"

namespace flocsim::app {

using CommandHandler = std::function<int()>;

struct Command {
  std::string name;
  std::string description;
  std::function<CommandHandler(CLI::App&)> setup;
};

bool register_command(Command command);
const std::vector<Command>& commands();

// Exit codes shared by all subcommands and the orchestrator's workers
// (docs/user-guide.md): defined once, in engine/process/exit_codes.hpp.
using process::kExitBadInput;
using process::kExitFailure;
using process::kExitInterrupted;
using process::kExitOk;

}  // namespace flocsim::app
