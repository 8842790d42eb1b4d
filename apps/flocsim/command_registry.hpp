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
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "engine/process/exit_codes.hpp"
#include "engine/text/printable.hpp"

namespace flocsim::app {

using CommandHandler = std::function<int()>;

struct Command {
  std::string name;
  std::string description;
  std::function<CommandHandler(CLI::App&)> setup;
};

bool register_command(Command command);
const std::vector<Command>& commands();

// The check of every number option: a finite number in [low, high]. CLI11's
// Range lets "nan" through (each comparison with NaN is false: a NaN
// tolerance never converged); CLI11 names the option in front of the message.
inline CLI::Validator finite_number(double low, double high) {
  char range[96];
  std::snprintf(range, sizeof range, "a finite number in [%g, %g]", low, high);
  const std::string allowed = range;
  return CLI::Validator(
      [low, high, allowed](std::string& text) -> std::string {
        double v = 0;
        if (!CLI::detail::lexical_cast(text, v)) return "must be " + allowed + ", got " + text;
        if (!std::isfinite(v) || v < low || v > high) return "must be " + allowed + ", got " + text;
        return {};
      },
      "in [" + std::to_string(low) + ", " + std::to_string(high) + "]");
}

// Exit codes shared by all subcommands and the orchestrator's workers
// (docs/user-guide.md): defined once, in engine/process/exit_codes.hpp.
using process::kExitBadInput;
using process::kExitFailure;
using process::kExitInterrupted;
using process::kExitOk;

// Every message printed on stderr goes through text::printable: it carries
// names, paths and values from files, databases and the command line, and
// their control and bidirectional characters (and a newline, which would
// forge a line) are shown escaped, never obeyed. One message is one line.
using text::printable;

}  // namespace flocsim::app
