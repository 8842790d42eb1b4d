// flocsim: particle-resolved simulations of settling, flocculating spheres and
// the tools around them. Subcommands register themselves (command_registry.hpp).
#include <algorithm>
#include <cstdio>
#include <exception>
#include <map>
#include <string>

#include "apps/flocsim/command_registry.hpp"

namespace flocsim::app {

namespace {
std::vector<Command>& registry() {
  static std::vector<Command> r;
  return r;
}
}  // namespace

bool register_command(Command command) {
  registry().push_back(std::move(command));
  return true;
}

const std::vector<Command>& commands() {
  return registry();
}

}  // namespace flocsim::app

int main(int argc, char** argv) {
  using namespace flocsim::app;
  CLI::App app{"flocsim " FLOCSIM_VERSION
               ": particle-resolved simulation of settling, flocculating spheres\n"
               "(lattice Boltzmann D3Q19 + immersed boundary + event-driven contacts)"};
  app.set_version_flag("--version", FLOCSIM_VERSION);
  app.require_subcommand(1);
  // CLI11's refusals quote the words given (an option's value, an unknown
  // argument): shown escaped like every other message
  app.failure_message([](const CLI::App*, const CLI::Error& e) {
    return printable(e.what()) + "\nRun with --help for more information.\n";
  });
  std::vector<Command> sorted = commands();
  std::sort(sorted.begin(), sorted.end(),
            [](const Command& a, const Command& b) { return a.name < b.name; });
  std::map<CLI::App*, CommandHandler> handlers;
  for (const Command& c : sorted) {
    CLI::App* sub = app.add_subcommand(c.name, c.description);
    handlers[sub] = c.setup(*sub);
  }
  // CLI11 answers an unknown first word with "A subcommand is required": name it
  if (argc > 1 && argv[1][0] != '-' &&
      std::none_of(sorted.begin(), sorted.end(),
                   [&](const Command& c) { return c.name == argv[1]; })) {
    std::string known;
    for (const Command& c : sorted) known += (known.empty() ? "" : ", ") + c.name;
    std::fprintf(stderr, "flocsim: %s: no such subcommand (subcommands: %s; see --help)\n",
                 printable(std::string(argv[1]).substr(0, 80)).c_str(), known.c_str());
    return kExitBadInput;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitBadInput;
  }
  for (auto& [sub, handler] : handlers) {
    if (!sub->parsed()) continue;
    try {
      return handler();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "flocsim %s: error: %s\n", sub->get_name().c_str(),
                   printable(e.what()).c_str());
      return kExitFailure;
    }
  }
  return kExitBadInput;
}
