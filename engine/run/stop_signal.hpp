#pragma once
// SIGTERM and SIGINT ask a run to stop: the handler only records the signal;
// the time loop notices it between steps, writes a checkpoint and exits with
// kExitInterrupted, so nothing computed is lost.
namespace flocsim::run {

void install_stop_handlers();
// The signal received (0 when none).
int stop_requested();
// For tests: pretend a signal arrived / forget it.
void request_stop(int signal);
void clear_stop_request();

}  // namespace flocsim::run
