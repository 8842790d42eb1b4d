#include "engine/run/stop_signal.hpp"

#include <atomic>
#include <csignal>

namespace flocsim::run {

namespace {
// Written by the handler (on whichever thread the signal lands, OpenMP
// workers included) and read by the time loop: a lock-free atomic is both
// async-signal-safe and free of data races.
std::atomic<int> received{0};
static_assert(std::atomic<int>::is_always_lock_free);
extern "C" void on_stop_signal(int signal) {
  received.store(signal, std::memory_order_relaxed);
}
}  // namespace

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  // The first signal asks for a clean stop; the handler then reverts to the
  // default, so a second Ctrl-C ends a run that is stuck writing.
  action.sa_flags = SA_RESETHAND;
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);
}

int stop_requested() {
  return received.load(std::memory_order_relaxed);
}
void request_stop(int signal) {
  received.store(signal, std::memory_order_relaxed);
}
void clear_stop_request() {
  received.store(0, std::memory_order_relaxed);
}

}  // namespace flocsim::run
