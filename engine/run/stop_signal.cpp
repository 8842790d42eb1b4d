#include "engine/run/stop_signal.hpp"

#include <csignal>

namespace flocsim::run {

namespace {
volatile std::sig_atomic_t received = 0;
extern "C" void on_stop_signal(int signal) { received = signal; }
}  // namespace

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);
}

int stop_requested() { return received; }
void request_stop(int signal) { received = signal; }
void clear_stop_request() { received = 0; }

}  // namespace flocsim::run
