#include "engine/process/stop_signal.hpp"

#include <atomic>
#include <csignal>

namespace flocsim::process {

namespace {
// Written by the handler (on whichever thread the signal lands, OpenMP
// workers included) and read at the caller's safe points: lock-free atomics
// are both async-signal-safe and free of data races.
std::atomic<int> last_signal{0};
std::atomic<int> signals_received{0};
static_assert(std::atomic<int>::is_always_lock_free);
extern "C" void on_stop_signal(int signal) {
  last_signal.store(signal, std::memory_order_relaxed);
  signals_received.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

void install_stop_handlers(SecondSignal second) {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = second == SecondSignal::ends_the_process ? SA_RESETHAND : 0;
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);
}

int stop_requested() {
  return last_signal.load(std::memory_order_relaxed);
}
int stop_requests() {
  return signals_received.load(std::memory_order_relaxed);
}
void request_stop(int signal) {
  last_signal.store(signal, std::memory_order_relaxed);
  signals_received.fetch_add(1, std::memory_order_relaxed);
}
void clear_stop_request() {
  last_signal.store(0, std::memory_order_relaxed);
  signals_received.store(0, std::memory_order_relaxed);
}

}  // namespace flocsim::process
